//! `grains cg`: a finished run's fields computed again from its saved
//! frames and contacts, with another kernel, width or grid.
//!
//! The run must have written `fields.json` (it had `[measure.fields]`),
//! its frames (`output.frames`) and its contacts (`output.contacts`, which
//! also saves each grain's mass with the frames). Every frame after the
//! measurement's first step, from `measure.fields.start` on, is one
//! sample; with the frames at the run's own sample steps (`output.every` a
//! multiple of `measure.fields.every` steps, the relaxation too) and the
//! run's kernel, width and grid, the fields are the run's again.

use super::{FieldsMeasure, Snapshot};
use crate::error::{Error, Result};
use crate::io::contacts_read::read_contacts_csv;
use crate::io::{read_collection, read_frame, read_series};
use crate::scenario::schema::FieldsSpec;
use std::collections::HashMap;
use std::path::Path;

/// What to change of the run's `[measure.fields]` (None: the run's own).
#[derive(Clone, Debug, Default)]
pub struct Recompute {
    /// "gaussian" (or "gauss") or "lucy".
    pub kernel: Option<String>,
    /// The kernel's width in units of d0.
    pub width: Option<f64>,
    /// "AXIS:CELLS,…" (e.g. "y:60" or "x:20,z:40"), or "box".
    pub grid: Option<String>,
}

/// What a recomputation read and wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Replayed {
    /// The frames sampled.
    pub samples: usize,
    /// Of those, how many are not at the run's own sample steps.
    pub off_schedule: usize,
    /// The windows written.
    pub windows: usize,
}

/// Recomputes the fields of `run_dir` with the changes `r` and writes
/// them into `out` (fields/, fields.pvd, fields.json).
pub fn recompute(run_dir: &Path, out: &Path, r: &Recompute) -> Result<Replayed> {
    let settings_path = run_dir.join("fields.json");
    let text = std::fs::read_to_string(&settings_path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => Error::input(format!(
            "{}: not found; `grains cg` recomputes the fields of a run that had \
             [measure.fields] and wrote output.frames = true and output.contacts = true",
            settings_path.display()
        )),
        _ => Error::io(&settings_path, e),
    })?;
    let bad = |what: &str| {
        Error::input(format!(
            "{}: {what} (not written by this version of grains?)",
            settings_path.display()
        ))
    };
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|_| bad("not JSON"))?;
    let mut spec: FieldsSpec =
        serde_json::from_value(v["fields"].clone()).map_err(|_| bad("no fields table"))?;
    let num = |key: &str| {
        v[key]
            .as_f64()
            .ok_or_else(|| bad(&format!("no number {key}")))
    };
    let triple = |key: &str| -> Result<[f64; 3]> {
        serde_json::from_value(v[key].clone()).map_err(|_| bad(&format!("no 3-vector {key}")))
    };
    let periodic: [bool; 3] =
        serde_json::from_value(v["periodic"].clone()).map_err(|_| bad("no periodic"))?;
    let (d0, dim, begun) = (num("d0")?, num("dim")? as usize, num("begin_step")? as u64);
    let bx = (triple("lo")?, triple("hi")?, periodic);
    apply(&mut spec, r, dim)?;
    let mut measure = FieldsMeasure::begin(&spec, d0, dim, bx)?.begun_at(begun);

    let contacts = read_collection(
        run_dir,
        "contacts.pvd",
        "the run wrote no contacts; `grains cg` needs output.contacts = true",
    )?;
    let by_time: HashMap<u64, &Path> = contacts
        .iter()
        .map(|e| (e.time.to_bits(), e.path.as_path()))
        .collect();
    let mut used = Replayed {
        samples: 0,
        off_schedule: 0,
        windows: 0,
    };
    for entry in read_series(run_dir)? {
        if entry.time < spec.start {
            continue;
        }
        let frame = read_frame(&entry.path)?;
        if frame.step <= begun {
            continue;
        }
        if frame.mass.is_empty() {
            return Err(Error::input(format!(
                "{}: the frame holds no grain masses; `grains cg` needs a run that wrote \
                 output.contacts = true (which saves them with the frames)",
                entry.path.display()
            )));
        }
        let Some(vtp) = by_time.get(&entry.time.to_bits()) else {
            return Err(Error::input(format!(
                "{}: no contacts at time {} (the frame's) in contacts.pvd",
                run_dir.display(),
                entry.time
            )));
        };
        let mut s = Snapshot {
            dim,
            time: frame.time,
            step: frame.step,
            id: frame.id,
            pos: frame.pos,
            vel: frame.vel,
            mass: frame.mass,
            radius: frame.radius,
            lo: bx.0,
            hi: bx.1,
            periodic,
            ..Snapshot::default()
        };
        read_contacts_csv(&vtp.with_extension("csv"), &mut s)?;
        used.off_schedule += usize::from(!measure.due(s.step));
        used.samples += 1;
        measure.sample(&s);
    }
    if used.samples == 0 {
        return Err(Error::input(format!(
            "{}: no frame after the measurement's first step ({begun}) from \
             measure.fields.start = {} s on; nothing to coarse-grain",
            run_dir.display(),
            spec.start
        )));
    }
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    measure.write(out)?;
    used.windows = measure.window_count();
    Ok(used)
}

/// The changes `r` applied to the run's table, each checked by its
/// option's name.
fn apply(spec: &mut FieldsSpec, r: &Recompute, dim: usize) -> Result<()> {
    if let Some(k) = &r.kernel {
        spec.kernel = match k.as_str() {
            "gauss" | "gaussian" => "gaussian".into(),
            "lucy" => "lucy".into(),
            other => {
                return Err(Error::input(format!(
                    "--kernel {other}: allowed gauss (or gaussian), lucy"
                )))
            }
        };
    }
    if let Some(w) = r.width {
        if !(w.is_finite() && w > 0.0) {
            return Err(Error::input(format!(
                "--width {w}: must be positive (units of d0)"
            )));
        }
        spec.width = w;
    }
    if let Some(g) = &r.grid {
        let (axes, cells) = parse_grid(g, dim)?;
        spec.axes = axes;
        spec.cells = cells;
    }
    Ok(())
}

/// `--grid`: "box", or "AXIS:CELLS" entries joined by commas.
pub fn parse_grid(g: &str, dim: usize) -> Result<(Vec<String>, Vec<usize>)> {
    let names = &["x", "y", "z"][..dim];
    let mut axes: Vec<String> = Vec::new();
    let mut cells = Vec::new();
    if g.trim() == "box" {
        return Ok((axes, cells));
    }
    for part in g.split(',') {
        let bad = || {
            Error::input(format!(
                "--grid {g}: \"{part}\" is not AXIS:CELLS with AXIS one of {names:?} and \
                 CELLS a count of points above 0 (or give --grid box)"
            ))
        };
        let (a, n) = part.trim().split_once(':').ok_or_else(bad)?;
        let n = n.trim().parse::<usize>().map_err(|_| bad())?;
        let a = a.trim();
        if !names.contains(&a) || n == 0 || axes.iter().any(|x| x == a) {
            return Err(bad());
        }
        axes.push(a.to_string());
        cells.push(n);
    }
    Ok((axes, cells))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_are_read_or_refused_by_name() {
        let ok = parse_grid("y:60", 2).unwrap();
        assert_eq!(ok, (vec!["y".to_string()], vec![60]));
        let ok = parse_grid("z:40, x:20", 3).unwrap();
        assert_eq!(ok.0, ["z", "x"]);
        assert_eq!(parse_grid("box", 3).unwrap().1, Vec::<usize>::new());
        for bad in ["z:10", "y", "y:0", "y:ten", "y:4,y:5"] {
            let err = parse_grid(bad, 2).unwrap_err().to_string();
            assert!(
                err.contains("--grid") && err.contains("AXIS:CELLS"),
                "{err}"
            );
        }
    }
}
