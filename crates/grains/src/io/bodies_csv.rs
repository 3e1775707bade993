//! bodies.csv: the rigid clumps of a run, one row per body at each output
//! step (position of the centre of mass, orientation quaternion, velocity,
//! angular momentum and angular velocity, all in the space frame).
//!
//! The table is long: every output step appends its bodies' rows, so one
//! file holds the whole run. A resumed run cuts the rows after the
//! checkpoint's last output step and goes on appending, as thermo.csv does.

use super::Num;
use crate::error::{Error, Result};
use std::fmt::Write as _;
use std::fs::File;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The table's columns, in file order.
pub const BODY_COLUMNS: [&str; 20] = [
    "step", "time", "id", "shape", "x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "Lx",
    "Ly", "Lz", "wx", "wy", "wz",
];

/// One body at one instant, in the space frame.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyRow {
    /// The body's number from 1 (the `body` array of frames, the `mol`
    /// column of dumps).
    pub id: u64,
    /// Its shape's name.
    pub shape: String,
    pub pos: [f64; 3],
    /// Unit quaternion (w, x, y, z) from the body's principal frame to space.
    pub quat: [f64; 4],
    pub vel: [f64; 3],
    /// Angular momentum about the centre of mass.
    pub ang_mom: [f64; 3],
    pub omega: [f64; 3],
}

/// bodies.csv, opened at the first output step that has bodies.
pub struct BodyTable {
    path: PathBuf,
    /// Open for appending once the first rows are due.
    file: Option<File>,
    /// A resumed run: the last output step the checkpoint saw (`None`: no
    /// output step yet), rows after it to be cut before appending.
    resume_after: Option<Option<u64>>,
}

impl BodyTable {
    /// The table of a fresh run in `dir` (created when rows come).
    pub fn new(dir: &Path) -> Self {
        Self {
            path: dir.join("bodies.csv"),
            file: None,
            resume_after: None,
        }
    }

    /// The table of a resumed run, cut back to `last_step` when rows come.
    pub fn resume(dir: &Path, last_step: Option<u64>) -> Self {
        Self {
            resume_after: Some(last_step),
            ..Self::new(dir)
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends the rows of one output step.
    pub fn write(&mut self, step: u64, time: f64, rows: &[BodyRow]) -> Result<()> {
        let path = self.path.clone();
        let io = |e| Error::io(&path, e);
        if self.file.is_none() {
            self.file = Some(self.open()?);
        }
        let mut s = String::with_capacity(rows.len() * 300);
        for r in rows {
            let _ = write!(s, "{step},{},{},{}", Num(time), r.id, r.shape);
            let values = r.pos.iter().chain(&r.quat).chain(&r.vel);
            for v in values.chain(&r.ang_mom).chain(&r.omega) {
                let _ = write!(s, ",{}", Num(*v));
            }
            s.push('\n');
        }
        let file = self.file.as_mut().expect("opened above");
        file.write_all(s.as_bytes()).map_err(io)
    }

    /// A fresh file with its header, or a resumed one without the rows
    /// after the checkpoint's last output step.
    fn open(&mut self) -> Result<File> {
        let path = &self.path;
        let io = |e| Error::io(path, e);
        let kept = match self.resume_after {
            Some(last) if path.exists() => {
                let text = std::fs::read_to_string(path).map_err(io)?;
                let mut lines = text.lines();
                let mut kept = String::new();
                if let Some(h) = lines.next() {
                    kept.push_str(h);
                    kept.push('\n');
                }
                for line in lines {
                    let step = line.split(',').next().and_then(|s| s.parse::<u64>().ok());
                    let Some(step) = step else {
                        return Err(Error::input(format!(
                            "{}: row '{line}' does not start with a step; the run directory \
                             was changed after the checkpoint",
                            path.display()
                        )));
                    };
                    if last.is_some_and(|l| step <= l) {
                        kept.push_str(line);
                        kept.push('\n');
                    }
                }
                kept
            }
            _ => BODY_COLUMNS.join(",") + "\n",
        };
        let mut file = File::create(path).map_err(io)?;
        file.write_all(kept.as_bytes()).map_err(io)?;
        Ok(file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;

    fn row(id: u64) -> BodyRow {
        BodyRow {
            id,
            shape: "rod".into(),
            pos: [1.0, 2.0, 3.0],
            quat: [0.5, 0.5, -0.5, 0.5],
            vel: [0.25, 0.0, -1.0],
            ang_mom: [1e-9, 0.0, 2e-9],
            omega: [3.0, 0.0, -0.125],
        }
    }

    /// Rows after a header, one per body and output step; a resume keeps
    /// the rows up to its last output step and appends after them.
    #[test]
    fn rows_are_written_and_cut_back_on_resume() {
        let dir = scratch_dir("bodies_csv");
        let mut t = BodyTable::new(&dir);
        t.write(0, 0.0, &[row(1), row(2)]).unwrap();
        t.write(10, 0.5, &[row(1), row(2)]).unwrap();
        t.write(20, 1.0, &[row(1), row(2)]).unwrap();
        let text = std::fs::read_to_string(t.path()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], BODY_COLUMNS.join(","));
        assert_eq!(lines.len(), 7);
        assert_eq!(
            lines[3],
            "10,0.5,1,rod,1,2,3,0.5,0.5,-0.5,0.5,0.25,0,-1,1e-9,0,2e-9,3,0,-0.125"
        );
        let mut t = BodyTable::resume(&dir, Some(10));
        t.write(20, 1.0, &[row(1), row(2)]).unwrap();
        let again = std::fs::read_to_string(t.path()).unwrap();
        assert_eq!(again, text, "cut after step 10, then step 20 again");
        let mut t = BodyTable::resume(&dir, None);
        t.write(0, 0.0, &[row(1)]).unwrap();
        let fresh = std::fs::read_to_string(t.path()).unwrap();
        assert_eq!(fresh.lines().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
