//! Flow scenarios: run events (settle, then remove a wall or tilt the box),
//! recycling of the grains discharged by the silo of `[hopper]` (its walls
//! are built by [`crate::scenario::hopper`]),
//! and the measurements that go with them (angle of repose, marginal angle,
//! flow rate, dynamic angle of a drum, space–time density).
//!
//! The runner calls [`crate::scenario::hopper::expand`] (the silo's walls)
//! before building the engine; the run loop's flow hook calls [`FlowRun::after_step`] after every step at which
//! [`FlowRun::next_act`] says it acts (relaxation included) and
//! [`FlowRun::sample`] at every sample; the runner calls
//! [`FlowRun::finish`] at the end.

use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::write_atomic;
use crate::md::Md;
use crate::measure::{refit_below, surface, Spacetime, SurfaceFit};
use crate::scenario::inlet::Inlets;
use crate::scenario::outlet::Outlets;
use crate::scenario::schema::{EventsSpec, HopperSpec, SurfaceSpec};
use crate::scenario::Loaded;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::Path;

mod ranks;
mod state;

pub use ranks::apply_on_rank;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Stage {
    Settling,
    /// Settled at this time; the wall is gone (or goes on tilting).
    Settled(f64),
    /// Tilting since this time; the surface stood at `base` degrees when it began.
    Tilting {
        since: f64,
        base: f64,
    },
    /// The pile failed `tilt` degrees into the tilt, its surface at `base` + `tilt`.
    Failed {
        tilt: f64,
        base: f64,
    },
}

/// Everything a flow scenario adds to a run.
pub struct FlowRun<D: Dim> {
    events: Option<EventsSpec>,
    stage: Stage,
    g0: D::V,
    energy_unit: f64,
    /// g d0 (d0 without gravity): the energy unit per unit of mass, for
    /// an engine that starts empty.
    g_d0: f64,
    tilt: f64,
    parked: usize,
    d0: f64,
    /// Highest grain top when settling ended: the repose fit keeps only the
    /// surface below it (the part that flowed).
    fill_top: Option<f64>,
    /// Mobile grains when settling ended.
    settled_grains: usize,
    /// Simulated time at which settling ended (kept apart from the stage:
    /// a tilt after a wall removal starts later).
    settled_at: Option<f64>,
    /// The gravity the tilt last set, once it has set one.
    gravity: Option<D::V>,
    hopper: Option<Recycler>,
    repose: Option<SurfaceSpec>,
    drum: Option<(SurfaceSpec, Vec<f64>)>,
    spacetime: Option<Spacetime>,
    /// `[[inlets]]`: grains arriving during the run.
    inlets: Inlets<D>,
    /// `[[outlets]]` and `[[sensors]]` (`scenario/outlet.rs`).
    outlets: Option<Outlets<D>>,
}

struct Recycler {
    spec: HopperSpec,
    sink: f64,
    rng: Xoshiro256PlusPlus,
    /// (time, mass) of every grain that left through the outlet.
    exits: Vec<(f64, f64)>,
    start: f64,
}

impl<D: Dim> FlowRun<D> {
    pub fn begin(loaded: &Loaded, md: &Md<D>) -> Result<Self> {
        let s = &loaded.scenario;
        let d0 = s.particles.d0;
        let p = &md.particles;
        let mobile: Vec<usize> = (0..p.n_owned()).filter(|&i| !p.frozen[i]).collect();
        let mean_mass = mobile.iter().map(|&i| p.mass[i]).sum::<f64>() / mobile.len().max(1) as f64;
        let g = D::norm(md.settings.gravity);
        let energy_unit = mean_mass * if g > 0.0 { g } else { 1.0 } * d0;
        let g_d0 = if g > 0.0 { g } else { 1.0 } * d0;
        let mut events = s.run.events.clone();
        if let Some(e) = &mut events {
            if e.remove_wall.as_deref() == Some("") {
                e.remove_wall = None;
            }
            if let Some(w) = &e.remove_wall {
                if !md.walls.iter().any(|x| &x.name == w) {
                    return Err(Error::input(format!(
                        "run.events.remove_wall = \"{w}\": no wall has that name"
                    )));
                }
            }
        }
        if let Some(e) = &events {
            if e.tilt_rate.is_some() && e.remove_wall.is_some() && s.measure.repose.is_none() {
                return Err(Error::input(
                    "run.events: tilt_rate after remove_wall measures the slope left by the \
                     avalanche first; add [measure.repose] (or set remove_wall = \"\")",
                ));
            }
        }
        for (key, m) in [
            ("repose", &s.measure.repose),
            ("surface_angle", &s.measure.surface_angle),
        ] {
            if let Some(m) = m {
                if m.x_range.len() != 2 || m.x_range[0] >= m.x_range[1] || m.column <= 0.0 {
                    return Err(Error::input(format!(
                        "measure.{key}: x_range must be [x0, x1] with x0 < x1 and column > 0"
                    )));
                }
            }
        }
        let hopper = s.hopper.as_ref().filter(|h| h.recycle).map(|h| Recycler {
            spec: h.clone(),
            sink: hopper_sink(h, d0),
            rng: Xoshiro256PlusPlus::seed_from_u64(s.seed ^ 0x686f_7070_6572),
            exits: Vec::new(),
            start: md.time,
        });
        Ok(Self {
            events,
            stage: Stage::Settling,
            g0: md.settings.gravity,
            energy_unit,
            g_d0,
            tilt: 0.0,
            parked: 0,
            d0,
            fill_top: None,
            settled_grains: 0,
            settled_at: None,
            gravity: None,
            hopper,
            repose: s.measure.repose.clone(),
            drum: s.measure.surface_angle.clone().map(|m| (m, Vec::new())),
            spacetime: s
                .measure
                .spacetime
                .as_ref()
                .map(|m| Spacetime::new(&md.view(), m.bin * d0)),
            inlets: Inlets::begin(loaded, md)?,
            outlets: Outlets::begin(s, md)?,
        })
    }

    /// The first step after `now`, at most `horizon`, after which
    /// [`FlowRun::after_step`] may read or change the grains or the
    /// gravity; at every other step it does nothing, so the run loop
    /// advances over those steps without calling it. A sink (recycling,
    /// parking) is checked after every step, a tilt turns gravity after
    /// every step; the stage changes only at a look, so the answer holds
    /// until the next call.
    pub fn next_act(&self, now: u64, horizon: u64) -> u64 {
        let every_step = self.hopper.is_some()
            || self
                .events
                .as_ref()
                .is_some_and(|e| e.sink.is_some() || matches!(self.stage, Stage::Tilting { .. }));
        let next = match (every_step, &self.events) {
            (true, _) => now + 1,
            (false, Some(_)) => (now / LOOK_EVERY + 1) * LOOK_EVERY,
            (false, None) => horizon,
        };
        let outlets = self
            .outlets
            .as_ref()
            .map_or(horizon, |o| o.next_due(now, horizon));
        next.min(horizon)
            .min(self.inlets.next_act(now, horizon))
            .min(outlets)
    }

    /// Whether an inlet, outlet or sensor acts after `step` (reads or
    /// changes the grains), as [`FlowRun::next_act`] schedules them.
    pub fn edits_at(&self, step: u64) -> bool {
        let (now, horizon) = (step.saturating_sub(1), step + 1);
        let outlets = self.outlets.as_ref();
        self.inlets.next_act(now, horizon) == step
            || outlets.is_some_and(|o| o.next_due(now, horizon) == step)
    }

    /// The outlets and sensors after the step (after [`FlowRun::after_step`]):
    /// grains counted, grains taken out of `md`.
    pub fn outflow(&mut self, md: &mut Md<D>) -> Result<()> {
        match &mut self.outlets {
            Some(o) => o.after_step(md),
            None => Ok(()),
        }
    }

    /// Kinetic energy per mobile grain in units of m g d0.
    fn energy(&self, md: &Md<D>) -> f64 {
        let n = md.particles.n_mobile().max(1) as f64;
        // With bodies, a clump's energy is ½ M V² of its centre of mass, not
        // the sum over its sub-spheres; without them this is the grains' sum.
        let energy = md.kinetic_energy();
        if self.energy_unit > 0.0 {
            return energy / n / self.energy_unit;
        }
        // Started empty (inlets fill it): the mean mass of the mobile
        // grains there now.
        let p = &md.particles;
        let mass: f64 = (0..p.n_owned())
            .filter(|&i| !p.frozen[i])
            .map(|i| p.mass[i])
            .sum();
        if mass == 0.0 {
            return f64::INFINITY;
        }
        energy / n / (mass / n * self.g_d0)
    }

    /// The step's events on `md`; returns the grains it moved (id, new
    /// position), in order, so that a decomposed run can move them on the
    /// ranks that own them.
    pub fn after_step(&mut self, md: &mut Md<D>) -> Vec<(u64, D::V)> {
        self.inlets.act(md);
        let mut placed = match &mut self.hopper {
            Some(h) => h.recycle(md),
            None => Vec::new(),
        };
        let Some(e) = self.events.clone() else {
            return placed;
        };
        if let Some(sink) = e.sink {
            self.park(md, sink, &mut placed);
        }
        // The energy is a sum over grains: look every 50 steps.
        let look = md.step.is_multiple_of(LOOK_EVERY);
        match self.stage {
            Stage::Settling
                if look && md.time >= e.settle_min && self.energy(md) < e.settle_energy =>
            {
                self.stage = Stage::Settled(md.time);
                self.settled_at = Some(md.time);
                self.fill_top = Some(top_of_pile(md));
                self.settled_grains = md.particles.n_mobile();
                if let Some(name) = &e.remove_wall {
                    for w in md.walls.iter_mut().filter(|w| &w.name == name) {
                        w.remove_at = Some(md.time);
                    }
                } else if e.tilt_rate.is_some() {
                    // A closed box tilts from its flat settled surface.
                    self.stage = Stage::Tilting {
                        since: md.time,
                        base: 0.0,
                    };
                }
            }
            // With a wall removed, the tilt starts from the pile the avalanche
            // left (Lee & Herrmann 1993): wait until it is at rest again (and
            // at least as long after the removal as settling took), then take
            // its slope as the base of the tilt.
            Stage::Settled(t0)
                if e.tilt_rate.is_some()
                    && look
                    && md.time >= 2.0 * t0
                    && self.energy(md) < e.settle_energy =>
            {
                let base = self.repose_fit(md).map_or(0.0, |f| f.angle_deg());
                self.stage = Stage::Tilting {
                    since: md.time,
                    base,
                };
            }
            Stage::Tilting { since, base } => {
                let rate = e.tilt_rate.unwrap_or(0.0);
                if look && self.energy(md) > e.fail_energy {
                    self.stage = Stage::Failed {
                        tilt: self.tilt,
                        base,
                    };
                    return placed;
                }
                self.tilt = rate * (md.time - since);
                let a = self.tilt.to_radians();
                let g = D::norm(self.g0);
                let v = D::vertical();
                let mut gv = D::zero();
                D::set(&mut gv, 0, g * a.sin());
                D::set(&mut gv, v, -g * a.cos());
                md.settings.gravity = gv;
                self.gravity = Some(gv);
            }
            _ => {}
        }
        placed
    }

    /// The slope of the pile left by the avalanche: column tops within
    /// `x_range`, only those more than 2 d0 below the settled fill height
    /// (the settled top is rough by about one grain).
    /// The columns still standing at that height (against the far wall, or a
    /// block that never moved) are not a slope of repose.
    fn repose_fit(&self, md: &Md<D>) -> Option<SurfaceFit> {
        let m = self.repose.as_ref()?;
        let fit = surface(
            &md.view(),
            m.x_range[0],
            m.x_range[1],
            m.column * self.d0,
            m.min_height,
        );
        let cap = self.fill_top.map_or(f64::INFINITY, |h| h - 2.0 * self.d0);
        Some(refit_below(fit, cap))
    }

    /// Grains that fell below `sink` are frozen and parked in rows below it,
    /// out of everyone's way (appended to `placed`).
    fn park(&mut self, md: &mut Md<D>, sink: f64, placed: &mut Vec<(u64, D::V)>) {
        let v = D::vertical();
        let p = &mut md.particles;
        let lo = D::get(md.domain.lo, 0);
        let width = D::get(md.domain.hi, 0) - lo;
        let pitch = 2.0 * p.max_radius() * 1.5;
        let per_row = ((width / pitch).floor() as usize).max(1);
        for i in 0..p.n_owned() {
            if p.frozen[i] || D::get(p.pos[i], v) >= sink {
                continue;
            }
            let k = self.parked;
            self.parked += 1;
            let mut x = D::zero();
            D::set(&mut x, 0, lo + (k % per_row) as f64 * pitch + 0.5 * pitch);
            if D::D == 3 {
                D::set(&mut x, 1, D::get(md.domain.lo, 1) + 0.5 * pitch);
            }
            D::set(
                &mut x,
                v,
                sink - 5.0 * self.d0 - (k / per_row) as f64 * pitch,
            );
            place(p, i, x);
            p.frozen[i] = true;
            placed.push((p.id[i], x));
        }
    }

    pub fn sample(&mut self, md: &Md<D>) {
        if let Some((m, angles)) = &mut self.drum {
            let fit = surface(
                &md.view(),
                m.x_range[0],
                m.x_range[1],
                m.column * self.d0,
                m.min_height,
            );
            if fit.points.len() >= 3 {
                angles.push(fit.angle_deg());
            }
        }
        if let Some(s) = &mut self.spacetime {
            s.sample(&md.view());
        }
    }

    pub fn finish(&self, dir: &Path, md: &Md<D>, summary: &mut Map<String, Value>) -> Result<()> {
        if !self.inlets.is_empty() {
            summary.insert("inlets".into(), self.inlets.report(md.time));
            let (seconds, acts) = self.inlets.cost();
            summary.insert(
                "inlet_seconds".into(),
                json!({ "total": seconds, "insertions": acts }),
            );
            self.inlets.warn_short(md.time);
        }
        if let Some(e) = &self.events {
            match self.stage {
                Stage::Settling => {
                    summary.insert("settled".into(), json!(0));
                }
                Stage::Settled(_) | Stage::Tilting { .. } => {
                    summary.insert("settled".into(), json!(1));
                    summary.insert("settle_time".into(), json!(self.settled_at));
                    if let Stage::Tilting { base, .. } = self.stage {
                        // Never failed: the angle reached is a lower bound.
                        summary.insert(
                            "marginal_angle_lower_bound_deg".into(),
                            json!(base + self.tilt),
                        );
                    } else if e.tilt_rate.is_some() {
                        summary.insert("marginal_angle_lower_bound_deg".into(), json!(0.0));
                    }
                }
                Stage::Failed { tilt, base } => {
                    summary.insert("settled".into(), json!(1));
                    summary.insert("marginal_angle_deg".into(), json!(base + tilt));
                    summary.insert("tilt_at_failure_deg".into(), json!(tilt));
                    summary.insert("repose_before_tilt_deg".into(), json!(base));
                }
            }
            if e.sink.is_some() {
                summary.insert("lost_grains".into(), json!(self.parked));
            }
        }
        if let Some(fit) = self.repose_fit(md) {
            write_surface(dir, &fit)?;
            // Share of the settled grains that left the box. Below a tenth
            // there was no avalanche (the pile stands as a block, at most a
            // corner slumped), so whatever slope is there is no angle of
            // repose; with fewer than three columns there is no fit either.
            let flowed = if self.settled_grains > 0 {
                self.parked as f64 / self.settled_grains as f64
            } else {
                0.0
            };
            // Without a sink nothing is counted as gone: no such check.
            let sink = self.events.as_ref().and_then(|e| e.sink);
            let avalanche = sink.is_none() || flowed >= 0.1;
            if fit.points.len() >= 3 && avalanche {
                summary.insert("repose_angle_deg".into(), json!(fit.angle_deg()));
            }
            summary.insert("repose_flowed_fraction".into(), json!(flowed));
            summary.insert("repose_surface_points".into(), json!(fit.points.len()));
            summary.insert("remaining_grains".into(), json!(md.particles.n_mobile()));
        }
        if let Some((_, angles)) = &self.drum {
            let n = angles.len().max(1) as f64;
            let mean = angles.iter().sum::<f64>() / n;
            let sd = (angles.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / n).sqrt();
            summary.insert("dynamic_angle_deg".into(), json!(mean));
            summary.insert("dynamic_angle_sd_deg".into(), json!(sd));
        }
        if let Some(s) = &self.spacetime {
            s.write(dir)?;
            summary.insert("density_contrast".into(), json!(s.contrast()));
        }
        if let Some(h) = &self.hopper {
            h.finish(dir, md.time, summary)?;
        }
        if let Some(o) = &self.outlets {
            o.finish(dir, md, self.inlets.inserted(), summary)?;
        }
        Ok(())
    }
}

/// Whether `loaded` has inlets, outlets or sensors: what adds, removes or
/// counts grains at steps that only the flow run knows (a decomposed run
/// asks it at every step, [`FlowRun::edits_at`]).
pub fn edits(loaded: &Loaded) -> bool {
    let s = &loaded.scenario;
    !(s.inlets.is_empty() && s.outlets.is_empty() && s.sensors.is_empty())
}

/// Highest grain top among the mobile grains.
fn top_of_pile<D: Dim>(md: &Md<D>) -> f64 {
    let p = &md.particles;
    let v = D::vertical();
    (0..p.n_owned())
        .filter(|&i| !p.frozen[i])
        .map(|i| D::get(p.pos[i], v) + p.radius[i])
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Below this height (m) a grain is moved by [`FlowRun::after_step`]
/// (recycled by `[hopper]`, parked by `run.events.sink`); `None` when no
/// grain is ever moved. The higher of the two when both are set.
pub fn sink_height(loaded: &Loaded) -> Option<f64> {
    let s = &loaded.scenario;
    let hopper = s
        .hopper
        .as_ref()
        .filter(|h| h.recycle)
        .map(|h| hopper_sink(h, s.particles.d0));
    let events = s.run.events.as_ref().and_then(|e| e.sink);
    hopper.into_iter().chain(events).reduce(f64::max)
}

/// Whether [`FlowRun::after_step`] may read the kinetic energy or the pile
/// at `step` (the settle and failure checks of `run.events`).
pub fn looks_at(loaded: &Loaded, step: u64) -> bool {
    loaded.scenario.run.events.is_some() && step.is_multiple_of(LOOK_EVERY)
}

/// Steps between looks at the kinetic energy (a sum over all grains).
pub(crate) const LOOK_EVERY: u64 = 50;

/// Recycling height of `[hopper]`: `sink`, by default 10 d0 below the floor.
fn hopper_sink(h: &HopperSpec, d0: f64) -> f64 {
    h.sink.unwrap_or(h.floor - 10.0 * d0)
}

/// Puts grain `i` at `x` at rest, its integrator history cleared.
pub(crate) fn place<D: Dim>(p: &mut crate::particles::Particles<D>, i: usize, x: D::V) {
    p.pos[i] = x;
    p.vel[i] = D::zero();
    p.omega[i] = D::A::default();
    for g in p.gear.iter_mut() {
        g[i] = D::zero();
    }
    for g in p.gear_ang.iter_mut() {
        g[i] = D::A::default();
    }
}

fn write_surface(dir: &Path, fit: &SurfaceFit) -> Result<()> {
    let mut csv = format!(
        "# height = {} + {} x; angle {} deg\nx,top\n",
        fit.intercept,
        fit.slope,
        fit.angle_deg()
    );
    for p in &fit.points {
        let _ = writeln!(csv, "{},{}", p[0], p[1]);
    }
    write_atomic(&dir.join("surface.csv"), csv.as_bytes())
}

impl Recycler {
    /// Grains below the sink go back to a random free spot in the refill
    /// band; returns them as (id, new position) in the order placed.
    fn recycle<D: Dim>(&mut self, md: &mut Md<D>) -> Vec<(u64, D::V)> {
        let mut placed = Vec::new();
        let v = D::vertical();
        let n = md.particles.n_owned();
        for i in 0..n {
            if md.particles.frozen[i] || D::get(md.particles.pos[i], v) >= self.sink {
                continue;
            }
            let r = md.particles.radius[i];
            for _ in 0..30 {
                let mut x = D::zero();
                for a in 0..D::D {
                    let (lo, hi) = if a == v {
                        (self.spec.refill[0], self.spec.refill[1])
                    } else {
                        (D::get(md.domain.lo, a) + r, D::get(md.domain.hi, a) - r)
                    };
                    D::set(&mut x, a, self.rng.gen_range(lo..hi));
                }
                let p = &md.particles;
                let free =
                    (0..n).all(|j| j == i || D::norm(p.pos[j] - x) > 1.02 * (p.radius[j] + r));
                if free {
                    self.exits.push((md.time, p.mass[i]));
                    placed.push((p.id[i], x));
                    place(&mut md.particles, i, x);
                    break;
                }
            }
        }
        placed
    }

    fn finish(&self, dir: &Path, end: f64, summary: &mut Map<String, Value>) -> Result<()> {
        let t0 = self.start + self.spec.transient;
        let window = end - t0;
        let counted: Vec<&(f64, f64)> = self.exits.iter().filter(|e| e.0 >= t0).collect();
        let mass: f64 = counted.iter().map(|e| e.1).sum::<f64>() + 0.0;
        let (rate, grains) = if window > 0.0 {
            (mass / window, counted.len() as f64 / window)
        } else {
            (0.0, 0.0)
        };
        // Clogged: nothing left the silo in the last fifth of the window.
        let tail = end - 0.2 * window.max(0.0);
        let clogged = window > 0.0 && !self.exits.iter().any(|e| e.0 >= tail);
        summary.insert("flow_rate".into(), json!(rate));
        summary.insert("flow_rate_grains".into(), json!(grains));
        summary.insert("discharged_grains".into(), json!(self.exits.len()));
        summary.insert("clogged".into(), json!(u8::from(clogged)));
        summary.insert("outlet".into(), json!(self.spec.outlet));
        let mut csv = String::from("time,cumulative_mass\n");
        let mut m = 0.0;
        for (t, dm) in &self.exits {
            m += dm;
            let _ = writeln!(csv, "{t},{m}");
        }
        write_atomic(&dir.join("discharge.csv"), csv.as_bytes())
    }
}
