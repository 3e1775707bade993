//! A run's checkpoint payload: the scenario as TOML with its origin and
//! absolute base directory, the files it read ([`super::inputs`]), the dimension, the run plan, the checkpoint interval,
//! where the output files stood, the step, the engine's exported state, the
//! measurement section (a flag, and when set the accumulators'
//! length-prefixed bytes) and the flow section (the same, for an MD run's
//! flow events and flow measurements, `scenario::flow`); written by
//! [`payload`], read back by [`decode`] and [`find`] (the newest valid file
//! of a run directory).

use super::inputs::{self, InputFile};
use crate::codec::{Dec, Enc};
use crate::error::{Error, Result};
use crate::scenario::schema::Scenario;
use crate::scenario::Loaded;
use std::path::{Path, PathBuf};

/// Where the output files stood when a checkpoint was taken: resuming cuts
/// them back to this point, so rows and frames written after the checkpoint
/// by the interrupted run are not duplicated.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputState {
    pub thermo_len: u64,
    pub dump_len: Option<u64>,
    /// The frames.pvd entries (time, file).
    pub frames: Vec<(f64, String)>,
    pub last_step: Option<u64>,
}

/// What every checkpoint payload, MD or DSMC, says about its run.
pub(crate) struct RunHeader {
    /// The scenario as TOML ([`scenario_text`]).
    pub scenario: String,
    pub origin: String,
    /// The scenario's base directory, absolute, so that a resume from
    /// another folder resolves its relative paths alike.
    pub base_dir: String,
    /// The files the scenario read, as they were.
    pub inputs: Vec<InputFile>,
    pub dim: usize,
    pub plan: (u64, u64),
    pub interval: Option<u64>,
}

impl RunHeader {
    /// The header of a run of `loaded` with step plan `plan` and checkpoint
    /// interval `interval`: its scenario text, absolute base directory and
    /// input files read now.
    pub(crate) fn new(loaded: &Loaded, plan: (u64, u64), interval: Option<u64>) -> Result<Self> {
        Ok(Self {
            scenario: scenario_text(&loaded.scenario)?,
            origin: loaded.origin.clone(),
            base_dir: inputs::absolute(&loaded.base_dir)
                .to_string_lossy()
                .into_owned(),
            inputs: inputs::of_scenario(loaded)?,
            dim: loaded.scenario.dimension.axes(),
            plan,
            interval,
        })
    }
}

/// Writes one checkpoint: the run header, where the outputs stood, the
/// step, the engine's bytes, the measurement section and the (MD) flow
/// section. [`decode`] reads exactly this layout, for both engines.
pub(crate) fn write_payload(
    dir: &Path,
    run: &RunHeader,
    outputs: &OutputState,
    step: u64,
    engine: &[u8],
    sections: (Option<&[u8]>, Option<&[u8]>),
) -> Result<PathBuf> {
    let payload = payload(run, outputs, step, engine, sections);
    super::write(dir, step, &payload)
}

/// The payload [`write_payload`] writes.
pub(crate) fn payload(
    run: &RunHeader,
    outputs: &OutputState,
    step: u64,
    engine: &[u8],
    (measurements, flow): (Option<&[u8]>, Option<&[u8]>),
) -> Vec<u8> {
    let mut e = Enc::default();
    e.str(&run.scenario);
    e.str(&run.origin);
    e.str(&run.base_dir);
    inputs::encode(&mut e, &run.inputs);
    e.u8(run.dim as u8);
    e.u64(run.plan.0);
    e.u64(run.plan.1);
    e.u64(run.interval.unwrap_or(0));
    encode_outputs(&mut e, outputs);
    e.u64(step);
    e.len(engine.len());
    e.buf.extend_from_slice(engine);
    encode_section(&mut e, measurements);
    encode_section(&mut e, flow);
    e.buf
}

/// The scenario as TOML text that reads back to an equal scenario.
pub(crate) fn scenario_text(s: &Scenario) -> Result<String> {
    let text = toml::to_string(s)
        .map_err(|e| Error::input(format!("checkpoint: cannot write the scenario: {e}")))?;
    match toml::from_str::<Scenario>(&text) {
        Ok(back) if back == *s => Ok(text),
        _ => Err(Error::input(
            "checkpoint: the scenario does not survive a TOML round trip; cannot checkpoint it",
        )),
    }
}

/// The measurement or flow section: a flag, then the state's bytes.
fn encode_section(e: &mut Enc, bytes: Option<&[u8]>) {
    e.bool(bytes.is_some());
    if let Some(b) = bytes {
        e.len(b.len());
        e.buf.extend_from_slice(b);
    }
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

fn decode_section(d: &mut Dec, what: &str) -> std::result::Result<Option<Vec<u8>>, String> {
    if !d.bool(what)? {
        return Ok(None);
    }
    let n = d.len(1, what)?;
    Ok(Some(d.take(n, what)?.to_vec()))
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
    pub(crate) loaded: Loaded,
    /// The files the scenario read when the run started.
    pub inputs: Vec<InputFile>,
    pub(crate) plan: (u64, u64),
    pub(crate) interval: u64,
    pub(crate) outputs: OutputState,
    pub(crate) engine: Vec<u8>,
    pub(crate) measurements: Option<Vec<u8>>,
    /// The MD flow run's state ([`crate::scenario::flow::FlowRun::save`]).
    pub(crate) flow: Option<Vec<u8>>,
    /// Set when the state continues under a changed scenario (a restart):
    /// the scenario keys that changed, which may be none.
    pub(crate) restart: Option<Vec<String>>,
    /// The checkpoint's own scenario when a restart replaced `loaded`: its
    /// flow state (inlets' and outlets' grains) is read under it.
    pub(crate) restarted_from: Option<Loaded>,
}

/// A payload's fields as read, before its scenario is parsed and checked.
struct Raw {
    scenario: String,
    origin: String,
    base_dir: String,
    inputs: Vec<InputFile>,
    dim: usize,
    plan: (u64, u64),
    interval: u64,
    outputs: OutputState,
    step: u64,
    engine: Vec<u8>,
    measurements: Option<Vec<u8>>,
    flow: Option<Vec<u8>>,
}

/// Reads the fields [`payload`] writes, in its order.
fn read_raw(d: &mut Dec) -> std::result::Result<Raw, String> {
    let raw = Raw {
        scenario: d.str("scenario")?,
        origin: d.str("scenario origin")?,
        base_dir: d.str("scenario directory")?,
        inputs: inputs::decode(d)?,
        dim: d.u8("dimension")? as usize,
        plan: (d.u64("relax steps")?, d.u64("measured steps")?),
        interval: d.u64("checkpoint interval")?,
        outputs: OutputState {
            thermo_len: d.u64("thermo length")?,
            dump_len: read_opt(d, "dump length")?,
            frames: {
                let n = d.len(16, "frame count")?;
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push((d.f64("frame time")?, d.str("frame file")?));
                }
                v
            },
            last_step: read_opt(d, "last output step")?,
        },
        step: d.u64("step")?,
        engine: {
            let n = d.len(1, "engine state")?;
            d.take(n, "engine state")?.to_vec()
        },
        measurements: decode_section(d, "measurement state")?,
        flow: decode_section(d, "flow state")?,
    };
    if d.remaining() != 0 {
        return Err(format!("{} unexpected bytes at the end", d.remaining()));
    }
    Ok(raw)
}

/// Decodes a checkpoint payload (from `path`, for messages).
pub fn decode(payload: &[u8], path: &Path) -> Result<Found> {
    let Raw {
        scenario,
        origin,
        base_dir,
        inputs,
        dim,
        plan,
        interval,
        outputs,
        step,
        engine,
        measurements,
        flow,
    } = read_raw(&mut Dec::new(payload))
        .map_err(|e| Error::input(format!("checkpoint {}: {e}", path.display())))?;
    let scenario: Scenario = toml::from_str(&scenario).map_err(|e| {
        Error::input(format!(
            "checkpoint {}: its scenario does not parse: {e}",
            path.display()
        ))
    })?;
    let want = scenario.dimension.axes();
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
        inputs,
        plan,
        interval,
        outputs,
        engine,
        measurements,
        flow,
        restart: None,
        restarted_from: None,
    })
}

/// The checkpoint to resume from `path`: that file, or the newest valid
/// checkpoint of that run directory. Also returns why newer files were
/// skipped. Fails (input error) when none is usable, saying why for each.
pub fn find(path: &Path) -> Result<(Found, Vec<String>)> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_file() {
        let payload = super::read(path)?;
        return Ok((decode(&payload, path)?, Vec::new()));
    }
    let files = super::list(path)?;
    if files.is_empty() {
        return Err(Error::input(format!(
            "{}: no checkpoint-*.grck file; checkpoints are written by \
             `grains run --checkpoint-every T` or when a run is interrupted",
            path.display()
        )));
    }
    let mut skipped = Vec::new();
    for f in files {
        match super::read(&f).and_then(|p| decode(&p, &f)) {
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

impl Found {
    /// The (relax, measured) step plan of the run resumed from here at
    /// engine step `step`: the checkpoint's own, or, with `--steps n`, one
    /// that ends n steps after `step`.
    pub(crate) fn resume_plan(&self, step: u64, steps: Option<u64>) -> Result<(u64, u64)> {
        let (relax, measure) = self.plan;
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
                "checkpoint {}: step {step} lies beyond the run's end",
                self.path.display()
            ))),
            None => Ok((relax, measure)),
        }
    }

    /// The checkpoint's scenario.
    pub fn loaded(&self) -> &Loaded {
        &self.loaded
    }

    /// Checks that the files the run read are as they were
    /// ([`inputs::verify`]); returns the changes let through by
    /// `allow_changed`.
    pub fn check_inputs(&self, allow_changed: bool) -> Result<Vec<String>> {
        inputs::verify(
            &self.inputs,
            &self.path.display().to_string(),
            allow_changed,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
