//! Reader for LAMMPS data files written by `write_data` with
//! `atom_style sphere`.
//!
//! Understood: the header counts (`N atoms`, `N atom types`), the box
//! (`xlo xhi`, `ylo yhi`, `zlo zhi`), the `Atoms # sphere` section (columns
//! `id type diameter density x y z [ix iy iz]`) and the `Velocities` section
//! (`id vx vy vz wx wy wz`). Other header lines and sections (Masses, …) are
//! skipped; text after `#` is a comment. Positions are kept as written (image
//! flags are reported, not applied). Triclinic boxes are refused.

use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct LammpsAtom {
    pub id: u64,
    pub kind: u32,
    pub diameter: f64,
    /// Mass per volume of a sphere (also for 2D disks, as LAMMPS reads it).
    pub density: f64,
    pub pos: [f64; 3],
    pub image: [i32; 3],
}

impl LammpsAtom {
    /// The mass LAMMPS assigns: density × volume of a sphere of this diameter.
    pub fn sphere_mass(&self) -> f64 {
        self.density * std::f64::consts::PI * self.diameter.powi(3) / 6.0
    }
}

/// Translational and angular velocity of one atom.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LammpsVelocity {
    pub v: [f64; 3],
    pub omega: [f64; 3],
}

#[derive(Clone, Debug, PartialEq)]
pub struct LammpsData {
    pub box_lo: [f64; 3],
    pub box_hi: [f64; 3],
    /// The header's `N atom types` (0 when absent).
    pub atom_types: u32,
    pub atoms: Vec<LammpsAtom>,
    /// Aligned with `atoms`; all zero when the file has no Velocities section.
    pub velocities: Vec<LammpsVelocity>,
    pub has_velocities: bool,
}

impl LammpsData {
    /// True when the box and positions look like a LAMMPS 2D system: z
    /// bounds straddling 0 and every atom at z = 0.
    pub fn is_planar(&self) -> bool {
        self.box_lo[2] < 0.0 && self.box_hi[2] > 0.0 && self.atoms.iter().all(|a| a.pos[2] == 0.0)
    }
}

/// Reads a LAMMPS data file from disk.
pub fn read_lammps_data(path: &Path) -> Result<LammpsData> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_lammps_data(&text, &path.display().to_string())
}

#[derive(Clone, Copy, PartialEq)]
enum Section {
    Header,
    Atoms,
    Velocities,
    Other,
}

const ATOM_COLUMNS: [&str; 10] = [
    "id", "type", "diameter", "density", "x", "y", "z", "ix", "iy", "iz",
];
const VEL_COLUMNS: [&str; 7] = ["id", "vx", "vy", "vz", "wx", "wy", "wz"];

/// Parses the text of a data file; `name` (the file name) prefixes errors.
pub fn parse_lammps_data(text: &str, name: &str) -> Result<LammpsData> {
    let err = |line: usize, msg: String| Error::input(format!("{name}:{line}: {msg}"));
    let mut section = Section::Header;
    let mut declared_atoms: Option<(usize, usize)> = None; // (count, line)
    let mut atom_types = 0u32;
    let mut box_lo = [-0.5; 3];
    let mut box_hi = [0.5; 3];
    let mut atoms: Vec<LammpsAtom> = Vec::new();
    let mut index_of: HashMap<u64, (usize, usize)> = HashMap::new(); // id -> (index, line)
    let mut atoms_line = None;
    let mut vel_line = None;
    let mut vels: Vec<(usize, u64, LammpsVelocity)> = Vec::new();
    let mut tok: Vec<&str> = Vec::with_capacity(12);

    // The first line is a title and is always skipped, as LAMMPS does.
    for (i, raw) in text.lines().enumerate().skip(1) {
        let line = i + 1;
        let (content, comment) = match raw.find('#') {
            Some(k) => (&raw[..k], raw[k + 1..].trim()),
            None => (raw, ""),
        };
        let content = content.trim();
        if content.is_empty() {
            continue;
        }
        if content.as_bytes()[0].is_ascii_alphabetic() {
            section = match content {
                "Atoms" => {
                    if let Some(first) = atoms_line {
                        return Err(err(
                            line,
                            format!("second Atoms section (the first is on line {first})"),
                        ));
                    }
                    if !comment.is_empty() && comment != "sphere" {
                        return Err(err(
                            line,
                            format!("atom style '{comment}' is not supported: only atom_style sphere is read"),
                        ));
                    }
                    atoms_line = Some(line);
                    Section::Atoms
                }
                "Velocities" => {
                    if let Some(first) = vel_line {
                        return Err(err(
                            line,
                            format!("second Velocities section (the first is on line {first})"),
                        ));
                    }
                    vel_line = Some(line);
                    Section::Velocities
                }
                _ => Section::Other,
            };
            continue;
        }
        tok.clear();
        tok.extend(content.split_ascii_whitespace());
        match section {
            Section::Header => {
                let words = &tok[1.min(tok.len())..];
                match words {
                    ["atoms"] => {
                        let n = tok[0].parse::<usize>().map_err(|_| {
                            err(line, format!("'{}' is not a count of atoms (expected a non-negative integer)", tok[0]))
                        })?;
                        declared_atoms = Some((n, line));
                    }
                    ["atom", "types"] => {
                        atom_types = tok[0].parse::<u32>().map_err(|_| {
                            err(line, format!("'{}' is not a count of atom types (expected a non-negative integer)", tok[0]))
                        })?;
                    }
                    [_, "xlo", "xhi"] | [_, "ylo", "yhi"] | [_, "zlo", "zhi"] => {
                        let axis = (words[1].as_bytes()[0] - b'x') as usize;
                        let lo = parse_f64(tok[0], line, "lower bound", &err)?;
                        let hi = parse_f64(tok[1], line, "upper bound", &err)?;
                        if lo >= hi {
                            return Err(err(
                                line,
                                format!(
                                    "box bounds {lo} {hi}: the lower bound must be below the upper"
                                ),
                            ));
                        }
                        box_lo[axis] = lo;
                        box_hi[axis] = hi;
                    }
                    [_, _, "xy", "xz", "yz"] => {
                        return Err(err(line, "triclinic boxes are not supported (only orthogonal boxes: xlo xhi, ylo yhi, zlo zhi)".into()));
                    }
                    _ => {} // other counts (bonds, …) do not concern spheres
                }
            }
            Section::Atoms => {
                if tok.len() != 7 && tok.len() != 10 {
                    return Err(err(
                        line,
                        format!(
                            "Atoms line has {} columns; atom_style sphere expects 7 (id type diameter density x y z) or 10 (with image flags ix iy iz)",
                            tok.len()
                        ),
                    ));
                }
                let id = parse_id(tok[0], line, &err)?;
                let kind = tok[1].parse::<u32>().ok().filter(|&k| k >= 1).ok_or_else(|| {
                    err(line, format!("column 2 (type): '{}' is not an atom type (expected a positive integer)", tok[1]))
                })?;
                if atom_types > 0 && kind > atom_types {
                    return Err(err(line, format!("atom type {kind} is out of range: the header declares {atom_types} atom types")));
                }
                let mut f = [0.0; 5];
                for (k, v) in f.iter_mut().enumerate() {
                    *v = parse_col(tok[k + 2], line, k + 3, ATOM_COLUMNS[k + 2], &err)?;
                }
                if f[0] <= 0.0 {
                    return Err(err(line, format!("diameter {} must be positive", f[0])));
                }
                if f[1] <= 0.0 {
                    return Err(err(line, format!("density {} must be positive", f[1])));
                }
                let mut image = [0i32; 3];
                if tok.len() == 10 {
                    for a in 0..3 {
                        image[a] = tok[7 + a].parse().map_err(|_| {
                            err(line, format!("column {} ({}): '{}' is not an image flag (expected an integer)", 8 + a, ATOM_COLUMNS[7 + a], tok[7 + a]))
                        })?;
                    }
                }
                if let Some(&(_, first)) = index_of.get(&id) {
                    return Err(err(
                        line,
                        format!("duplicate atom id {id} (first on line {first})"),
                    ));
                }
                if let Some((n, hl)) = declared_atoms {
                    if atoms.len() == n {
                        return Err(err(
                            line,
                            format!("more Atoms lines than the {n} atoms declared on line {hl}"),
                        ));
                    }
                }
                index_of.insert(id, (atoms.len(), line));
                atoms.push(LammpsAtom {
                    id,
                    kind,
                    diameter: f[0],
                    density: f[1],
                    pos: [f[2], f[3], f[4]],
                    image,
                });
            }
            Section::Velocities => {
                if tok.len() != 7 {
                    return Err(err(
                        line,
                        format!(
                            "Velocities line has {} columns; expected 7 (id vx vy vz wx wy wz)",
                            tok.len()
                        ),
                    ));
                }
                let id = parse_id(tok[0], line, &err)?;
                let mut f = [0.0; 6];
                for (k, v) in f.iter_mut().enumerate() {
                    *v = parse_col(tok[k + 1], line, k + 2, VEL_COLUMNS[k + 1], &err)?;
                }
                vels.push((
                    line,
                    id,
                    LammpsVelocity {
                        v: [f[0], f[1], f[2]],
                        omega: [f[3], f[4], f[5]],
                    },
                ));
            }
            Section::Other => {}
        }
    }

    let Some((n, header_line)) = declared_atoms else {
        return Err(Error::input(format!(
            "{name}: the header has no 'N atoms' line"
        )));
    };
    let Some(atoms_at) = atoms_line else {
        if n == 0 {
            return Ok(LammpsData {
                box_lo,
                box_hi,
                atom_types,
                atoms,
                velocities: Vec::new(),
                has_velocities: false,
            });
        }
        return Err(Error::input(format!(
            "{name}: no Atoms section (the header on line {header_line} declares {n} atoms)"
        )));
    };
    if atoms.len() != n {
        return Err(err(
            atoms_at,
            format!(
                "Atoms section has {} lines but the header (line {header_line}) declares {n} atoms",
                atoms.len()
            ),
        ));
    }
    let mut velocities = vec![LammpsVelocity::default(); atoms.len()];
    let mut seen = vec![0usize; atoms.len()];
    for &(line, id, v) in &vels {
        let Some(&(k, _)) = index_of.get(&id) else {
            return Err(err(
                line,
                format!("velocity for atom id {id}, which is not in the Atoms section"),
            ));
        };
        if seen[k] != 0 {
            return Err(err(
                line,
                format!(
                    "second velocity for atom id {id} (first on line {})",
                    seen[k]
                ),
            ));
        }
        seen[k] = line;
        velocities[k] = v;
    }
    if let Some(vl) = vel_line {
        if vels.len() != atoms.len() {
            return Err(err(
                vl,
                format!(
                    "Velocities section has {} lines but there are {} atoms",
                    vels.len(),
                    atoms.len()
                ),
            ));
        }
    }
    Ok(LammpsData {
        box_lo,
        box_hi,
        atom_types,
        atoms,
        velocities,
        has_velocities: vel_line.is_some(),
    })
}

fn parse_id(s: &str, line: usize, err: &impl Fn(usize, String) -> Error) -> Result<u64> {
    s.parse::<u64>().ok().filter(|&id| id >= 1).ok_or_else(|| {
        err(
            line,
            format!("column 1 (id): '{s}' is not an atom id (expected a positive integer)"),
        )
    })
}

fn parse_col(
    s: &str,
    line: usize,
    col: usize,
    what: &str,
    err: &impl Fn(usize, String) -> Error,
) -> Result<f64> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(err(
            line,
            format!("column {col} ({what}): '{s}' is not a finite number"),
        )),
    }
}

fn parse_f64(
    s: &str,
    line: usize,
    what: &str,
    err: &impl Fn(usize, String) -> Error,
) -> Result<f64> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(err(line, format!("{what}: '{s}' is not a finite number"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use std::path::PathBuf;

    fn fixture(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    #[test]
    fn reads_small_fixture() {
        let d = read_lammps_data(&fixture("small_sphere.data")).unwrap();
        assert_eq!(d.box_lo, [0.0, -1.0, -0.5]);
        assert_eq!(d.box_hi, [10.0, 20.0, 0.5]);
        assert_eq!(d.atom_types, 2);
        assert_eq!(d.atoms.len(), 3);
        assert_eq!(
            d.atoms[0],
            LammpsAtom {
                id: 7,
                kind: 1,
                diameter: 1.0,
                density: 1.9098593,
                pos: [1.5, 2.0, 0.0],
                image: [1, 0, 0]
            }
        );
        assert_eq!(d.atoms[2].id, 2);
        assert_eq!(d.atoms[2].image, [0, 0, 0]);
        assert!(d.has_velocities);
        // Velocities are listed in another order than atoms; they are aligned by id.
        assert_eq!(
            d.velocities[0],
            LammpsVelocity {
                v: [0.5, -1.0, 0.0],
                omega: [0.0, 0.0, 3.0]
            }
        );
        assert_eq!(d.velocities[2].v, [-0.25, 0.0, 0.0]);
        assert!(d.is_planar());
        assert!((d.atoms[0].sphere_mass() - 1.0).abs() < 1e-7);
    }

    /// Writes `text` to a scratch file and returns the reader's error message.
    fn error_of(tag: &str, text: &str) -> (String, String) {
        let dir = scratch_dir(&format!("data-{tag}"));
        let path = dir.join(format!("{tag}.data"));
        std::fs::write(&path, text).unwrap();
        let msg = read_lammps_data(&path).unwrap_err().to_string();
        (msg, path.display().to_string())
    }

    const HEAD: &str =
        "title\n\n2 atoms\n1 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n-0.5 0.5 zlo zhi\n\n";

    fn check(tag: &str, text: &str, line: usize, words: &str) {
        let (msg, path) = error_of(tag, text);
        assert!(msg.starts_with(&format!("{path}:{line}: ")), "{tag}: {msg}");
        assert!(msg.contains(words), "{tag}: {msg}");
    }

    #[test]
    fn error_cases_name_file_and_line() {
        let atoms = "Atoms # sphere\n\n1 1 1 1 1 1 0\n";
        check(
            "columns",
            &format!("{HEAD}{atoms}2 1 1 1 2 2\n"),
            12,
            "expects 7",
        );
        check(
            "number",
            &format!("{HEAD}{atoms}2 1 1 1 2 zz 0\n"),
            12,
            "column 6 (y): 'zz'",
        );
        check(
            "diameter",
            &format!("{HEAD}{atoms}2 1 0 1 2 2 0\n"),
            12,
            "diameter 0 must be positive",
        );
        check(
            "dup",
            &format!("{HEAD}{atoms}1 1 1 1 2 2 0\n"),
            12,
            "duplicate atom id 1 (first on line 11)",
        );
        check(
            "count",
            &format!("{HEAD}{atoms}"),
            9,
            "has 1 lines but the header (line 3) declares 2 atoms",
        );
        check(
            "toomany",
            &format!("{HEAD}{atoms}2 1 1 1 2 2 0\n3 1 1 1 3 3 0\n"),
            13,
            "more Atoms lines",
        );
        check(
            "type",
            &format!("{HEAD}{atoms}2 3 1 1 2 2 0\n"),
            12,
            "atom type 3 is out of range",
        );
        let both =
            format!("{HEAD}{atoms}2 1 1 1 2 2 0\n\nVelocities\n\n1 0 0 0 0 0 0\n9 0 0 0 0 0 0\n");
        check(
            "unknown-vel",
            &both,
            17,
            "atom id 9, which is not in the Atoms section",
        );
        let vcols = format!("{HEAD}{atoms}2 1 1 1 2 2 0\n\nVelocities\n\n1 0 0 0 0 0\n");
        check("vel-cols", &vcols, 16, "expected 7 (id vx vy vz wx wy wz)");
        check(
            "style",
            &format!("{HEAD}Atoms # atomic\n\n1 1 1 1 1\n"),
            9,
            "atom style 'atomic' is not supported",
        );
        let tri = "title\n\n2 atoms\n0 10 xlo xhi\n0 1 0 xy xz yz\n";
        check("triclinic", tri, 5, "triclinic boxes are not supported");
        check(
            "bounds",
            "title\n2 atoms\n5 1 xlo xhi\n",
            3,
            "lower bound must be below",
        );
    }

    #[test]
    fn missing_atoms_section_and_header() {
        let (msg, path) = error_of("noatoms", HEAD);
        assert!(
            msg.starts_with(&path)
                && msg.contains("no Atoms section (the header on line 3 declares 2 atoms)"),
            "{msg}"
        );
        let (msg, path) = error_of("nohead", "title\n\nAtoms # sphere\n\n1 1 1 1 1 1 0\n");
        assert!(
            msg.starts_with(&path) && msg.contains("no 'N atoms' line"),
            "{msg}"
        );
    }

    #[test]
    fn missing_file_names_path() {
        let msg = read_lammps_data(Path::new("/no/such/file.data"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("/no/such/file.data"), "{msg}");
    }

    /// The vib2d benchmark file: looked for in the repository's `bench/`, then
    /// in the shared folder; the test passes silently when neither exists.
    #[test]
    fn reads_vib2d_benchmark_if_present() {
        let candidates = [
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/data.vib2d"),
            PathBuf::from("/work/shared/bench/data.vib2d"),
        ];
        let Some(path) = candidates.iter().find(|p| p.exists()) else {
            eprintln!("data.vib2d not found; skipping");
            return;
        };
        let t = std::time::Instant::now();
        let d = read_lammps_data(path).unwrap();
        eprintln!("read {} atoms in {:?}", d.atoms.len(), t.elapsed());
        assert_eq!(d.atoms.len(), 3700);
        assert_eq!(d.box_hi, [96.0, 400.0, 0.5]);
        assert!(d.has_velocities && d.is_planar());
        assert!(d
            .atoms
            .iter()
            .all(|a| (0.75..=1.25).contains(&a.diameter) && a.density == 1.0));
        let first = &d.atoms[0];
        assert_eq!((first.id, first.image), (74, [1, 0, 0]));
        assert_eq!(d.velocities[0].omega[2], 0.3070513781547277);
    }
}
