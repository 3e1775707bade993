//! Inlets (`[[inlets]]`): grains that arrive in a region during an MD run,
//! at a rate (grains or kilograms per second) or as a total spread over a
//! time window, with the size law of `particles.size` (`scenario/sizes.rs`).
//!
//! By time t an inlet has inserted floor(rate (t − start)) grains (by mass:
//! every grain whose running total stays within mass_rate (t − start)), so
//! it follows the requested rate within one grain at every step. A grain
//! that finds no free spot (it would overlap a grain or a wall) waits, and
//! later grains wait behind it: it is tried again every [`RETRY_STEPS`]
//! steps until `stop`; what is still missing then is reported.
//!
//! Every draw comes from a stream of (seed, purpose, inlet, grain number,
//! attempt), so the grains are the same on any thread count and after a
//! resume; the inlets' counters go into the flow run's checkpoint section.
//! A mixture of materials (`inlet/mixture.rs`) draws each grain's material
//! from a stream of its own, so an inlet of one kind keeps its bits.
//! An inlet of rigid bodies (`inlet/bodies.rs`) counts and weighs bodies,
//! and places each only where all its sub-spheres pass a grain's test.

use super::keys::vector;
use super::placement::stream;
use super::schema::{InletSpec, Scenario};
use super::sizes::SizeLaw;
use super::Loaded;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::particles::{MassModel, ParticleRecord};
use crate::rigid::shape::wxyz;
use crate::rigid::BodySpec;
use bodies::{BodyMix, STREAM_SHAPE, STREAM_TURN};
use mixture::Mixture;
use rand::Rng;
use region::Region;
use serde_json::{json, Value};
use std::path::Path;

pub mod bodies;
mod check;
pub mod mixture;
mod region;
mod state;

pub use check::{check_report, extent};

/// Stream purposes (after placement's 1–3): a grain's size and velocity,
/// and one attempt's position.
const STREAM_GRAIN: u64 = 11;
const STREAM_SPOT: u64 = 12;
const STREAM_MATERIAL: u64 = 13;

/// Steps between two tries of a grain that found no room.
pub const RETRY_STEPS: u64 = 100;

/// SplitMix64's finaliser: nearby inputs give unrelated words.
fn mix(a: u64, b: u64) -> u64 {
    let mut z = a ^ b.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// How much an inlet delivers: `per_second` grains or kilograms per
/// second (`None`: everything at `start`), at most `total`.
#[derive(Clone, Copy, Debug)]
struct Amount {
    per_second: Option<f64>,
    total: f64,
    by_mass: bool,
}

/// One inlet: its keys checked, and its counters.
#[derive(Clone, Debug)]
struct Inlet<D: Dim> {
    key: String,
    region: Region<D>,
    start: f64,
    stop: f64,
    amount: Amount,
    velocity: D::V,
    spread: f64,
    law: SizeLaw,
    /// The materials: kinds, densities, fractions.
    mix: Mixture,
    /// An inlet of bodies: its shapes and fractions by number (checked
    /// with the keys), and the mixture built on the run's shapes.
    shares: Option<Vec<(usize, f64)>>,
    bodies: Option<BodyMix<D>>,
    model: MassModel,
    attempts: u32,
    /// Grains inserted, their mass, the attempts already spent on the
    /// next grain, and the attempts that found no room (all grains).
    inserted: u64,
    mass: f64,
    tries: u64,
    failed: u64,
    /// The step at which a grain that found no room is tried again (0:
    /// none waits), whatever else stops the run loop before it.
    retry_at: u64,
}

fn positive(key: &str, v: f64, unit: &str) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::input(format!(
            "{key} = {v}: must be positive ({unit})"
        )))
    }
}

impl<D: Dim> Inlet<D> {
    fn new(s: &Scenario, base: &Path, i: usize, spec: &InletSpec) -> Result<Self> {
        let key = format!("inlets[{i}]");
        let region = Region::<D>::new(&spec.region, &format!("{key}.region"))?;
        if !(spec.start.is_finite() && spec.start >= 0.0) {
            return Err(Error::input(format!(
                "{key}.start = {}: must be a time >= 0 (s)",
                spec.start
            )));
        }
        let stop = spec.stop.unwrap_or(f64::INFINITY);
        if stop.is_nan() || stop < spec.start {
            return Err(Error::input(format!(
                "{key}.stop = {stop}: must not come before start = {}",
                spec.start
            )));
        }
        let window = (stop > spec.start && stop.is_finite()).then_some(stop - spec.start);
        let given = [
            ("rate", spec.rate),
            ("mass_rate", spec.mass_rate),
            ("count", spec.count.map(|c| c as f64)),
            ("mass", spec.mass),
        ];
        let named: Vec<_> = given.iter().filter(|(_, v)| v.is_some()).collect();
        let [(name, Some(v))] = named[..] else {
            return Err(Error::input(format!(
                "{key}: give exactly one of rate (grains/s), mass_rate (kg/s), count (grains) \
                 and mass (kg); {} given",
                if named.is_empty() {
                    "none".to_string()
                } else {
                    named.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
                }
            )));
        };
        let full = format!("{key}.{name}");
        let amount = match *name {
            "rate" | "mass_rate" => Amount {
                per_second: Some(positive(&full, *v, "per second")?),
                total: f64::INFINITY,
                by_mass: *name == "mass_rate",
            },
            _ => {
                let total = positive(&full, *v, if *name == "mass" { "kg" } else { "grains" })?;
                Amount {
                    per_second: window.map(|w| total / w),
                    total,
                    by_mass: *name == "mass",
                }
            }
        };
        let velocity = match &spec.velocity {
            Some(v) => vector::<D>(&format!("{key}.velocity"), v)?,
            None => D::zero(),
        };
        let spread = spec.velocity_spread;
        if !((2.0 * spread).is_finite() && spread >= 0.0) {
            return Err(Error::input(format!(
                "{key}.velocity_spread = {spread}: must be a finite speed >= 0 (m/s)"
            )));
        }
        if spec.attempts == 0 {
            return Err(Error::input(format!(
                "{key}.attempts = 0: must be at least 1"
            )));
        }
        let ps = &s.particles;
        let shares = bodies::shares(s, spec, &key)?;
        let law = match &spec.size {
            Some(size) => SizeLaw::new(size, ps.mass_model, base).map_err(|e| match e {
                Error::Input(m) => {
                    Error::input(m.replace("particles.size", &format!("{key}.size")))
                }
                other => other,
            })?,
            None => SizeLaw::band(ps.d0, ps.width),
        };
        if !region.fits(0.5 * law.max()) {
            return Err(Error::input(format!(
                "{key}.region is narrower than its largest grain ({:.3e} m)",
                law.max()
            )));
        }
        let mix = match Mixture::new(s, spec, &key)? {
            Some(mix) => mix,
            None => {
                let kind = spec.kind.unwrap_or(1);
                // Grains of one kind share one material: a
                // `particles.add` entry of this kind may name it.
                let entry = ps.add.iter().find(|a| {
                    a.material.is_some() && a.kind.unwrap_or(if a.frozen { 2 } else { 1 }) == kind
                });
                let density = super::materials::density(s, entry)?;
                Mixture::single(kind, density, ps.frozen_types.contains(&kind))
            }
        };
        Ok(Self {
            key,
            region,
            start: spec.start,
            stop,
            amount,
            velocity,
            spread,
            law,
            mix,
            shares,
            bodies: None,
            model: ps.mass_model,
            attempts: spec.attempts,
            inserted: 0,
            mass: 0.0,
            tries: 0,
            failed: 0,
            retry_at: 0,
        })
    }

    /// What is due by time `t` (grains, or kilograms by mass).
    fn target(&self, t: f64) -> f64 {
        if t < self.start {
            return 0.0;
        }
        // A total is whole at stop, whatever the rounding of total/window.
        if t >= self.stop && self.amount.total.is_finite() {
            return self.amount.total;
        }
        match self.amount.per_second {
            Some(q) => (q * (t.min(self.stop) - self.start)).min(self.amount.total),
            None => self.amount.total,
        }
    }

    /// Grain `k`'s diameter, velocity and material (its place in the
    /// mixture).
    fn grain(&self, seed: u64, index: usize, k: u64) -> (f64, D::V, usize) {
        let mut rng = stream(mix(mix(seed, index as u64), k), STREAM_GRAIN);
        // The law was checked when built: its draws cannot fail but by an
        // exhausted redraw budget, which a checked law never reaches.
        let d = self.law.draw_with(&mut rng).unwrap_or(self.law.max());
        let mut v = self.velocity;
        if self.spread > 0.0 {
            for a in 0..D::D {
                let dv = self.spread * (2.0 * rng.gen::<f64>() - 1.0);
                let now = D::get(v, a);
                D::set(&mut v, a, now + dv);
            }
        }
        let c = (self.mix).pick(&mut stream(
            mix(mix(seed, index as u64), k),
            STREAM_MATERIAL,
        ));
        (d, v, c)
    }

    /// The mass of a grain of diameter `d` and material `c`.
    fn grain_mass(&self, d: f64, c: usize) -> f64 {
        self.model.mass(self.mix.part(c).density, d)
    }

    /// Item `k` (a grain, or a body of an inlet of bodies): its diameter,
    /// velocity and material as [`Inlet::grain`] gives them, its shape
    /// (`None` for a grain) and its mass.
    fn item(&self, seed: u64, index: usize, k: u64) -> (f64, D::V, usize, Option<usize>, f64) {
        let (d, v, c) = self.grain(seed, index, k);
        match &self.bodies {
            None => (d, v, c, None, self.grain_mass(d, c)),
            Some(b) => {
                let sh = b.pick(&mut stream(mix(mix(seed, index as u64), k), STREAM_SHAPE));
                (d, v, c, Some(sh), b.shapes[sh].mass)
            }
        }
    }

    /// Whether grain `k` (the next, with mass `m`) is due at time `t`.
    fn due(&self, k: u64, m: f64, t: f64) -> bool {
        let target = self.target(t);
        if self.amount.by_mass {
            self.mass + m <= target
        } else {
            (k + 1) as f64 <= target.floor()
        }
    }

    /// The first step after `now` at which the next grain is due
    /// (`u64::MAX`: never).
    fn next_due(&self, seed: u64, index: usize, now: u64, dt: f64) -> u64 {
        let k = self.inserted;
        let m = if self.amount.by_mass {
            self.item(seed, index, k).4
        } else {
            0.0
        };
        let need = if self.amount.by_mass {
            self.mass + m
        } else {
            (k + 1) as f64
        };
        if need > self.amount.total {
            return u64::MAX;
        }
        let at = match self.amount.per_second {
            Some(q) => self.start + need / q,
            None => self.start,
        };
        if at > self.stop + dt {
            return u64::MAX;
        }
        // Near the exact step, then the step the engine's clock agrees on.
        let mut s = ((at / dt).ceil().max(0.0) as u64).max(now + 1);
        while s > now + 1 && self.due(k, m, (s - 1) as f64 * dt) {
            s -= 1;
        }
        for _ in 0..4 {
            if self.due(k, m, s as f64 * dt) {
                return s;
            }
            s += 1;
        }
        u64::MAX
    }
}

/// Grains near `lo`–`hi` (periodic images included), with their radii.
fn near<D: Dim>(md: &Md<D>, lo: D::V, hi: D::V, margin: f64) -> Vec<(D::V, f64)> {
    let p = &md.particles;
    let centre = (lo + hi) * 0.5;
    let half = (hi - lo) * 0.5;
    (0..p.n_owned())
        .filter(|&i| {
            let d = md.domain.minimum_image(p.pos[i] - centre);
            (0..D::D).all(|a| D::get(d, a).abs() <= D::get(half, a) + margin)
        })
        .map(|i| (p.pos[i], p.radius[i]))
        .collect()
}

/// The run's shapes given to the inlets of bodies in `list`, each checked
/// against its region, its kind's material and the engine, which must
/// hold the shapes (`scenario/build.rs` registers them).
fn attach_bodies<D: Dim>(loaded: &Loaded, md: &Md<D>, list: &mut [Inlet<D>]) -> Result<()> {
    let s = &loaded.scenario;
    let (shapes, props) = super::shapes::build::<D>(loaded)?;
    if md.shape_sizes().len() != shapes.len() {
        return Err(Error::input(
            "[[inlets]] of bodies: the engine holds no [[shapes]] (built without them)",
        ));
    }
    let density = super::materials::density(s, None)?;
    for (inlet, spec) in list.iter_mut().zip(&s.inlets) {
        let Some(shares) = &inlet.shares else {
            continue;
        };
        let key = inlet.key.clone();
        let b = BodyMix::new(spec, &key, shares, &shapes, &props)?;
        if !inlet.region.fits(b.widest()) {
            return Err(Error::input(format!(
                "{key}.region is narrower than its widest body (bounding radius {:.3e} m)",
                b.widest()
            )));
        }
        if inlet.mix.part(0).density != density {
            return Err(Error::input(format!(
                "{key}.kind = {}: grains of that kind are of another material than \
                 particles.material, and a body's mass comes from its shape in \
                 particles.material",
                b.kind
            )));
        }
        inlet.bodies = Some(b);
    }
    Ok(())
}

/// The inlets of a run and the ids they hand out.
#[derive(Clone, Debug)]
pub struct Inlets<D: Dim> {
    list: Vec<Inlet<D>>,
    seed: u64,
    /// The first id inlets give (above every grain the scenario places)
    /// and the next one.
    first_id: u64,
    next_id: u64,
    /// The engine's time step: step s is at s dt.
    dt: f64,
    /// Wall time spent choosing and inserting grains (s), and the acts
    /// that inserted some: the cost of the inlets (not checkpointed).
    seconds: f64,
    acts: u64,
    /// Whether an inlet brings bodies, and each body inserted: its first
    /// grain id and shape (what a resume puts back as stand-ins).
    with_bodies: bool,
    made: Vec<(u64, u32)>,
}

impl<D: Dim> Inlets<D> {
    /// The inlets of `loaded` (none: an empty list) for the engine `md`
    /// built from it.
    pub fn begin(loaded: &Loaded, md: &Md<D>) -> Result<Self> {
        let s = &loaded.scenario;
        let mut list = s
            .inlets
            .iter()
            .enumerate()
            .map(|(i, spec)| Inlet::new(s, &loaded.base_dir, i, spec))
            .collect::<Result<Vec<_>>>()?;
        let with_bodies = list.iter().any(|x| x.shares.is_some());
        if with_bodies {
            attach_bodies(loaded, md, &mut list)?;
        }
        for inlet in &list {
            let (lo, hi) = inlet.region.bounds();
            let outside = (0..D::D).any(|a| {
                D::get(lo, a) < D::get(md.domain.lo, a) || D::get(hi, a) > D::get(md.domain.hi, a)
            });
            if outside {
                return Err(Error::input(format!(
                    "{}.region reaches outside the domain: keep it within domain.lo and domain.hi",
                    inlet.key
                )));
            }
        }
        if !list.is_empty() && md.domain.shear.is_some() {
            return Err(Error::input(
                "[[inlets]] and domain.shear do not go together: a sheared box's images \
                 slide, which the inlets' overlap test does not follow",
            ));
        }
        let first_id = md.particles.id.iter().copied().max().unwrap_or(0) + 1;
        Ok(Self {
            list,
            seed: s.seed,
            first_id,
            next_id: first_id,
            dt: md.settings.dt,
            seconds: 0.0,
            acts: 0,
            with_bodies,
            made: Vec::new(),
        })
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The next step after `now` at which an inlet acts (at most `horizon`).
    pub fn next_act(&self, now: u64, horizon: u64) -> u64 {
        let dt = self.dt;
        let t = now as f64 * dt;
        let mut next = horizon;
        for (i, inlet) in self.list.iter().enumerate() {
            let s = if t > inlet.stop + dt {
                u64::MAX
            } else if inlet.retry_at > now {
                inlet.retry_at
            } else {
                inlet.next_due(self.seed, i, now, dt)
            };
            next = next.min(s);
        }
        next.max(now + 1).min(horizon.max(now + 1))
    }

    /// Inserts every grain (or body) due at the engine's time that finds
    /// room.
    pub fn act(&mut self, md: &mut Md<D>) {
        if self.list.is_empty() {
            return;
        }
        let clock = std::time::Instant::now();
        let t = md.time;
        let walls: Vec<_> = md.walls.iter().map(|w| w.at(t)).collect();
        let largest = md.particles.max_radius();
        let mut added: Vec<ParticleRecord<D>> = Vec::new();
        // Bodies placed at this act (first grain id, body) and their
        // sub-spheres (centre, radius), which later candidates must clear.
        let mut new_bodies: Vec<(u64, BodySpec<D>)> = Vec::new();
        let mut subs: Vec<(D::V, f64)> = Vec::new();
        for (i, inlet) in self.list.iter_mut().enumerate() {
            let waiting = inlet.retry_at > md.step;
            if t < inlet.start || t > inlet.stop + md.settings.dt || waiting {
                continue;
            }
            let mut nearby: Option<Vec<(D::V, f64)>> = None;
            loop {
                let k = inlet.inserted;
                let (d, v, c, shape, m) = inlet.item(self.seed, i, k);
                if !inlet.due(k, m, t) {
                    break;
                }
                // A grain is a body of one sphere about its centre.
                let r = 0.5 * d;
                let (reach, widest, turn) = match (&inlet.bodies, shape) {
                    (Some(b), Some(sh)) => {
                        let mut rng = stream(mix(mix(self.seed, i as u64), k), STREAM_TURN);
                        let q = b.turn(sh, &mut rng);
                        (b.bound(sh), b.widest() + largest.max(b.largest_sub()), q)
                    }
                    _ => {
                        let half = 0.5 * inlet.law.max();
                        (r, half + largest.max(half), glam::DQuat::IDENTITY)
                    }
                };
                let (lo, hi) = inlet.region.bounds();
                let near = nearby.get_or_insert_with(|| near(md, lo, hi, widest));
                let free = |p: D::V, r: f64| {
                    let clear_of = |(q, rq): &(D::V, f64)| {
                        let gap = r + rq;
                        D::norm2(md.domain.minimum_image(p - *q)) >= gap * gap
                    };
                    near.iter().all(clear_of)
                        && added.iter().all(|g| clear_of(&(g.pos, g.radius)))
                        && subs.iter().all(clear_of)
                        && walls.iter().all(|w| w.contact(p, r).is_none())
                };
                let fits = |p: D::V| match (&inlet.bodies, shape) {
                    (Some(b), Some(sh)) => {
                        bodies::sub_spheres(&b.shapes[sh], p, turn).all(|(c, rc)| free(c, rc))
                    }
                    _ => free(p, r),
                };
                let mut spot = None;
                for j in 0..inlet.attempts as u64 {
                    let a = inlet.tries + j;
                    let mut rng = stream(mix(mix(mix(self.seed, i as u64), k), a), STREAM_SPOT);
                    let p = inlet.region.draw(reach, &mut rng);
                    if fits(p) {
                        spot = Some((p, j));
                        break;
                    }
                }
                let Some((p, j)) = spot else {
                    inlet.tries += inlet.attempts as u64;
                    inlet.failed += inlet.attempts as u64;
                    inlet.retry_at = md.step + RETRY_STEPS;
                    break;
                };
                inlet.failed += j;
                inlet.tries = 0;
                inlet.inserted += 1;
                inlet.mass += m;
                if let (Some(b), Some(sh)) = (&inlet.bodies, shape) {
                    subs.extend(bodies::sub_spheres(&b.shapes[sh], p, turn));
                    new_bodies.push((
                        self.next_id,
                        BodySpec {
                            shape: sh,
                            kind: b.kind,
                            pos: p,
                            orientation: wxyz(turn),
                            vel: v,
                            omega: D::ang_from_xyz([0.0; 3]),
                        },
                    ));
                    self.made.push((self.next_id, sh as u32));
                    self.next_id += b.shapes[sh].spheres.len() as u64;
                    continue;
                }
                let inertia = inlet.model.inertia(m, r);
                let mut g = ParticleRecord::new(self.next_id, p, r, m, inertia);
                g.vel = v;
                let part = inlet.mix.part(c);
                g.kind = part.kind;
                g.frozen = part.frozen;
                self.next_id += 1;
                added.push(g);
            }
        }
        if !added.is_empty() || !new_bodies.is_empty() {
            // Fresh ids, checked sizes and shapes: nothing here can be
            // refused.
            if let Err(e) = md.insert_grains(added) {
                eprintln!("warning: inlets: {e}");
            }
            if let Err(e) = md.insert_bodies(new_bodies) {
                eprintln!("warning: inlets: {e}");
            }
            self.acts += 1;
        }
        self.seconds += clock.elapsed().as_secs_f64();
    }

    /// Grains the inlets have inserted and their mass, summed inlet by
    /// inlet (the mass balance's supply).
    pub fn inserted(&self) -> (u64, f64) {
        (self.list.iter()).fold((0, 0.0), |(n, m), inlet| {
            (n + inlet.inserted, m + inlet.mass)
        })
    }

    /// Wall time spent in [`Inlets::act`] (s) and the acts that inserted
    /// grains.
    pub fn cost(&self) -> (f64, u64) {
        (self.seconds, self.acts)
    }

    /// Each inlet's account at time `t` (the end of the run):
    /// requested (grains due by then), inserted, mass, failed attempts,
    /// not inserted.
    pub fn report(&self, t: f64) -> Value {
        let rows: Vec<Value> = (self.list.iter().enumerate())
            .map(|(i, inlet)| {
                let requested = self.requested(i, inlet, t);
                let mut row = json!({
                    "requested": requested,
                    "inserted": inlet.inserted,
                    "mass": inlet.mass,
                    "failed_attempts": inlet.failed,
                    "not_inserted": requested.saturating_sub(inlet.inserted),
                });
                // An inlet of bodies counts them: said so, and only there,
                // so that an inlet of grains keeps its report.
                if inlet.shares.is_some() {
                    row["unit"] = json!("bodies");
                }
                row
            })
            .collect();
        Value::Array(rows)
    }

    /// Grains due by time `t`: by number the target; by mass the grains
    /// the target's mass holds, in their drawn order.
    fn requested(&self, i: usize, inlet: &Inlet<D>, t: f64) -> u64 {
        let target = inlet.target(t);
        if !inlet.amount.by_mass {
            return target.floor() as u64;
        }
        let (mut k, mut mass) = (inlet.inserted, inlet.mass);
        // Bounded: a grain's mass is at least the smallest grain's.
        let limit = k + 10_000_000;
        while k < limit {
            let m = inlet.item(self.seed, i, k).4;
            if mass + m > target {
                break;
            }
            mass += m;
            k += 1;
        }
        k
    }

    /// Warns on stderr about every inlet that fell short by time `t`.
    pub fn warn_short(&self, t: f64) {
        for (i, inlet) in self.list.iter().enumerate() {
            let requested = self.requested(i, inlet, t);
            if requested > inlet.inserted {
                eprintln!(
                    "warning: {}: {} of {requested} {} could not be inserted by t = {t:.4} s \
                     ({} attempts found no room): the region is full; widen it, lower the rate \
                     or let the grains drain",
                    inlet.key,
                    requested - inlet.inserted,
                    if inlet.shares.is_some() {
                        "bodies"
                    } else {
                        "grains"
                    },
                    inlet.failed
                );
            }
        }
    }

    /// The first id the inlets give: ids below it are the scenario's own.
    pub fn first_id(&self) -> u64 {
        self.first_id
    }
}
