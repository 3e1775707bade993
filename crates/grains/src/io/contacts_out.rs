//! The contacts of one frame as files: VTK polydata lines between the two
//! centres (ParaView and OVITO draw them as the force network) and CSV.
//! A wall contact is a line from the contact point to the grain's centre.

use super::contact_records::{dot, Snapshot};
use super::vtk_binary::{f64_array, i64_array};
use super::{push_num, write_atomic, Num, PvdCollection};
use crate::error::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Columns of `contacts/contacts_NNNNN.csv`: one row per contact; a wall
/// contact has `id2` empty, its wall's index and name, and its branch from
/// the contact point to the grain.
pub const CONTACT_COLUMNS: &str = "id1,id2,wall,wall_name,px,py,pz,bx,by,bz,nx,ny,nz,\
fnx,fny,fnz,ftx,fty,ftz,overlap";

/// The `.vtp` text (arrays in the inline binary format of `vtk_binary`):
/// one line cell per contact (points: both ends), cell
/// data `force` (magnitude), `normal_force` (signed, along the normal),
/// `tangential_force` (3), `overlap`, `id1`, `id2` (the second grain's id,
/// −1 for a wall) and `wall` (−1 for a pair).
pub fn contacts_vtp_string(s: &Snapshot) -> String {
    let n = s.contacts.len() + s.walls.len();
    let mut ends = Vec::with_capacity(2 * n);
    let mut force = Vec::with_capacity(n);
    let mut normal = Vec::with_capacity(n);
    let mut tangential = Vec::with_capacity(n);
    let mut overlap = Vec::with_capacity(n);
    let mut id1 = Vec::with_capacity(n);
    let mut id2 = Vec::with_capacity(n);
    let mut wall = Vec::with_capacity(n);
    for c in &s.contacts {
        let j = s.pos[c.index[1]];
        ends.push(j);
        ends.push([j[0] + c.branch[0], j[1] + c.branch[1], j[2] + c.branch[2]]);
        let f = c.force();
        force.push(dot(f, f).sqrt());
        normal.push(dot(c.force_n, c.normal));
        tangential.push(c.force_t);
        overlap.push(c.overlap);
        id1.push(c.ids[0] as i64);
        id2.push(c.ids[1] as i64);
        wall.push(-1);
    }
    for c in &s.walls {
        ends.push(c.point);
        ends.push(s.pos[c.index]);
        force.push(dot(c.force, c.force).sqrt());
        let fn_ = dot(c.force, c.normal);
        normal.push(fn_);
        tangential.push([0, 1, 2].map(|a| c.force[a] - fn_ * c.normal[a]));
        overlap.push(c.overlap);
        id1.push(c.id as i64);
        id2.push(-1);
        wall.push(c.wall as i64);
    }
    let mut x = String::from("<?xml version=\"1.0\"?>\n");
    x.push_str("<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    x.push_str("  <PolyData>\n    <FieldData>\n");
    let _ = writeln!(
        x,
        "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
        Num(s.time)
    );
    let _ = writeln!(
        x,
        "      <DataArray type=\"Int64\" Name=\"Step\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
        s.step
    );
    x.push_str("    </FieldData>\n");
    let _ = writeln!(
        x,
        "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{n}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">",
        2 * n
    );
    x.push_str("      <Points>\n");
    float_array(&mut x, "Points", 3, ends.iter().flatten().copied());
    x.push_str("      </Points>\n      <Lines>\n");
    int_array(&mut x, "connectivity", 0..2 * n as i64);
    int_array(&mut x, "offsets", (1..=n as i64).map(|k| 2 * k));
    x.push_str("      </Lines>\n      <CellData Scalars=\"force\">\n");
    float_array(&mut x, "force", 1, force.into_iter());
    float_array(&mut x, "normal_force", 1, normal.into_iter());
    float_array(
        &mut x,
        "tangential_force",
        3,
        tangential.iter().flatten().copied(),
    );
    float_array(&mut x, "overlap", 1, overlap.into_iter());
    int_array(&mut x, "id1", id1.into_iter());
    int_array(&mut x, "id2", id2.into_iter());
    int_array(&mut x, "wall", wall.into_iter());
    x.push_str("      </CellData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
    x
}

fn float_array(x: &mut String, name: &str, comps: usize, values: impl Iterator<Item = f64>) {
    f64_array(x, 8, name, comps, values);
}

fn int_array(x: &mut String, name: &str, values: impl Iterator<Item = i64>) {
    i64_array(x, 8, name, values);
}

/// The CSV text ([`CONTACT_COLUMNS`]), built by appending to one string
/// (no formatter per field: a frame holds thousands of rows).
pub fn contacts_csv_string(s: &Snapshot) -> String {
    // About 20 fields of up to 24 characters a row.
    let rows = s.contacts.len() + s.walls.len();
    let mut t = String::with_capacity(CONTACT_COLUMNS.len() + 1 + 400 * rows);
    t.push_str(CONTACT_COLUMNS);
    t.push('\n');
    let v3 = |t: &mut String, v: [f64; 3]| {
        for x in v {
            t.push(',');
            push_num(t, x);
        }
    };
    let mut int = itoa::Buffer::new();
    for c in &s.contacts {
        t.push_str(int.format(c.ids[0]));
        t.push(',');
        t.push_str(int.format(c.ids[1]));
        t.push_str(",,");
        v3(&mut t, c.point);
        v3(&mut t, c.branch);
        v3(&mut t, c.normal);
        v3(&mut t, c.force_n);
        v3(&mut t, c.force_t);
        t.push(',');
        push_num(&mut t, c.overlap);
        t.push('\n');
    }
    for c in &s.walls {
        t.push_str(int.format(c.id));
        t.push_str(",,");
        t.push_str(int.format(c.wall));
        t.push(',');
        t.extend(c.wall_name.chars().map(|ch| {
            if matches!(ch, ',' | '"' | '\n') {
                '_'
            } else {
                ch
            }
        }));
        v3(&mut t, c.point);
        let b = [0, 1, 2].map(|a| s.pos[c.index][a] - c.point[a]);
        v3(&mut t, b);
        v3(&mut t, c.normal);
        let fn_ = dot(c.force, c.normal);
        v3(&mut t, c.normal.map(|e| e * fn_));
        v3(&mut t, [0, 1, 2].map(|a| c.force[a] - fn_ * c.normal[a]));
        t.push(',');
        push_num(&mut t, c.overlap);
        t.push('\n');
    }
    t
}

/// The contact series of a run: `contacts/contacts_NNNNN.vtp` and `.csv`
/// per output frame, listed in `contacts.pvd`.
pub struct ContactSeries {
    dir: PathBuf,
    collection: PvdCollection,
}

impl ContactSeries {
    /// Creates `out_dir/contacts/` and a fresh series.
    pub fn new(out_dir: &Path) -> Result<Self> {
        let dir = out_dir.join("contacts");
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(Self {
            dir: out_dir.to_path_buf(),
            collection: PvdCollection::new(out_dir.join("contacts.pvd")),
        })
    }

    /// The series of a resumed run: the entries of `contacts.pvd` at times
    /// up to `upto` (the last frame the checkpoint saw; all without one)
    /// are kept, and the next frame follows them.
    pub fn resume(out_dir: &Path, upto: Option<f64>) -> Result<Self> {
        let mut series = Self::new(out_dir)?;
        let path = out_dir.join("contacts.pvd");
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        for line in text.lines() {
            let attr = |name: &str| {
                let key = format!("{name}=\"");
                let at = line.find(&key)? + key.len();
                line[at..].split('"').next().map(str::to_string)
            };
            let (Some(t), Some(file)) = (attr("timestep"), attr("file")) else {
                continue;
            };
            let Ok(t) = t.parse::<f64>() else {
                continue;
            };
            if upto.is_none_or(|u| t <= u) {
                series.collection.entries.push((t, file));
            }
        }
        series.collection.write()?;
        Ok(series)
    }

    /// Writes one frame's contacts and the updated `contacts.pvd`.
    pub fn write(&mut self, s: &Snapshot) -> Result<()> {
        let k = self.collection.entries.len();
        let vtp = format!("contacts/contacts_{k:05}.vtp");
        write_atomic(&self.dir.join(&vtp), contacts_vtp_string(s).as_bytes())?;
        let csv = format!("contacts/contacts_{k:05}.csv");
        write_atomic(&self.dir.join(csv), contacts_csv_string(s).as_bytes())?;
        self.collection.add(s.time, vtp)
    }
}
