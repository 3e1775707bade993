//! Checkpoints of a scenario run, and resuming one.
//!
//! A run with `checkpoint_every` writes `checkpoint-<step>.grck` files into
//! its output directory (at step 0, then at every interval, and when asked
//! to stop); [`find`] + [`resume`] continue from the newest valid one,
//! cutting thermo.csv, the dump and frames.pvd back to where they stood at
//! the checkpoint, so no row or frame is written twice.
//!
//! Payload (inside the sealed file of [`crate::checkpoint`]): the scenario
//! as TOML with its origin and base directory, the dimension, the run plan
//! (relaxation and measured steps), the checkpoint interval, the output
//! state, then the engine (fingerprint + state), then the measurement
//! accumulators (a flag, and when set their length-prefixed bytes: absent
//! in a checkpoint taken before the measurement began).

use super::engine::Engine;
use super::md_run::{run_loop, Start};
use super::output::{OutputState, Outputs};
use super::run_loop::Saved;
use super::{prepare, Measurements, Progress, RunOptions};
use crate::checkpoint;
use crate::checkpoint::codec::{Dec, Enc};
use crate::dim::{Dim, D2, D3};
use crate::error::{Error, Result};
use crate::md::Md;
use crate::scenario::schema::{Dimension, Scenario};
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A checkpoint interval: simulated seconds or a number of steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Every {
    Seconds(f64),
    Steps(u64),
}

impl Every {
    /// Parses `0.01` (seconds) or `500steps` / `500 steps`.
    pub fn parse(text: &str) -> Result<Self> {
        let t = text.trim();
        let bad = || {
            Error::input(format!(
                "--checkpoint-every '{text}': give simulated seconds (e.g. 0.01) \
                 or a step count (e.g. 500steps)"
            ))
        };
        if let Some(n) = t.strip_suffix("steps").or_else(|| t.strip_suffix("step")) {
            let n: u64 = n.trim().parse().map_err(|_| bad())?;
            if n == 0 {
                return Err(bad());
            }
            return Ok(Every::Steps(n));
        }
        let s = t.strip_suffix('s').unwrap_or(t).trim();
        let v: f64 = s.parse().map_err(|_| bad())?;
        if !(v.is_finite() && v > 0.0) {
            return Err(bad());
        }
        Ok(Every::Seconds(v))
    }

    /// The interval in steps of `dt` (at least one).
    pub fn steps(self, dt: f64) -> u64 {
        match self {
            Every::Steps(n) => n.max(1),
            Every::Seconds(t) => {
                let n = (t / dt).round();
                if n >= 1.0 && n < u64::MAX as f64 {
                    n as u64
                } else {
                    1
                }
            }
        }
    }
}

/// Why a scenario's state cannot be checkpointed yet, if it cannot: the
/// flow events (settling, recycling) and the measurements the flow run keeps
/// (repose, surface_angle, spacetime) are not part of a checkpoint.
fn blocker(scenario: &Scenario) -> Option<String> {
    let mesh = |w: &&crate::scenario::schema::WallSpec| {
        matches!(w.shape, crate::scenario::schema::ShapeSpec::Mesh { .. })
    };
    if let Some(w) = scenario.walls.iter().find(mesh) {
        return Some(format!(
            "checkpoints do not carry the tangential springs of mesh walls yet (wall '{}'); \
             run this scenario without --checkpoint-every",
            w.name
        ));
    }
    if scenario.hopper.is_some() || scenario.run.events.is_some() {
        return Some(
            "checkpoints do not carry the state of [hopper] recycling or run.events yet; \
             run this scenario without --checkpoint-every"
                .to_string(),
        );
    }
    let m = &scenario.measure;
    let flow: Vec<&str> = [
        ("measure.repose", m.repose.is_some()),
        ("measure.surface_angle", m.surface_angle.is_some()),
        ("measure.spacetime", m.spacetime.is_some()),
    ]
    .into_iter()
    .filter_map(|(k, on)| on.then_some(k))
    .collect();
    if flow.is_empty() {
        return None;
    }
    Some(format!(
        "checkpoints do not carry the state of {} yet; remove {} (or --set it off) \
         to checkpoint this run",
        flow.join(", "),
        if flow.len() == 1 { "it" } else { "them" }
    ))
}

/// Writes the checkpoints of one run, MD or DSMC: the run loop calls it
/// when a hook asks for one ([`super::run_loop::Control`]).
pub(crate) struct Checkpointer {
    dir: PathBuf,
    interval: Option<u64>,
    /// Why this scenario cannot be checkpointed, if it cannot.
    blocked: Option<String>,
    scenario: String,
    origin: String,
    base_dir: String,
    plan: (u64, u64),
}

impl Checkpointer {
    /// The checkpoints of a run of `loaded` with time step `dt` and
    /// (relaxation, measured) steps `plan`; refuses `--checkpoint-every`
    /// for a scenario whose state a checkpoint does not carry.
    pub(crate) fn new(
        loaded: &Loaded,
        opts: &RunOptions,
        dt: f64,
        plan: (u64, u64),
    ) -> Result<Self> {
        let blocked = match loaded.scenario.method {
            crate::dsmc::Method::Dsmc => None,
            _ => blocker(&loaded.scenario),
        };
        if let (Some(_), Some(why)) = (opts.checkpoint_every, &blocked) {
            return Err(Error::input(format!("--checkpoint-every: {why}")));
        }
        let scenario = scenario_text(&loaded.scenario)?;
        Ok(Self {
            dir: opts.out_dir.clone(),
            interval: opts.checkpoint_every.map(|e| e.steps(dt)),
            blocked,
            scenario,
            origin: loaded.origin.clone(),
            base_dir: loaded.base_dir.to_string_lossy().into_owned(),
            plan,
        })
    }

    /// Checkpoints into `dir` at `interval` of a run with no scenario text
    /// (for the run loop's tests).
    #[cfg(test)]
    pub(crate) fn in_dir(dir: &Path, interval: Option<u64>) -> Self {
        Self {
            dir: dir.to_path_buf(),
            interval,
            blocked: None,
            scenario: String::new(),
            origin: String::new(),
            base_dir: String::new(),
            plan: (0, 0),
        }
    }

    /// The interval in steps, when the run takes checkpoints.
    pub(crate) fn interval(&self) -> Option<u64> {
        self.interval
    }

    /// Whether the interval asks for a checkpoint at `step`.
    pub(crate) fn due(&self, step: u64) -> bool {
        self.interval.is_some_and(|n| step.is_multiple_of(n))
    }

    /// The summary of a run stopped by a signal at the step `engine` stands
    /// at, with a checkpoint there unless the scenario cannot take one.
    pub(crate) fn interrupt(&self, engine: &dyn Engine, saved: &Saved) -> Result<Value> {
        let (step, time) = (engine.step_count(), engine.sim_time());
        if let Some(why) = &self.blocked {
            return Ok(json!({
                "interrupted": true,
                "step": step,
                "time": time,
                "checkpoint": Value::Null,
                "message": format!("stopped at step {step} without a checkpoint: {why}"),
            }));
        }
        let path = self.write(engine, saved)?;
        Ok(json!({
            "interrupted": true,
            "step": step,
            "time": time,
            "checkpoint": path.display().to_string(),
            "message": format!(
                "stopped at step {step} (t = {time:.6e} s); checkpoint {}; continue with: grains resume {}",
                path.display(), self.dir.display()
            ),
        }))
    }

    /// Writes the checkpoint of `engine` with the hooks' `saved` parts.
    pub(crate) fn write(&self, engine: &dyn Engine, saved: &Saved) -> Result<PathBuf> {
        let run = RunHeader {
            scenario: &self.scenario,
            origin: &self.origin,
            base_dir: &self.base_dir,
            dim: engine.dim(),
            plan: self.plan,
            interval: self.interval,
        };
        let outputs = saved.outputs.clone().unwrap_or_default();
        write_payload(
            &self.dir,
            &run,
            &outputs,
            engine.step_count(),
            &engine.export()?,
            saved.measurements.as_deref(),
        )
    }
}

/// What every checkpoint payload, MD or DSMC, says about its run.
pub(super) struct RunHeader<'a> {
    pub scenario: &'a str,
    pub origin: &'a str,
    pub base_dir: &'a str,
    pub dim: usize,
    pub plan: (u64, u64),
    pub interval: Option<u64>,
}

/// Writes one checkpoint: the run header, where the outputs stood, the
/// step, the engine's bytes and the (MD) measurement section. [`decode`]
/// reads exactly this layout, for both engines.
pub(super) fn write_payload(
    dir: &Path,
    run: &RunHeader,
    outputs: &OutputState,
    step: u64,
    engine: &[u8],
    measurements: Option<&[u8]>,
) -> Result<PathBuf> {
    let payload = payload(run, outputs, step, engine, measurements);
    checkpoint::write(dir, step, &payload)
}

/// The payload [`write_payload`] writes.
pub(super) fn payload(
    run: &RunHeader,
    outputs: &OutputState,
    step: u64,
    engine: &[u8],
    measurements: Option<&[u8]>,
) -> Vec<u8> {
    let mut e = Enc::default();
    e.str(run.scenario);
    e.str(run.origin);
    e.str(run.base_dir);
    e.u8(run.dim as u8);
    e.u64(run.plan.0);
    e.u64(run.plan.1);
    e.u64(run.interval.unwrap_or(0));
    encode_outputs(&mut e, outputs);
    e.u64(step);
    e.len(engine.len());
    e.buf.extend_from_slice(engine);
    encode_measurements(&mut e, measurements);
    e.buf
}

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

/// The scenario as TOML text that reads back to an equal scenario.
pub(super) fn scenario_text(s: &Scenario) -> Result<String> {
    let text = toml::to_string(s)
        .map_err(|e| Error::input(format!("checkpoint: cannot write the scenario: {e}")))?;
    match toml::from_str::<Scenario>(&text) {
        Ok(back) if back == *s => Ok(text),
        _ => Err(Error::input(
            "checkpoint: the scenario does not survive a TOML round trip; cannot checkpoint it",
        )),
    }
}

/// The measurement section: a flag, then the accumulators' bytes.
fn encode_measurements(e: &mut Enc, bytes: Option<&[u8]>) {
    e.bool(bytes.is_some());
    if let Some(b) = bytes {
        e.len(b.len());
        e.buf.extend_from_slice(b);
    }
}

fn decode_measurements(d: &mut Dec) -> std::result::Result<Option<Vec<u8>>, String> {
    if !d.bool("measurement flag")? {
        return Ok(None);
    }
    let n = d.len(1, "measurement state")?;
    Ok(Some(d.take(n, "measurement state")?.to_vec()))
}

fn encode_outputs(e: &mut Enc, o: &OutputState) {
    e.u64(o.thermo_len);
    opt(e, o.dump_len);
    e.len(o.frames.len());
    for (t, f) in &o.frames {
        e.f64(*t);
        e.str(f);
    }
    opt(e, o.last_step);
}

fn opt(e: &mut Enc, v: Option<u64>) {
    e.bool(v.is_some());
    e.u64(v.unwrap_or(0));
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
    loaded: Loaded,
    pub(super) dim: usize,
    pub(super) plan: (u64, u64),
    interval: u64,
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

/// Continues a run from a checkpoint: to the end of its scenario, or for
/// `steps` more steps. Outputs go to the checkpoint's directory.
pub fn resume(
    found: Found,
    steps: Option<u64>,
    opts: RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    crate::parallel::on_pool(move || resume_on_pool(found, steps, opts, progress))
}

/// The options of a resumed run: its outputs go to the checkpoint's
/// directory, and it keeps the checkpoint's interval unless given another.
pub(super) fn resume_options(found: &Found, mut opts: RunOptions) -> RunOptions {
    let dir = found
        .path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    opts.out_dir = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir
    };
    if opts.checkpoint_every.is_none() && found.interval > 0 {
        opts.checkpoint_every = Some(Every::Steps(found.interval));
    }
    opts
}

/// Rank 0's (or a single process's) preparation of a resumed run's directory.
pub(super) fn prepare_resume(opts: &RunOptions) -> Result<()> {
    prepare(&opts.out_dir)?;
    checkpoint::remove_stale_temporaries(&opts.out_dir);
    Ok(())
}

fn resume_on_pool(
    found: Found,
    steps: Option<u64>,
    opts: RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let opts = resume_options(&found, opts);
    prepare_resume(&opts)?;
    if found.loaded.scenario.method == crate::dsmc::Method::Dsmc {
        return super::dsmc::resume(&found, steps, &opts, progress);
    }
    match found.dim {
        2 => resume_dim::<D2>(found, steps, &opts, progress),
        _ => resume_dim::<D3>(found, steps, &opts, progress),
    }
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

fn resume_dim<D: Dim>(
    found: Found,
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let r = found.restore::<D>(steps)?;
    let loaded = &found.loaded;
    let outputs = Outputs::resume(&opts.out_dir, &loaded.scenario.output, &found.outputs)?;
    let start = Start {
        md: r.md,
        resolved: r.resolved,
        outputs,
        plan: r.plan,
        restored: r.measurements,
    };
    run_loop(loaded, opts, start, progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_parse() {
        assert_eq!(Every::parse("0.01").unwrap(), Every::Seconds(0.01));
        assert_eq!(Every::parse("500steps").unwrap(), Every::Steps(500));
        assert_eq!(Every::parse("20 steps").unwrap(), Every::Steps(20));
        assert_eq!(Every::Seconds(0.01).steps(1e-4), 100);
        for bad in ["", "0", "-1", "nan", "0steps", "xsteps", "inf"] {
            assert!(Every::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn shipped_scenarios_survive_toml_round_trip() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
        for f in std::fs::read_dir(dir).unwrap() {
            let p = f.unwrap().path();
            // scenarios/meshes/ holds the mesh scenarios' STL files.
            if p.extension().is_none_or(|e| e != "toml") {
                continue;
            }
            let l = crate::scenario::load_file(&p, &[]).unwrap();
            scenario_text(&l.scenario).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        }
    }
}
