//! LAMMPS text dump output (`dump custom` style), readable by OVITO and by
//! LAMMPS's own tools. One file holds many snapshots, appended in turn.

use super::frame::Frame;
use super::Num;
use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes one snapshot in LAMMPS dump format to `out`.
///
/// Columns: `id type radius x y z vx vy vz`, then `mol` (the grain's body,
/// 0 for a free sphere) when the frame has bodies. Box bounds are flagged `pp`
/// along periodic axes and `ff` otherwise; a 2D frame is written with z
/// bounds `-0.5 0.5` and flag `pp`, as LAMMPS writes its 2D boxes.
pub fn write_snapshot(out: &mut impl Write, frame: &Frame) -> std::io::Result<()> {
    frame.check_lengths();
    let planar = frame.dim != 3;
    writeln!(out, "ITEM: TIMESTEP\n{}", frame.step)?;
    writeln!(out, "ITEM: NUMBER OF ATOMS\n{}", frame.len())?;
    let flag = |a: usize| {
        if frame.periodic[a] || (planar && a == 2) {
            "pp"
        } else {
            "ff"
        }
    };
    writeln!(out, "ITEM: BOX BOUNDS {} {} {}", flag(0), flag(1), flag(2))?;
    for a in 0..3 {
        let (lo, hi) = if planar && a == 2 {
            (-0.5, 0.5)
        } else {
            (frame.box_lo[a], frame.box_hi[a])
        };
        writeln!(out, "{} {}", Num(lo), Num(hi))?;
    }
    // `mol` only with bodies, so dumps of runs without clumps keep their
    // bytes; OVITO groups atoms of one molecule id into one cluster.
    let mol = if frame.body.is_some() { " mol" } else { "" };
    writeln!(out, "ITEM: ATOMS id type radius x y z vx vy vz{mol}")?;
    for i in 0..frame.len() {
        let [x, y, z] = frame.pos[i].map(Num);
        let [vx, vy, vz] = frame.vel[i].map(Num);
        let r = Num(frame.radius[i]);
        write!(
            out,
            "{} {} {r} {x} {y} {z} {vx} {vy} {vz}",
            frame.id[i], frame.kind[i]
        )?;
        match &frame.body {
            Some(b) => writeln!(out, " {}", b[i])?,
            None => writeln!(out)?,
        }
    }
    Ok(())
}

/// A dump file opened once; each [`DumpWriter::write`] appends a snapshot and
/// flushes it, so the file is always a sequence of complete snapshots.
pub struct DumpWriter {
    path: PathBuf,
    out: BufWriter<File>,
}

impl DumpWriter {
    /// Creates (or truncates) the dump file.
    pub fn create(path: &Path) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        Ok(DumpWriter {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
        })
    }

    /// Opens the dump file for appending, creating it if absent (for restarts).
    pub fn append(path: &Path) -> Result<Self> {
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        Ok(DumpWriter {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn write(&mut self, frame: &Frame) -> Result<()> {
        write_snapshot(&mut self.out, frame)
            .and_then(|_| self.out.flush())
            .map_err(|e| Error::io(&self.path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::frame::tests::sample_2d;

    struct Snap {
        step: u64,
        flags: Vec<String>,
        bounds: Vec<[f64; 2]>,
        rows: Vec<Vec<f64>>,
    }

    /// A minimal dump reader for the round trip.
    fn read_dump(text: &str) -> Vec<Snap> {
        let mut lines = text.lines();
        let mut snaps = Vec::new();
        while let Some(l) = lines.next() {
            assert_eq!(l, "ITEM: TIMESTEP");
            let step = lines.next().unwrap().parse().unwrap();
            assert_eq!(lines.next().unwrap(), "ITEM: NUMBER OF ATOMS");
            let n: usize = lines.next().unwrap().parse().unwrap();
            let bb = lines.next().unwrap();
            let flags = bb.strip_prefix("ITEM: BOX BOUNDS ").unwrap();
            let flags = flags.split_whitespace().map(String::from).collect();
            let bounds = (0..3)
                .map(|_| {
                    let v: Vec<f64> = lines
                        .next()
                        .unwrap()
                        .split(' ')
                        .map(|t| t.parse().unwrap())
                        .collect();
                    [v[0], v[1]]
                })
                .collect();
            assert_eq!(
                lines.next().unwrap(),
                "ITEM: ATOMS id type radius x y z vx vy vz"
            );
            let rows = (0..n)
                .map(|_| {
                    lines
                        .next()
                        .unwrap()
                        .split(' ')
                        .map(|t| t.parse().unwrap())
                        .collect()
                })
                .collect();
            snaps.push(Snap {
                step,
                flags,
                bounds,
                rows,
            });
        }
        snaps
    }

    #[test]
    fn round_trip_two_snapshots() {
        let dir = scratch_dir("dump");
        let path = dir.join("run.dump");
        let mut f = sample_2d();
        let mut w = DumpWriter::create(&path).unwrap();
        w.write(&f).unwrap();
        f.step = 1300;
        f.pos[2][1] = 1.0 / 3.0;
        w.write(&f).unwrap();
        drop(w);
        let snaps = read_dump(&std::fs::read_to_string(&path).unwrap());
        assert_eq!(snaps.len(), 2);
        assert_eq!(snaps[0].step, 1200);
        assert_eq!(snaps[1].step, 1300);
        assert_eq!(snaps[0].flags, ["pp", "ff", "pp"]);
        assert_eq!(snaps[0].bounds, vec![[0.0, 10.0], [0.0, 20.0], [-0.5, 0.5]]);
        let s = &snaps[1];
        for i in 0..3 {
            let r = &s.rows[i];
            assert_eq!(r[0], f.id[i] as f64);
            assert_eq!(r[1], f.kind[i] as f64);
            assert_eq!(r[2], f.radius[i]);
            assert_eq!(&r[3..6], &f.pos[i]);
            assert_eq!(&r[6..9], &f.vel[i]);
        }
    }

    #[test]
    fn three_d_uses_box_z_and_flags() {
        let mut f = sample_2d();
        f.dim = 3;
        f.box_lo[2] = -2.0;
        f.box_hi[2] = 7.5;
        f.periodic = [true, true, false];
        let mut buf = Vec::new();
        write_snapshot(&mut buf, &f).unwrap();
        let snaps = read_dump(std::str::from_utf8(&buf).unwrap());
        assert_eq!(snaps[0].flags, ["pp", "pp", "ff"]);
        assert_eq!(snaps[0].bounds[2], [-2.0, 7.5]);
    }

    #[test]
    fn append_keeps_earlier_snapshots() {
        let dir = scratch_dir("dump-append");
        let path = dir.join("a.dump");
        let f = sample_2d();
        DumpWriter::create(&path).unwrap().write(&f).unwrap();
        DumpWriter::append(&path).unwrap().write(&f).unwrap();
        assert_eq!(read_dump(&std::fs::read_to_string(&path).unwrap()).len(), 2);
    }
}
