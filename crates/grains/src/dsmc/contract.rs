//! The DSMC engine's side of the [`Engine`] contract: its steps, its frame,
//! and its state to and from checkpoint bytes: a kind tag (so an MD and a
//! DSMC state are never mistaken for each other), a fingerprint of the
//! settings the state depends on, then the state: the particle store in
//! store order, the cell starts of the last sort, every cell's v_max,
//! fractional remainder and collision counter, the candidate/collision
//! tallies, step and time.
//!
//! The collision random numbers carry no state: each cell's stream is
//! derived from (seed, step, cell) ([`crate::dsmc::rng::Stream::new`]), so
//! the seed (fingerprinted) and the step (saved) bring them back. The cell
//! keys are a function of the positions and are recomputed on restore.

use super::collide::{CellState, GasDim, Tally};
use super::engine::Dsmc;
use super::store::Particle;
use crate::codec::{Dec, DecResult, Enc};
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::io::Frame;

impl<D: GasDim> Engine for Dsmc<D> {
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
        self.run(n);
        Ok(())
    }
    fn frame(&self) -> Result<Frame> {
        Ok(gas_frame(self))
    }
    fn export(&self) -> Result<Vec<u8>> {
        Ok(encode(self))
    }
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()> {
        let rest = restore(self, bytes, origin)?;
        match rest.len() {
            0 => Ok(()),
            n => Err(Error::input(format!(
                "checkpoint {origin}: {n} unexpected bytes after the DSMC state"
            ))),
        }
    }
}

/// A DSMC gas as a frame: point particles whose ids are their store
/// positions + 1 (they carry no identity), a 2D box one unit deep.
pub fn gas_frame<D: GasDim>(sim: &Dsmc<D>) -> Frame {
    let n = sim.store.len();
    let mut periodic = [false; 3];
    periodic[..D::D].copy_from_slice(&sim.domain.periodic[..D::D]);
    let (mut lo, mut hi) = (D::to_xyz(sim.domain.lo), D::to_xyz(sim.domain.hi));
    if D::D == 2 {
        lo[2] = -0.5;
        hi[2] = 0.5;
    }
    Frame {
        step: sim.step,
        time: sim.time,
        dim: D::D,
        box_lo: lo,
        box_hi: hi,
        periodic,
        id: (1..=n as u64).collect(),
        kind: vec![1; n],
        pos: sim.store.p.iter().map(|q| D::to_xyz(q.x)).collect(),
        vel: sim.store.p.iter().map(|q| D::to_xyz(q.v)).collect(),
        omega: vec![[0.0; 3]; n],
        radius: vec![0.5 * sim.store.diameter; n],
        body: None,
        orientation: None,
        mass: Vec::new(),
    }
}

/// First bytes of a DSMC engine state.
pub const TAG: &[u8; 8] = b"DSMCSTAT";

/// Whether `bytes` (an engine state) is a DSMC one.
pub fn is_dsmc(bytes: &[u8]) -> bool {
    bytes.starts_with(TAG)
}

fn fingerprint<D: GasDim>(sim: &Dsmc<D>) -> Vec<(&'static str, String)> {
    let bits = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:?}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let s = &sim.settings;
    let lo = D::to_xyz(sim.domain.lo);
    let hi = D::to_xyz(sim.domain.hi);
    vec![
        ("dimension", D::NAME.to_string()),
        ("particles", sim.store.len().to_string()),
        (
            "diameter and mass",
            bits(&[sim.store.diameter, sim.store.mass]),
        ),
        ("settings", format!("{s:?}")),
        ("cells", format!("{:?}", sim.grid.n)),
        ("gravity", bits(&D::to_xyz(sim.gravity))),
        (
            "domain",
            format!("{} {} {:?}", bits(&lo), bits(&hi), sim.domain.periodic),
        ),
        (
            "walls",
            sim.walls
                .iter()
                .map(|w| format!("{w:?}"))
                .collect::<Vec<_>>()
                .join("; "),
        ),
    ]
}

/// The engine's kind tag, fingerprint and full state.
pub fn encode<D: GasDim>(sim: &Dsmc<D>) -> Vec<u8> {
    let mut e = Enc::default();
    e.buf.extend_from_slice(TAG);
    let fp = fingerprint(sim);
    e.len(fp.len());
    for (k, v) in &fp {
        e.str(k);
        e.str(v);
    }
    e.u64(sim.step);
    e.f64(sim.time);
    e.len(sim.store.p.len());
    for q in &sim.store.p {
        e.vec::<D>(q.x);
        e.vec::<D>(q.v);
    }
    let u32s = |e: &mut Enc, v: &[u32]| {
        e.len(v.len());
        v.iter().for_each(|&x| e.u32(x));
    };
    u32s(&mut e, &sim.start);
    e.len(sim.cells.len());
    for c in &sim.cells {
        e.f64(c.vmax);
        e.u32(c.remainder.to_bits());
        e.u32(c.collisions);
    }
    for t in [sim.totals, sim.last] {
        e.u64(t.candidates);
        e.u64(t.collisions);
    }
    e.buf
}

fn u32s(d: &mut Dec, want: usize, what: &str) -> DecResult<Vec<u32>> {
    let n = d.len(4, what)?;
    if n != want {
        return Err(format!("{what}: {n} entries, expected {want}"));
    }
    (0..n).map(|_| d.u32(what)).collect()
}

/// Restores `sim` (freshly built from the checkpoint's scenario) from bytes
/// written by [`encode`]; `origin` names the file in messages. Refuses an
/// MD state and a state whose fingerprint differs. Returns the bytes that
/// follow the engine state (the runner's own state).
pub fn restore<'a, D: GasDim>(
    sim: &mut Dsmc<D>,
    bytes: &'a [u8],
    origin: &str,
) -> Result<&'a [u8]> {
    if !is_dsmc(bytes) {
        return Err(Error::input(format!(
            "checkpoint {origin}: holds an MD engine state, but its scenario is a \
             method = \"dsmc\" run; the file cannot be resumed as DSMC"
        )));
    }
    let mut d = Dec::new(&bytes[TAG.len()..]);
    let n_cells = sim.cells.len();
    let n_p = sim.store.len();
    let mut read = || -> DecResult<_> {
        let n = d.len(16, "fingerprint")?;
        let mut fp = Vec::with_capacity(n);
        for _ in 0..n {
            fp.push((d.str("fingerprint key")?, d.str("fingerprint value")?));
        }
        let step = d.u64("step")?;
        let time = d.f64("time")?;
        let n = d.len(16 * D::D, "particles")?;
        if n != n_p {
            return Err(format!("{n} particles, the scenario has {n_p}"));
        }
        let mut p = Vec::with_capacity(n);
        for _ in 0..n {
            let x = d.vec::<D>("position")?;
            let v = d.vec::<D>("velocity")?;
            p.push(Particle { x, v });
        }
        let start = u32s(&mut d, n_cells + 1, "cell starts")?;
        let n = d.len(16, "cells")?;
        if n != n_cells {
            return Err(format!("{n} cells, the scenario has {n_cells}"));
        }
        let mut cells = Vec::with_capacity(n);
        for _ in 0..n {
            cells.push(CellState {
                vmax: d.f64("cell v_max")?,
                remainder: f32::from_bits(d.u32("cell remainder")?),
                collisions: d.u32("cell collisions")?,
            });
        }
        let mut tally = || -> DecResult<Tally> {
            Ok(Tally {
                candidates: d.u64("candidates")?,
                collisions: d.u64("collisions")?,
            })
        };
        let (totals, last) = (tally()?, tally()?);
        if start.windows(2).any(|w| w[0] > w[1]) || start.last().is_some_and(|&s| s as usize != n_p)
        {
            return Err("the cell sort is inconsistent".into());
        }
        Ok((fp, step, time, p, start, cells, totals, last))
    };
    let (fp, step, time, p, start, cells, totals, last) =
        read().map_err(|e| Error::input(format!("checkpoint {origin}: DSMC engine state: {e}")))?;
    for (k, v) in &fingerprint(sim) {
        match fp.iter().find(|(fk, _)| fk == k) {
            Some((_, fv)) if fv == v => {}
            Some((_, fv)) => {
                return Err(Error::input(format!(
                    "checkpoint {origin} was written for a different scenario: {k} differs \
                     (checkpoint: {fv}; scenario: {v})"
                )))
            }
            None => {
                return Err(Error::input(format!(
                    "checkpoint {origin} lacks the {k} of its scenario"
                )))
            }
        }
    }
    sim.step = step;
    sim.time = time;
    sim.store.p = p;
    sim.start = start;
    sim.cells = cells;
    sim.totals = totals;
    sim.last = last;
    sim.sort_now();
    Ok(&bytes[bytes.len() - d.remaining()..])
}
