//! The MD engine's side of the [`Engine`] contract: its steps, its frame,
//! and its state to and from checkpoint bytes: a fingerprint of the
//! settings the state depends on (checked on restore, so a checkpoint never
//! starts a different scenario silently), then the [`MdState`].

use super::codec::{decode_md, encode_md};
use super::{Md, MdState};
use crate::codec::{Dec, Enc};
use crate::dim::Dim;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::io::Frame;
use serde_json::{json, Map, Value};

impl<D: Dim> Engine for Md<D> {
    fn dim(&self) -> usize {
        D::D
    }
    fn step_count(&self) -> u64 {
        self.step
    }
    fn sim_time(&self) -> f64 {
        self.time
    }
    fn time_step(&self) -> f64 {
        self.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        Md::advance(self, n)
    }
    fn frame(&self) -> Result<Frame> {
        Ok(Md::frame(self))
    }
    fn export(&self) -> Result<Vec<u8>> {
        encode(self)
    }
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()> {
        if crate::dsmc::contract::is_dsmc(bytes) {
            return Err(Error::input(format!(
                "checkpoint {origin}: holds a DSMC engine state, but its scenario is an MD run \
                 (method = \"dsmc\" is not set); the file cannot be resumed as MD"
            )));
        }
        restore(self, bytes).map_err(|e| Error::input(format!("{origin}: {e}")))
    }
}

/// What a serial MD engine adds to summary.json: its neighbour builds, the
/// seconds per phase of the step (`other` is mostly measurements and
/// output), and how the governor ran its steps (the pool's size, the steps
/// run on all of it and on one thread: they depend on the machine's load,
/// never on the result).
pub fn scalars<D: Dim>(md: &Md<D>, summary: &mut Map<String, Value>, wall_seconds: f64) {
    summary.insert("neighbor_builds".into(), json!(md.neighbor_builds()));
    let phases = md.timing.to_json(wall_seconds, 1.0);
    summary.insert("phase_seconds".into(), phases);
    let (wide, narrow) = md.governor.steps_wide_narrow();
    let pool = rayon::current_num_threads();
    summary.insert(
        "threads".into(),
        json!({ "pool": pool, "steps_on_pool": wide, "steps_on_one": narrow }),
    );
}

/// What must be equal between the engine that wrote a checkpoint and the
/// one rebuilt from the scenario to restore it, as comparable text.
fn fingerprint<D: Dim>(md: &Md<D>) -> Vec<(&'static str, String)> {
    let s = &md.settings;
    let bits = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:?}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let lo = D::to_xyz(md.domain.lo);
    let mut hi = D::to_xyz(md.domain.hi);
    // A fixed-pressure box's gradient length is part of the state, not of
    // the scenario: marked as such.
    let pressure_axis = (md.domain.shear)
        .filter(|_| s.barostat.is_some())
        .map(|sh| sh.gradient);
    if let Some(g) = pressure_axis {
        hi[g] = f64::NAN;
    }
    let mut fp = vec![
        ("dimension", D::NAME.to_string()),
        ("integrator", s.integrator.name().to_string()),
        ("dt", bits(&[s.dt])),
        ("neighbour skin", bits(&[s.skin])),
        ("sort interval", s.sort_every.to_string()),
        ("gravity", bits(&D::to_xyz(s.gravity))),
        ("contact law", format!("{:?}", s.law.estimate())),
        (
            "domain",
            format!("{} {} {:?}", bits(&lo), bits(&hi), md.domain.periodic),
        ),
        (
            "walls",
            md.walls
                .iter()
                .map(|w| format!("{w:?}"))
                .collect::<Vec<_>>()
                .join("; "),
        ),
    ];
    if let Some(sh) = md.domain.shear {
        fp.push((
            "shear",
            format!("{} {} {}", sh.axis, sh.gradient, bits(&[sh.rate])),
        ));
    }
    if let Some(b) = s.barostat {
        fp.push(("fixed pressure", format!("{b:?}")));
    }
    if let Some(law) = s.law.materials() {
        fp.push(("material law", format!("{law:?}")));
    }
    fp
}

/// The engine's fingerprint and full state.
pub fn encode<D: Dim>(md: &Md<D>) -> Result<Vec<u8>> {
    Ok(encode_state(md, &md.export_state()?))
}

/// `md`'s fingerprint and `state`, a state of an engine built as `md` (an
/// engine whose steps run elsewhere, on a device, exports its state so).
pub fn encode_state<D: Dim>(md: &Md<D>, state: &MdState<D>) -> Vec<u8> {
    let mut e = Enc::default();
    let fp = fingerprint(md);
    e.len(fp.len());
    for (k, v) in &fp {
        e.str(k);
        e.str(v);
    }
    encode_md(&mut e, state);
    e.buf
}

/// Fingerprint entries a restart may change (`scenario::restart` says which
/// scenario keys feed them); the time step only under velocity Verlet.
const MAY_CHANGE: &[&str] = &["gravity", "contact law", "material law", "walls"];

/// Restores `md` (freshly built from the checkpoint's scenario) from bytes
/// written by [`encode`]. Refuses a state whose fingerprint differs.
pub fn restore<D: Dim>(md: &mut Md<D>, bytes: &[u8]) -> Result<()> {
    restore_under(md, bytes, false)
}

/// [`restore`] into an engine built from a changed scenario (a restart):
/// the law, gravity and walls' motions may differ from the checkpoint's,
/// and the time step too when the integrator is velocity Verlet.
pub fn restore_changed<D: Dim>(md: &mut Md<D>, bytes: &[u8]) -> Result<()> {
    restore_under(md, bytes, true)
}

fn restore_under<D: Dim>(md: &mut Md<D>, bytes: &[u8], restart: bool) -> Result<()> {
    let mut d = Dec::new(bytes);
    let mut read = || -> std::result::Result<_, String> {
        let n = d.len(16, "fingerprint")?;
        let mut fp = Vec::with_capacity(n);
        for _ in 0..n {
            fp.push((d.str("fingerprint key")?, d.str("fingerprint value")?));
        }
        let state = decode_md::<D>(&mut d)?;
        if d.remaining() != 0 {
            return Err(format!(
                "{} unexpected bytes after the state",
                d.remaining()
            ));
        }
        Ok((fp, state))
    };
    let (fp, state) = read().map_err(|e| Error::input(format!("checkpoint engine state: {e}")))?;
    let mine = fingerprint(md);
    let verlet = matches!(md.settings.integrator, Integrator::Verlet);
    let free = |k: &str| restart && (MAY_CHANGE.contains(&k) || (k == "dt" && verlet));
    for (k, v) in &mine {
        match fp.iter().find(|(fk, _)| fk == k) {
            Some((_, fv)) if fv == v || free(k) => {}
            Some((_, fv)) if restart && *k == "dt" => {
                return Err(Error::input(format!(
                    "run.dt: the restart's time step {v} differs from the checkpoint's {fv},                      but a Gear-5 state holds derivatives scaled by its time step; set                      run.dt = {fv} (the contact law's change moved the default dt)"
                )))
            }
            Some((_, fv)) => {
                return Err(Error::input(format!(
                    "checkpoint was written for a different scenario: {k} differs \
                     (checkpoint: {fv}; scenario: {v})"
                )))
            }
            None if free(k) => {}
            None => {
                return Err(Error::input(format!(
                    "checkpoint lacks the {k} of its scenario"
                )))
            }
        }
    }
    md.import_state(state)
}
