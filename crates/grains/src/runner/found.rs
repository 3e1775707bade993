//! Reading a checkpoint back: its payload decoded and checked ([`decode`]),
//! the newest valid file of a run directory ([`find`]), and the engine and
//! measurements it restores.

use super::engine::Engine;
use super::measurements::Measurements;
use super::output::OutputState;
use crate::checkpoint;
use crate::codec::Dec;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::scenario::schema::{Dimension, Scenario};
use crate::scenario::{build_md, Loaded, Resolved};
use std::path::{Path, PathBuf};

/// The (relax, measured) step plan of a resumed run: the checkpoint's own,
/// or, with `--steps n`, one that ends n steps after `step`. `origin` names
/// the checkpoint in messages.
pub(super) fn resume_plan(
    (relax, measure): (u64, u64),
    step: u64,
    steps: Option<u64>,
    origin: &str,
) -> Result<(u64, u64)> {
    match steps {
        Some(n) => {
            let end = step
                .checked_add(n)
                .ok_or_else(|| Error::input("--steps too large"))?;
            Ok(if end <= relax {
                (end, 0)
            } else {
                (relax, end - relax)
            })
        }
        None if step > relax + measure => Err(Error::input(format!(
            "checkpoint {origin}: step {step} lies beyond the run's end"
        ))),
        None => Ok((relax, measure)),
    }
}

fn decode_measurements(d: &mut Dec) -> std::result::Result<Option<Vec<u8>>, String> {
    if !d.bool("measurement flag")? {
        return Ok(None);
    }
    let n = d.len(1, "measurement state")?;
    Ok(Some(d.take(n, "measurement state")?.to_vec()))
}

fn read_opt(d: &mut Dec, what: &str) -> std::result::Result<Option<u64>, String> {
    let some = d.bool(what)?;
    let v = d.u64(what)?;
    Ok(some.then_some(v))
}

/// A checkpoint read and checked, ready to resume.
pub struct Found {
    pub path: PathBuf,
    pub step: u64,
    pub(super) loaded: Loaded,
    pub(super) dim: usize,
    pub(super) plan: (u64, u64),
    pub(super) interval: u64,
    pub(super) outputs: OutputState,
    pub(super) engine: Vec<u8>,
    pub(super) measurements: Option<Vec<u8>>,
}

/// Decodes a checkpoint payload (from `path`, for messages).
pub fn decode(payload: &[u8], path: &Path) -> Result<Found> {
    let mut d = Dec::new(payload);
    let mut go = || -> std::result::Result<_, String> {
        let scenario = d.str("scenario")?;
        let origin = d.str("scenario origin")?;
        let base_dir = d.str("scenario directory")?;
        let dim = d.u8("dimension")? as usize;
        let plan = (d.u64("relax steps")?, d.u64("measured steps")?);
        let interval = d.u64("checkpoint interval")?;
        let outputs = OutputState {
            thermo_len: d.u64("thermo length")?,
            dump_len: read_opt(&mut d, "dump length")?,
            frames: {
                let n = d.len(16, "frame count")?;
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push((d.f64("frame time")?, d.str("frame file")?));
                }
                v
            },
            last_step: read_opt(&mut d, "last output step")?,
        };
        let step = d.u64("step")?;
        let n = d.len(1, "engine state")?;
        let engine = d.take(n, "engine state")?.to_vec();
        let measurements = decode_measurements(&mut d)?;
        if d.remaining() != 0 {
            return Err(format!("{} unexpected bytes at the end", d.remaining()));
        }
        Ok((
            scenario,
            origin,
            base_dir,
            dim,
            plan,
            interval,
            outputs,
            step,
            engine,
            measurements,
        ))
    };
    let (scenario, origin, base_dir, dim, plan, interval, outputs, step, engine, measurements) =
        go().map_err(|e| Error::input(format!("checkpoint {}: {e}", path.display())))?;
    let scenario: Scenario = toml::from_str(&scenario).map_err(|e| {
        Error::input(format!(
            "checkpoint {}: its scenario does not parse: {e}",
            path.display()
        ))
    })?;
    let want = match scenario.dimension {
        Dimension::Two => 2,
        Dimension::Three => 3,
    };
    if dim != want {
        return Err(Error::input(format!(
            "checkpoint {}: state of dimension {dim} for a {want}d scenario",
            path.display()
        )));
    }
    if plan.0.checked_add(plan.1).is_none() {
        return Err(Error::input(format!(
            "checkpoint {}: run length out of range",
            path.display()
        )));
    }
    Ok(Found {
        path: path.to_path_buf(),
        step,
        loaded: Loaded {
            scenario,
            origin,
            base_dir: PathBuf::from(base_dir),
        },
        dim,
        plan,
        interval,
        outputs,
        engine,
        measurements,
    })
}

/// The checkpoint to resume from `path`: that file, or the newest valid
/// checkpoint of that run directory. Also returns why newer files were
/// skipped. Fails (input error) when none is usable, saying why for each.
pub fn find(path: &Path) -> Result<(Found, Vec<String>)> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_file() {
        let payload = checkpoint::read(path)?;
        return Ok((decode(&payload, path)?, Vec::new()));
    }
    let files = checkpoint::list(path)?;
    if files.is_empty() {
        return Err(Error::input(format!(
            "{}: no checkpoint-*.grck file; checkpoints are written by \
             `grains run --checkpoint-every T` or when a run is interrupted",
            path.display()
        )));
    }
    let mut skipped = Vec::new();
    for f in files {
        match checkpoint::read(&f).and_then(|p| decode(&p, &f)) {
            Ok(found) => return Ok((found, skipped)),
            Err(e) => skipped.push(e.to_string()),
        }
    }
    Err(Error::input(format!(
        "{}: no valid checkpoint:\n  {}",
        path.display(),
        skipped.join("\n  ")
    )))
}

/// What a resumed MD run starts from, every rank alike: the engine
/// restored from the checkpoint, the scenario's resolved settings, the step
/// plan, and the measurement accumulators when the checkpoint lies inside
/// the measurement.
pub(super) struct Restored<D: Dim> {
    pub md: Md<D>,
    pub resolved: crate::scenario::Resolved,
    pub plan: (u64, u64),
    pub measurements: Option<Measurements>,
}

impl Found {
    /// The checkpoint's scenario.
    pub fn loaded(&self) -> &Loaded {
        &self.loaded
    }

    /// A fresh engine of the checkpoint's scenario with the checkpoint's MD
    /// state in it.
    pub fn restore_md<D: Dim>(&self) -> Result<Md<D>> {
        self.restore_built::<D>().map(|(md, _)| md)
    }

    /// [`Found::restore_md`] with the scenario's resolved run parameters
    /// from the same build.
    pub(super) fn restore_built<D: Dim>(&self) -> Result<(Md<D>, Resolved)> {
        let (mut md, resolved) = build_md::<D>(&self.loaded)?;
        md.import(&self.engine, &self.path.display().to_string())?;
        if md.step != self.step {
            return Err(Error::input(format!(
                "checkpoint {}: header step {} but engine step {}",
                self.path.display(),
                self.step,
                md.step
            )));
        }
        Ok((md, resolved))
    }

    /// Everything a resumed MD run needs, checked; `steps`: `--steps`.
    pub(super) fn restore<D: Dim>(&self, steps: Option<u64>) -> Result<Restored<D>> {
        let loaded = &self.loaded;
        let (md, resolved) = self.restore_built::<D>()?;
        let path = self.path.display();
        let (relax, measure) = resume_plan(self.plan, md.step, steps, &path.to_string())?;
        let measurements = match &self.measurements {
            Some(bytes) if md.step > relax => Some(
                Measurements::load(loaded, &md, bytes)
                    .map_err(|e| Error::input(format!("checkpoint {path}: {e}")))?,
            ),
            Some(_) => {
                return Err(Error::input(format!(
                    "checkpoint {path}: measurement state at step {}, before the measurement begins",
                    md.step
                )))
            }
            None if md.step > relax => {
                return Err(Error::input(format!(
                    "checkpoint {path}: step {} lies in the measurement but carries no measurement state",
                    md.step
                )))
            }
            None => None,
        };
        Ok(Restored {
            md,
            resolved,
            plan: (relax, measure),
            measurements,
        })
    }
}
