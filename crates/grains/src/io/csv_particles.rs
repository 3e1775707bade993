//! Reader of an initial state from a CSV file with a header line.
//!
//! Required columns: `x`, `y` (and `z` in 3D) and either `diameter` or
//! `radius`. Optional: `vx`, `vy` (`vz` in 3D), angular velocity (`omega`
//! or `wz` in 2D; `wx`, `wy`, `wz` in 3D), `type`, `id`, `frozen` (0 or 1).
//! Blank lines and lines starting with `#` are skipped; fields may be
//! surrounded by spaces; column names are case-insensitive.

use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// One row. Fields absent from the file are `None`; among the velocity (or
/// angular velocity) columns, those absent read as 0 when any one is present.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CsvParticle {
    pub id: Option<u64>,
    pub kind: Option<u32>,
    pub pos: [f64; 3],
    pub radius: f64,
    pub vel: Option<[f64; 3]>,
    /// Angular velocity; in 2D the spin is the z component.
    pub omega: Option<[f64; 3]>,
    pub frozen: Option<bool>,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Col {
    Pos(usize),
    Diameter,
    Radius,
    Vel(usize),
    Omega(usize),
    Kind,
    Id,
    Frozen,
}

fn allowed(dim: usize) -> &'static [(&'static str, Col)] {
    use Col::*;
    if dim == 3 {
        &[
            ("x", Pos(0)),
            ("y", Pos(1)),
            ("z", Pos(2)),
            ("diameter", Diameter),
            ("radius", Radius),
            ("vx", Vel(0)),
            ("vy", Vel(1)),
            ("vz", Vel(2)),
            ("wx", Omega(0)),
            ("wy", Omega(1)),
            ("wz", Omega(2)),
            ("type", Kind),
            ("id", Id),
            ("frozen", Frozen),
        ]
    } else {
        &[
            ("x", Pos(0)),
            ("y", Pos(1)),
            ("diameter", Diameter),
            ("radius", Radius),
            ("vx", Vel(0)),
            ("vy", Vel(1)),
            ("omega", Omega(2)),
            ("wz", Omega(2)),
            ("type", Kind),
            ("id", Id),
            ("frozen", Frozen),
        ]
    }
}

fn allowed_list(dim: usize) -> String {
    allowed(dim)
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Reads particles from a CSV file for a `dim`-dimensional system (2 or 3).
pub fn read_particles_csv(path: &Path, dim: usize) -> Result<Vec<CsvParticle>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_particles_csv(&text, &path.display().to_string(), dim)
}

/// Parses CSV text; `name` (the file name) prefixes error messages.
pub fn parse_particles_csv(text: &str, name: &str, dim: usize) -> Result<Vec<CsvParticle>> {
    let err = |line: usize, msg: String| Error::input(format!("{name}:{line}: {msg}"));
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(Error::input(format!(
            "{name}: empty file: expected a header line naming the columns"
        )));
    };
    let table = allowed(dim);
    let mut cols = Vec::new();
    let mut unknown = Vec::new();
    for (c, raw) in header.split(',').enumerate() {
        let key = raw.trim().to_ascii_lowercase();
        match table.iter().find(|(n, _)| *n == key) {
            Some(&(_, col)) => {
                if let Some(prev) = cols.iter().position(|&p| p == col) {
                    return Err(err(
                        hline,
                        format!("column {} ('{key}') repeats column {}", c + 1, prev + 1),
                    ));
                }
                cols.push(col);
            }
            None => unknown.push(format!("'{}'", raw.trim())),
        }
    }
    if !unknown.is_empty() {
        return Err(err(
            hline,
            format!(
                "unknown column(s) {} for a {dim}D system; allowed: {}",
                unknown.join(", "),
                allowed_list(dim)
            ),
        ));
    }
    let has = |c: Col| cols.contains(&c);
    for a in 0..dim {
        if !has(Col::Pos(a)) {
            return Err(err(
                hline,
                format!("missing required column '{}'", ["x", "y", "z"][a]),
            ));
        }
    }
    match (has(Col::Diameter), has(Col::Radius)) {
        (false, false) => return Err(err(hline, "missing column 'diameter' or 'radius'".into())),
        (true, true) => {
            return Err(err(
                hline,
                "give either 'diameter' or 'radius', not both".into(),
            ))
        }
        _ => {}
    }
    let any_vel = cols.iter().any(|c| matches!(c, Col::Vel(_)));
    let any_omega = cols.iter().any(|c| matches!(c, Col::Omega(_)));
    let header_names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();

    let mut rows = Vec::new();
    let mut ids: HashMap<u64, usize> = HashMap::new();
    for (line, text) in lines {
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != cols.len() {
            return Err(err(
                line,
                format!(
                    "{} fields, but the header (line {hline}) names {} columns",
                    fields.len(),
                    cols.len()
                ),
            ));
        }
        let mut p = CsvParticle {
            vel: any_vel.then_some([0.0; 3]),
            omega: any_omega.then_some([0.0; 3]),
            ..Default::default()
        };
        for (c, (&col, field)) in cols.iter().zip(&fields).enumerate() {
            let here = || format!("column {} ({})", c + 1, header_names[c]);
            let num = || -> Result<f64> {
                match field.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(err(
                        line,
                        format!("{}: '{field}' is not a finite number", here()),
                    )),
                }
            };
            match col {
                Col::Pos(a) => p.pos[a] = num()?,
                Col::Vel(a) => p.vel.as_mut().unwrap()[a] = num()?,
                Col::Omega(a) => p.omega.as_mut().unwrap()[a] = num()?,
                Col::Diameter | Col::Radius => {
                    let v = num()?;
                    if v <= 0.0 {
                        return Err(err(line, format!("{}: {v} must be positive", here())));
                    }
                    p.radius = if col == Col::Diameter { v / 2.0 } else { v };
                }
                Col::Kind => {
                    let k = field.parse::<u32>().ok().filter(|&k| k >= 1);
                    p.kind = Some(k.ok_or_else(|| {
                        err(
                            line,
                            format!(
                                "{}: '{field}' is not a type (expected a positive integer)",
                                here()
                            ),
                        )
                    })?);
                }
                Col::Id => {
                    let id = field.parse::<u64>().map_err(|_| {
                        err(
                            line,
                            format!(
                                "{}: '{field}' is not an id (expected a non-negative integer)",
                                here()
                            ),
                        )
                    })?;
                    if let Some(first) = ids.insert(id, line) {
                        return Err(err(
                            line,
                            format!("{}: duplicate id {id} (first on line {first})", here()),
                        ));
                    }
                    p.id = Some(id);
                }
                Col::Frozen => {
                    p.frozen = Some(match *field {
                        "0" | "false" => false,
                        "1" | "true" => true,
                        _ => {
                            return Err(err(line, format!("{}: '{field}' must be 0 or 1", here())))
                        }
                    });
                }
            }
        }
        rows.push(p);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;

    #[test]
    fn reads_2d_with_optional_columns() {
        let text = "# initial state\nid, x, y, diameter, vx, omega, type, frozen\n\n3, 1.5, 2, 1.0, 0.25, -1, 2, 1\n4,3,4,0.8,0,0,1,0\n";
        let rows = parse_particles_csv(text, "a.csv", 2).unwrap();
        assert_eq!(rows.len(), 2);
        let r = &rows[0];
        assert_eq!(r.id, Some(3));
        assert_eq!(r.pos, [1.5, 2.0, 0.0]);
        assert_eq!(r.radius, 0.5);
        assert_eq!(r.vel, Some([0.25, 0.0, 0.0]));
        assert_eq!(r.omega, Some([0.0, 0.0, -1.0]));
        assert_eq!((r.kind, r.frozen), (Some(2), Some(true)));
        assert_eq!(rows[1].frozen, Some(false));
    }

    #[test]
    fn reads_3d_minimal_from_file() {
        let dir = scratch_dir("csv3d");
        let path = dir.join("p.csv");
        std::fs::write(&path, "X,Y,Z,Radius\n1,2,3,0.5\n").unwrap();
        let rows = read_particles_csv(&path, 3).unwrap();
        assert_eq!(rows[0].pos, [1.0, 2.0, 3.0]);
        assert_eq!(
            (rows[0].vel, rows[0].omega, rows[0].id, rows[0].kind),
            (None, None, None, None)
        );
    }

    fn msg(text: &str, dim: usize) -> String {
        parse_particles_csv(text, "init.csv", dim)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let m = msg("x,y,r\n1,1,1\n", 2);
        assert!(
            m.starts_with("init.csv:1: unknown column(s) 'r'")
                && m.contains("allowed: x, y, diameter"),
            "{m}"
        );
        assert!(msg("x,y,z,radius\n", 2).contains("unknown column(s) 'z' for a 2D system"));
        assert!(msg("x,y,omega,radius\n", 3).contains("'omega'"));
        assert!(msg("x,diameter\n", 2).contains("init.csv:1: missing required column 'y'"));
        assert!(msg("x,y\n", 2).contains("missing column 'diameter' or 'radius'"));
        assert!(msg("x,y,radius,diameter\n", 2).contains("not both"));
        assert!(msg("x,y,x,radius\n", 2).contains("column 3 ('x') repeats column 1"));
        let m = msg("x,y,radius\n\n1,2\n", 2);
        assert!(m.starts_with("init.csv:3: 2 fields"), "{m}");
        let m = msg("x,y,radius\n1,abc,1\n", 2);
        assert!(
            m.starts_with("init.csv:2: column 2 (y): 'abc' is not a finite number"),
            "{m}"
        );
        assert!(msg("x,y,radius\n1,1,-1\n", 2)
            .contains("init.csv:2: column 3 (radius): -1 must be positive"));
        assert!(msg("x,y,radius,frozen\n1,1,1,2\n", 2)
            .contains("column 4 (frozen): '2' must be 0 or 1"));
        assert!(msg("id,x,y,radius\n1,1,1,1\n1,2,2,1\n", 2)
            .contains("init.csv:3: column 1 (id): duplicate id 1 (first on line 2)"));
        assert!(msg("x,y,radius,type\n1,1,1,0\n", 2).contains("'0' is not a type"));
        assert!(msg("# only comments\n", 2).contains("init.csv: empty file"));
    }
}
