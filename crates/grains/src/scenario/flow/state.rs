//! A flow run's part of a checkpoint: its whole state as bytes
//! ([`FlowRun::save`]), read back over a flow run begun from the same
//! scenario ([`FlowRun::restored`]), every number as its exact bits.
//!
//! The flow run changes the engine too: a tilt sets gravity, a wall
//! removal sets the wall's removal time. Both are functions of the flow
//! state (the gravity last set, the settling time), so a resume puts them
//! back into the freshly built engine before the engine's own state is
//! restored over it; the engine's fingerprint (gravity, walls) then checks
//! that they agree with the engine that wrote the checkpoint.

use super::{FlowRun, Stage};
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::scenario::Loaded;
use rand_xoshiro::Xoshiro256PlusPlus;

/// The four words of the recycler's generator (its serde form, `{"s": [..]}`).
fn rng_words(rng: &Xoshiro256PlusPlus) -> [u64; 4] {
    let v = serde_json::to_value(rng).expect("a generator's state serializes");
    serde_json::from_value(v["s"].clone()).expect("the generator's state is four words")
}

fn rng_from_words(s: [u64; 4]) -> DecResult<Xoshiro256PlusPlus> {
    serde_json::from_value(serde_json::json!({ "s": s }))
        .map_err(|e| format!("recycler generator: {e}"))
}

fn opt_f64(e: &mut Enc, v: Option<f64>) {
    e.bool(v.is_some());
    e.f64(v.unwrap_or(0.0));
}

fn read_opt_f64(d: &mut Dec, what: &str) -> DecResult<Option<f64>> {
    let some = d.bool(what)?;
    let v = d.f64(what)?;
    Ok(some.then_some(v))
}

/// Whether a part saved as `saved` (present or not) fits the scenario's.
fn same_parts(what: &str, saved: bool, here: bool) -> DecResult<()> {
    match (saved, here) {
        (true, false) => Err(format!("flow state holds {what}, which the scenario lacks")),
        (false, true) => Err(format!("flow state lacks the scenario's {what}")),
        _ => Ok(()),
    }
}

impl<D: Dim> FlowRun<D> {
    /// The whole state (the scenario's keys aside, which the checkpoint
    /// carries): stage, gravity before and after the tilt, counters, the
    /// recycler's generator and exits, the drum's angles, the
    /// space–time rows and the outlets' and sensors' counts.
    pub fn save(&self) -> Vec<u8> {
        let mut e = Enc::default();
        match self.stage {
            Stage::Settling => e.u8(0),
            Stage::Settled(t) => {
                e.u8(1);
                e.f64(t);
            }
            Stage::Tilting { since, base } => {
                e.u8(2);
                e.f64(since);
                e.f64(base);
            }
            Stage::Failed { tilt, base } => {
                e.u8(3);
                e.f64(tilt);
                e.f64(base);
            }
        }
        e.vec::<D>(self.g0);
        e.f64(self.energy_unit);
        e.f64(self.tilt);
        e.u64(self.parked as u64);
        opt_f64(&mut e, self.fill_top);
        e.u64(self.settled_grains as u64);
        opt_f64(&mut e, self.settled_at);
        e.bool(self.gravity.is_some());
        e.vec::<D>(self.gravity.unwrap_or_else(D::zero));
        e.bool(self.hopper.is_some());
        if let Some(h) = &self.hopper {
            for w in rng_words(&h.rng) {
                e.u64(w);
            }
            e.len(h.exits.len());
            for (t, m) in &h.exits {
                e.f64(*t);
                e.f64(*m);
            }
            e.f64(h.start);
        }
        e.bool(self.drum.is_some());
        if let Some((_, angles)) = &self.drum {
            e.f64s(angles);
        }
        e.bool(self.spacetime.is_some());
        if let Some(s) = &self.spacetime {
            s.save(&mut e);
        }
        self.inlets.save(&mut e);
        e.bool(self.outlets.is_some());
        if let Some(o) = &self.outlets {
            o.save(&mut e);
        }
        e.buf
    }

    /// Reads the state [`FlowRun::save`] wrote into this flow run, begun
    /// from the same scenario.
    fn load(&mut self, bytes: &[u8]) -> DecResult<()> {
        let mut d = Dec::new(bytes);
        self.stage = match d.u8("flow stage")? {
            0 => Stage::Settling,
            1 => Stage::Settled(d.f64("settling time")?),
            2 => Stage::Tilting {
                since: d.f64("tilt start")?,
                base: d.f64("tilt base")?,
            },
            3 => Stage::Failed {
                tilt: d.f64("tilt at failure")?,
                base: d.f64("tilt base")?,
            },
            k => return Err(format!("flow stage {k} unknown")),
        };
        self.g0 = d.vec::<D>("gravity before the tilt")?;
        self.energy_unit = d.f64("energy unit")?;
        self.tilt = d.f64("tilt")?;
        self.parked = d.u64("parked grains")? as usize;
        self.fill_top = read_opt_f64(&mut d, "fill top")?;
        self.settled_grains = d.u64("settled grains")? as usize;
        self.settled_at = read_opt_f64(&mut d, "settling time")?;
        let tilted = d.bool("tilted gravity")?;
        let g = d.vec::<D>("tilted gravity")?;
        self.gravity = tilted.then_some(g);
        let hopper = d.bool("recycler")?;
        same_parts("[hopper] recycling", hopper, self.hopper.is_some())?;
        if let Some(h) = &mut self.hopper {
            let mut s = [0u64; 4];
            for w in &mut s {
                *w = d.u64("recycler generator")?;
            }
            h.rng = rng_from_words(s)?;
            let n = d.len(16, "discharged grains")?;
            h.exits = (0..n)
                .map(|_| Ok((d.f64("exit time")?, d.f64("exit mass")?)))
                .collect::<DecResult<_>>()?;
            h.start = d.f64("recycling start")?;
        }
        let drum = d.bool("surface angles")?;
        same_parts("measure.surface_angle", drum, self.drum.is_some())?;
        if let Some((_, angles)) = &mut self.drum {
            *angles = d.f64s("surface angles")?;
        }
        let spacetime = d.bool("space-time density")?;
        same_parts("measure.spacetime", spacetime, self.spacetime.is_some())?;
        if let Some(s) = &mut self.spacetime {
            s.load(&mut d)?;
        }
        self.inlets.load(&mut d)?;
        let outlets = d.bool("outlets")?;
        same_parts("[[outlets]]/[[sensors]]", outlets, self.outlets.is_some())?;
        if let Some(o) = &mut self.outlets {
            o.load(&mut d)?;
        }
        if d.remaining() != 0 {
            return Err(format!(
                "{} unexpected bytes after the flow state",
                d.remaining()
            ));
        }
        Ok(())
    }

    /// What the flow run has changed in the engine, put into `md`: the
    /// grains the inlets inserted, the gravity of the tilt and the removal
    /// time of the removed wall (set when settling ended), as
    /// [`FlowRun::after_step`] set them, and the grains the outlets took
    /// out (so that the engine's state, which lacks them, fits).
    fn apply(&self, md: &mut Md<D>) -> Result<()> {
        self.put_back_grains(md)?;
        if let Some(g) = self.gravity {
            md.settings.gravity = g;
        }
        let removed = self.events.as_ref().and_then(|e| e.remove_wall.as_ref());
        if let (Some(name), Some(t)) = (removed, self.settled_at) {
            for w in md.walls.iter_mut().filter(|w| &w.name == name) {
                w.remove_at = Some(t);
            }
        }
        Ok(())
    }

    /// The grains the inlets inserted and the outlets took out, put into
    /// `md` freshly built from the scenario. The scenario's own grains that
    /// left go first, while the store holds real grains only (removal
    /// rebuilds the neighbour list); the inserted grains still present then
    /// go in as stand-ins.
    fn put_back_grains(&self, md: &mut Md<D>) -> Result<()> {
        let mut removed = self
            .outlets
            .as_ref()
            .map_or(Vec::new(), |o| o.removed_ids());
        removed.sort_unstable();
        let first = self.inlets.first_id();
        // A removed body is listed by its first grain id: all its grains go.
        let own: Vec<u64> = (removed.iter().copied())
            .filter(|&id| id < first)
            .flat_map(|id| md.body_grain_ids(id).unwrap_or(id..id + 1))
            .collect();
        md.remove_grains(&own)?;
        self.inlets.apply(md, &removed)
    }

    /// The flow run of a resumed run: begun on `md` freshly built from the
    /// checkpoint's scenario (as the interrupted run began it), its state
    /// read from the checkpoint's flow section `bytes`, and its changes to
    /// the engine put back into `md` before the engine's state is restored
    /// into it. `origin` names the checkpoint in messages.
    ///
    /// A checkpoint without a flow section (a session's) gives the flow run
    /// as begun, unless the scenario has `[hopper]` or `run.events`.
    pub fn restored(
        loaded: &Loaded,
        md: &mut Md<D>,
        bytes: Option<&[u8]>,
        origin: &str,
    ) -> Result<Self> {
        let mut flow = Self::begin(loaded, md)?;
        let Some(bytes) = bytes else {
            // A Python session's checkpoint has no flow section: its
            // scenario has no events, and its flow measurements begin here.
            let s = &loaded.scenario;
            if s.hopper.is_some()
                || s.run.events.is_some()
                || !s.outlets.is_empty()
                || !s.sensors.is_empty()
                || !s.inlets.is_empty()
            {
                return Err(Error::input(format!(
                    "checkpoint {origin}: an MD state without its flow state"
                )));
            }
            return Ok(flow);
        };
        flow.load(bytes)
            .map_err(|e| Error::input(format!("checkpoint {origin}: {e}")))?;
        flow.apply(md)
            .map_err(|e| Error::input(format!("checkpoint {origin}: {e}")))?;
        Ok(flow)
    }
}

impl<D: Dim> FlowRun<D> {
    /// For a restart: the grains the checkpoint's run inserted through its
    /// inlets and took out through its outlets, put into `md` freshly built
    /// from the changed scenario (the grains, inlets and outlets cannot
    /// change, so it holds the checkpoint scenario's grains), so that the
    /// engine's state fits it. `old` is the checkpoint's own scenario, under
    /// which the flow section `bytes` was written. Returns the inlets' and
    /// outlets' state for [`FlowRun::carry`], since they go on where they
    /// were: a restarted fill must not insert its grains a second time.
    pub fn carried_grains(
        old: &Loaded,
        md: &mut Md<D>,
        bytes: Option<&[u8]>,
        origin: &str,
    ) -> Result<Option<Vec<u8>>> {
        let Some(bytes) = bytes else {
            return Ok(None);
        };
        let at = |e: String| Error::input(format!("checkpoint {origin}: {e}"));
        let mut flow = Self::begin(old, md)?;
        flow.load(bytes).map_err(at)?;
        flow.put_back_grains(md)?;
        let mut e = Enc::default();
        flow.inlets.save(&mut e);
        if let Some(o) = &flow.outlets {
            o.save(&mut e);
            e.u64(o.initial.0);
            e.f64(o.initial.1);
        }
        Ok(Some(e.buf))
    }

    /// Takes over what [`FlowRun::carried_grains`] returned: the inlets'
    /// counters and next grain id, the outlets' removals, the grains and
    /// mass the run began with (the mass balance spans the checkpoint's run
    /// and the restart) and the sensors' counts. The rest of the flow run
    /// (events, recycling, measurements) begins afresh at the restart.
    pub fn carry(&mut self, carried: Option<&[u8]>, origin: &str) -> Result<()> {
        let Some(bytes) = carried else {
            return Ok(());
        };
        let mut d = Dec::new(bytes);
        let mut read = || -> DecResult<()> {
            self.inlets.load(&mut d)?;
            if let Some(o) = &mut self.outlets {
                o.load(&mut d)?;
                o.initial = (d.u64("initial grains")?, d.f64("initial mass")?);
            }
            Ok(())
        };
        read().map_err(|e| Error::input(format!("checkpoint {origin}: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn generator_continues_from_its_words() {
        let mut a = Xoshiro256PlusPlus::seed_from_u64(7);
        for _ in 0..5 {
            a.gen::<u64>();
        }
        let mut b = rng_from_words(rng_words(&a)).unwrap();
        for _ in 0..100 {
            assert_eq!(a.gen_range(0.0..1.0f64), b.gen_range(0.0..1.0f64));
        }
    }
}
