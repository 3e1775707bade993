//! Grains that leave: the `[[outlets]]` that take grains out of a run, the
//! `[[sensors]]` that count the grains crossing a plane, and what they
//! write (outflow.csv, sensors.csv, the discharge rate and the mass
//! balance of summary.json).
//!
//! The flow run ([`crate::scenario::flow::FlowRun`]) holds them and calls
//! [`Outlets::after_step`] after every step, so they act at every step and
//! their state travels in the flow section of a checkpoint.
//!
//! With rigid bodies the unit is a free grain or a whole body: an outlet
//! takes a body out, all its sub-spheres at once, when its centre of mass
//! is inside; a sensor sees a body cross when its centre of mass does; a
//! removal's row, the counts and the mass balance hold the body once, by
//! its first grain id, with its mass (its diameter in outflow.csv: that of
//! the sphere of its sub-spheres' summed volume).

use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::scenario::keys;
use crate::scenario::schema::{OutletSpec, PlaneSpec, Scenario, SensorSpec};
use serde_json::{json, Map, Value};
use std::time::Instant;

mod discharge;

use discharge::{steady_rate, write_outflow, write_sensors};

/// Where an outlet takes grains out.
#[derive(Clone, Debug)]
enum Region<V> {
    /// Beyond the plane: (x − point)·normal > 0.
    Plane {
        point: V,
        normal: V,
    },
    Box {
        lo: V,
        hi: V,
    },
    /// Within `radius` of the segment from `a` along the unit `axis` for
    /// `length` (in 2D a disk about `a`: `length` 0).
    Cylinder {
        a: V,
        axis: V,
        length: f64,
        radius: f64,
    },
}

struct Outlet<D: Dim> {
    name: String,
    region: Region<D::V>,
    start: f64,
    every: u64,
}

struct Sensor<D: Dim> {
    name: String,
    point: D::V,
    normal: D::V,
    every: u64,
    /// Each grain's side at the last check, indexed by id (ids are dense
    /// from a placement; a hash per grain and step cost a third of a small
    /// run): 0 not seen, 1 behind, 2 on the side `normal` points to.
    side: Vec<u8>,
    /// Every crossing: (time, +1 or −1, mass), in the order found.
    crossings: Vec<(f64, i8, f64)>,
}

/// One removed grain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Removal {
    pub step: u64,
    pub time: f64,
    pub outlet: u32,
    pub id: u64,
    pub mass: f64,
    pub diameter: f64,
}

/// The outlets and sensors of a run, with what they have counted.
pub struct Outlets<D: Dim> {
    outlets: Vec<Outlet<D>>,
    sensors: Vec<Sensor<D>>,
    /// Diameter edges of the size classes (empty: one class).
    edges: Vec<f64>,
    tolerance: f64,
    bin: Option<f64>,
    /// Grains and their mass (summed in id order) when the run began (a
    /// restart carries its checkpoint's).
    pub(crate) initial: (u64, f64),
    removed: Vec<Removal>,
    /// Wall time spent by the outlets (scan and removal) and by the
    /// sensors in [`Outlets::after_step`] (not checkpointed).
    seconds: (f64, f64),
}

fn unit<D: Dim>(v: &[f64], key: &str) -> Result<D::V> {
    let n = keys::vector::<D>(key, v)?;
    let len = D::norm(n);
    if len == 0.0 {
        return Err(Error::input(format!("{key}: must not be the zero vector")));
    }
    Ok(n / len)
}

fn plane<D: Dim>(p: &PlaneSpec, key: &str) -> Result<(D::V, D::V)> {
    Ok((
        keys::vector::<D>(&format!("{key}.point"), &p.point)?,
        unit::<D>(&p.normal, &format!("{key}.normal"))?,
    ))
}

impl<V: crate::dim::Linear> Region<V> {
    fn contains<D: Dim<V = V>>(&self, x: V) -> bool {
        match *self {
            Region::Plane { point, normal } => D::dot(x - point, normal) > 0.0,
            Region::Box { lo, hi } => {
                (0..D::D).all(|k| D::get(x, k) >= D::get(lo, k) && D::get(x, k) <= D::get(hi, k))
            }
            Region::Cylinder {
                a,
                axis,
                length,
                radius,
            } => {
                let r = x - a;
                let s = D::dot(r, axis);
                (0.0..=length).contains(&s) && D::norm2(r - axis * s) <= radius * radius
            }
        }
    }
}

fn outlet<D: Dim>(k: usize, o: &OutletSpec) -> Result<Outlet<D>> {
    let key = format!("outlets[{k}] (\"{}\")", o.name);
    let given = [
        o.plane.is_some(),
        o.region_box.is_some(),
        o.cylinder.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(Error::input(format!(
            "{key}: give exactly one of plane = {{ point, normal }}, box = {{ lo, hi }}, \
             cylinder = {{ a, b, radius }}"
        )));
    }
    if !o.start.is_finite() || o.start < 0.0 {
        return Err(Error::input(format!(
            "{key}.start = {}: must be a time (s) >= 0",
            o.start
        )));
    }
    let region = if let Some(p) = &o.plane {
        let (point, normal) = plane::<D>(p, &format!("{key}.plane"))?;
        Region::Plane { point, normal }
    } else if let Some(b) = &o.region_box {
        let lo = keys::vector::<D>(&format!("{key}.box.lo"), &b.lo)?;
        let hi = keys::vector::<D>(&format!("{key}.box.hi"), &b.hi)?;
        if (0..D::D).any(|k| D::get(lo, k) >= D::get(hi, k)) {
            return Err(Error::input(format!(
                "{key}.box: lo must be below hi on every axis"
            )));
        }
        Region::Box { lo, hi }
    } else {
        let c = o.cylinder.as_ref().expect("one region is given");
        if !(c.radius.is_finite() && c.radius > 0.0) {
            return Err(Error::input(format!(
                "{key}.cylinder.radius = {}: must be positive",
                c.radius
            )));
        }
        let a = keys::vector::<D>(&format!("{key}.cylinder.a"), &c.a)?;
        // In 2D a disk about a: no axis, every point at s = 0.
        let (axis, length) = match (&c.b, D::D) {
            (_, 2) => (D::zero(), 0.0),
            (Some(b), _) => {
                let b = keys::vector::<D>(&format!("{key}.cylinder.b"), b)?;
                let l = D::norm(b - a);
                if l == 0.0 {
                    return Err(Error::input(format!(
                        "{key}.cylinder: b must differ from a"
                    )));
                }
                ((b - a) / l, l)
            }
            (None, _) => {
                return Err(Error::input(format!(
                    "{key}.cylinder: a 3D cylinder needs both ends a and b"
                )))
            }
        };
        Region::Cylinder {
            a,
            axis,
            length,
            radius: c.radius,
        }
    };
    if o.every == 0 {
        return Err(Error::input(format!(
            "{key}.every = 0: must be at least 1 step"
        )));
    }
    Ok(Outlet {
        name: o.name.clone(),
        region,
        start: o.start,
        every: o.every,
    })
}

fn sensor<D: Dim>(k: usize, s: &SensorSpec) -> Result<Sensor<D>> {
    let key = format!("sensors[{k}] (\"{}\")", s.name);
    let point = keys::vector::<D>(&format!("{key}.point"), &s.point)?;
    let normal = unit::<D>(&s.normal, &format!("{key}.normal"))?;
    if s.every == 0 {
        return Err(Error::input(format!(
            "{key}.every = 0: must be at least 1 step"
        )));
    }
    Ok(Sensor {
        name: s.name.clone(),
        point,
        normal,
        every: s.every,
        side: Vec::new(),
        crossings: Vec::new(),
    })
}

/// The size-class edges: given, or the grains' diameter range split in
/// `n` equal parts (none when the grains have one size).
fn class_edges(s: &Scenario, diameters: impl Iterator<Item = f64>) -> Result<Vec<f64>> {
    if let Some(e) = &s.outflow.size_edges {
        if e.iter().any(|x| !(x.is_finite() && *x > 0.0)) || e.windows(2).any(|w| w[0] >= w[1]) {
            return Err(Error::input(format!(
                "outflow.size_edges = {e:?}: must be ascending positive diameters (m)"
            )));
        }
        return Ok(e.clone());
    }
    let n = s.outflow.size_classes;
    if n == 0 {
        return Err(Error::input(
            "outflow.size_classes = 0: must be at least 1 (1: no classes)",
        ));
    }
    let (lo, hi) = diameters.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| {
        (a.min(d), b.max(d))
    });
    if lo >= hi || n == 1 {
        return Ok(Vec::new());
    }
    Ok((1..n)
        .map(|k| lo + (hi - lo) * k as f64 / n as f64)
        .collect())
}

/// The size class of diameter `d` under `edges`.
pub(crate) fn class_of(edges: &[f64], d: f64) -> usize {
    edges.partition_point(|&e| e <= d)
}

impl<D: Dim> Outlets<D> {
    /// The outlets and sensors of the scenario, checked; `None` without
    /// any. `md` is the engine at the start of the run.
    pub fn begin(s: &Scenario, md: &Md<D>) -> Result<Option<Self>> {
        if s.outlets.is_empty() && s.sensors.is_empty() {
            return Ok(None);
        }
        let outlets = (s.outlets.iter().enumerate())
            .map(|(k, o)| outlet::<D>(k, o))
            .collect::<Result<Vec<_>>>()?;
        let sensors = (s.sensors.iter().enumerate())
            .map(|(k, o)| sensor::<D>(k, o))
            .collect::<Result<Vec<_>>>()?;
        let mut names: Vec<&str> = outlets.iter().map(|o| o.name.as_str()).collect();
        names.extend(sensors.iter().map(|o| o.name.as_str()));
        let mut sorted = names.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(Error::input(format!(
                "outlets/sensors: the name \"{}\" is used twice; each needs its own",
                w[0]
            )));
        }
        let tol = s.outflow.steady_tolerance;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(Error::input(format!(
                "outflow.steady_tolerance = {tol}: must be a positive fraction"
            )));
        }
        if let Some(b) = s.outflow.bin {
            if !(b.is_finite() && b > 0.0) {
                return Err(Error::input(format!(
                    "outflow.bin = {b}: must be a positive time (s)"
                )));
            }
        }
        let p = &md.particles;
        let n = p.n_owned();
        let edges = class_edges(s, (0..n).map(|i| 2.0 * p.radius[i]))?;
        let order = md.id_order();
        let mut mass = order.iter().map(|&i| p.mass[i as usize]).sum::<f64>();
        let mut n = n;
        if md.has_bodies() {
            let units = md.units();
            n = units.len();
            mass = units.iter().map(|u| u.2).sum();
        }
        let mut run = Self {
            outlets,
            sensors,
            edges,
            tolerance: tol,
            bin: s.outflow.bin,
            initial: (n as u64, mass),
            removed: Vec::new(),
            seconds: (0.0, 0.0),
        };
        run.check_sensors(md, true);
        Ok(Some(run))
    }

    /// After a step: the sensors due count the grains that crossed them,
    /// then the outlets take out the mobile grains in them (a grain in two
    /// outlets counts for the first). Fails only on an engine that cannot
    /// remove grains.
    pub fn after_step(&mut self, md: &mut Md<D>) -> Result<()> {
        let start = Instant::now();
        self.check_sensors(md, false);
        let sensed = Instant::now();
        self.seconds.1 += (sensed - start).as_secs_f64();
        if md.has_bodies() {
            self.remove_units(md)?;
            self.seconds.0 += sensed.elapsed().as_secs_f64();
            return Ok(());
        }
        let p = &md.particles;
        let mut which: Vec<(u64, u32)> = Vec::new();
        for (k, o) in self.outlets.iter().enumerate() {
            if md.time < o.start || !md.step.is_multiple_of(o.every) {
                continue;
            }
            for i in 0..p.n_owned() {
                if !p.frozen[i] && o.region.contains::<D>(p.pos[i]) {
                    which.push((p.id[i], k as u32));
                }
            }
        }
        if !which.is_empty() {
            // First outlet wins; then in id order (as the removal returns them).
            which.sort_by_key(|&(id, k)| (id, k));
            which.dedup_by_key(|w| w.0);
            let ids: Vec<u64> = which.iter().map(|w| w.0).collect();
            let gone = md.remove_grains(&ids)?;
            let mut rows: Vec<Removal> = gone
                .iter()
                .zip(&which)
                .map(|(r, &(_, outlet))| Removal {
                    step: md.step,
                    time: md.time,
                    outlet,
                    id: r.id,
                    mass: r.mass,
                    diameter: 2.0 * r.radius,
                })
                .collect();
            rows.sort_by_key(|r| (r.outlet, r.id));
            for s in &mut self.sensors {
                for r in &rows {
                    s.side[r.id as usize] = 0;
                }
            }
            self.removed.extend(rows);
        }
        self.seconds.0 += sensed.elapsed().as_secs_f64();
        Ok(())
    }

    /// [`Outlets::after_step`]'s removal in a run with bodies: the free
    /// grains in an outlet, and the bodies whose centre of mass is in one,
    /// taken out whole.
    fn remove_units(&mut self, md: &mut Md<D>) -> Result<()> {
        let units = md.units();
        let mut which: Vec<(u64, u32)> = Vec::new();
        let frozen: std::collections::HashSet<u64> = (0..md.particles.n_owned())
            .filter(|&i| md.particles.frozen[i])
            .map(|i| md.particles.id[i])
            .collect();
        for (k, o) in self.outlets.iter().enumerate() {
            if md.time < o.start || !md.step.is_multiple_of(o.every) {
                continue;
            }
            for &(id, x, _) in &units {
                if !frozen.contains(&id) && o.region.contains::<D>(x) {
                    which.push((id, k as u32));
                }
            }
        }
        if which.is_empty() {
            return Ok(());
        }
        which.sort_by_key(|&(id, k)| (id, k));
        which.dedup_by_key(|w| w.0);
        // A unit's grain ids: a body's all its sub-spheres', consecutive.
        let spans: Vec<std::ops::Range<u64>> = (which.iter())
            .map(|&(id, _)| md.body_grain_ids(id).unwrap_or(id..id + 1))
            .collect();
        let ids: Vec<u64> = spans.iter().flat_map(|r| r.clone()).collect();
        let gone = md.remove_grains(&ids)?;
        let mass: std::collections::HashMap<u64, f64> = units.iter().map(|u| (u.0, u.2)).collect();
        let mut rows: Vec<Removal> = Vec::with_capacity(which.len());
        // `gone` is in id order, as `which` and its spans are.
        let mut at = 0;
        for (&(id, outlet), span) in which.iter().zip(&spans) {
            let mut volume = 0.0;
            while at < gone.len() && span.contains(&gone[at].id) {
                volume += (2.0 * gone[at].radius).powi(3);
                at += 1;
            }
            rows.push(Removal {
                step: md.step,
                time: md.time,
                outlet,
                id,
                mass: mass[&id],
                diameter: volume.cbrt(),
            });
        }
        rows.sort_by_key(|r| (r.outlet, r.id));
        for s in &mut self.sensors {
            for r in &rows {
                s.side[r.id as usize] = 0;
            }
        }
        self.removed.extend(rows);
        Ok(())
    }

    /// The first step after `now`, at most `horizon`, at which an outlet
    /// or a sensor looks at the grains.
    pub fn next_due(&self, now: u64, horizon: u64) -> u64 {
        let everies = self.outlets.iter().map(|o| o.every);
        everies
            .chain(self.sensors.iter().map(|s| s.every))
            .map(|e| (now / e + 1) * e)
            .fold(horizon, u64::min)
    }

    /// Counts the crossings of the sensors due at this step (`first`: only
    /// notes where each grain is).
    fn check_sensors(&mut self, md: &Md<D>, first: bool) {
        let p = &md.particles;
        let top = p.id[..p.n_owned()].iter().copied().max().unwrap_or(0);
        // With bodies a body crosses when its centre of mass does.
        let units = md.has_bodies().then(|| md.units());
        for s in &mut self.sensors {
            if !first && !md.step.is_multiple_of(s.every) {
                continue;
            }
            if s.side.len() <= top as usize {
                s.side.resize(top as usize + 1, 0);
            }
            let mut found: Vec<(u64, i8, f64)> = Vec::new();
            let mut look = |id: u64, x: D::V, m: f64| {
                let now = 1 + u8::from(D::dot(x - s.point, s.normal) > 0.0);
                let was = std::mem::replace(&mut s.side[id as usize], now);
                if was != 0 && was != now {
                    found.push((id, if now == 2 { 1 } else { -1 }, m));
                }
            };
            match &units {
                Some(units) => units.iter().for_each(|&(id, x, m)| look(id, x, m)),
                None => (0..p.n_owned()).for_each(|i| look(p.id[i], p.pos[i], p.mass[i])),
            }
            found.sort_by_key(|f| f.0);
            s.crossings
                .extend(found.into_iter().map(|(_, sign, m)| (md.time, sign, m)));
        }
    }

    /// The ids of the grains removed so far.
    pub fn removed_ids(&self) -> Vec<u64> {
        self.removed.iter().map(|r| r.id).collect()
    }

    /// The ids of the last `n` grains removed, in the order removed.
    pub fn last_removed(&self, n: usize) -> Vec<u64> {
        let from = self.removed.len().saturating_sub(n);
        self.removed[from..].iter().map(|r| r.id).collect()
    }

    /// outflow.csv and sensors.csv in `dir`; the discharge rate, the
    /// sensors' counts and the mass balance into `summary`.
    pub fn finish(
        &self,
        dir: &std::path::Path,
        md: &Md<D>,
        inserted: (u64, f64),
        summary: &mut Map<String, Value>,
    ) -> Result<()> {
        let names: Vec<&str> = self.outlets.iter().map(|o| o.name.as_str()).collect();
        if !self.outlets.is_empty() {
            write_outflow(dir, &self.removed, &names, &self.edges)?;
            let rate = steady_rate(&self.removed, self.bin, self.tolerance);
            summary.extend(rate.into_summary());
            let mut each = Map::new();
            for (k, name) in names.iter().enumerate() {
                let mine = self.removed.iter().filter(|r| r.outlet == k as u32);
                let (n, m) = mine.fold((0u64, 0.0), |(n, m), r| (n + 1, m + r.mass));
                each.insert((*name).into(), json!({ "grains": n, "mass": m }));
            }
            summary.insert("outlets".into(), Value::Object(each));
            summary.insert("size_class_edges".into(), json!(self.edges));
        }
        if !self.sensors.is_empty() {
            let rows: Vec<_> = self
                .sensors
                .iter()
                .map(|s| (s.name.as_str(), s.crossings.as_slice()))
                .collect();
            let bin = self.bin.unwrap_or(md.time / 20.0);
            write_sensors(dir, &rows, bin, md.time)?;
            let mut each = Map::new();
            for s in &self.sensors {
                let plus = s.crossings.iter().filter(|c| c.1 > 0).count();
                let minus = s.crossings.len() - plus;
                let net: f64 = s.crossings.iter().map(|c| f64::from(c.1) * c.2).sum();
                each.insert(
                    s.name.clone(),
                    json!({ "crossings_forward": plus, "crossings_back": minus, "net_mass": net }),
                );
            }
            summary.insert("sensors".into(), Value::Object(each));
        }
        summary.insert("mass_balance".into(), self.balance(md, inserted));
        summary.insert("outlet_seconds".into(), json!(self.seconds.0));
        summary.insert("sensor_seconds".into(), json!(self.seconds.1));
        Ok(())
    }

    /// The mass balance: initial + inserted (`inserted`: the inlets'
    /// grains and mass) = present + removed, the counts as integers and the
    /// masses as sums in id order over the same grains, so that without
    /// inlets `exact` holds bit for bit; the inlets sum their mass in their
    /// own order, so with them the masses must agree to 1e-12 (rounding of
    /// sums of positive terms, n ε with n far below 10⁴ per ulp).
    ///
    /// With bodies every count and sum is over units (free grains and
    /// whole bodies, [`Md::units`]).
    pub(crate) fn balance(&self, md: &Md<D>, inserted: (u64, f64)) -> Value {
        let p = &md.particles;
        let (n, present_mass, mut both) = if md.has_bodies() {
            let units = md.units();
            let mass = units.iter().map(|u| u.2).sum::<f64>();
            let both: Vec<(u64, f64)> = units.iter().map(|u| (u.0, u.2)).collect();
            (units.len(), mass, both)
        } else {
            let n = p.n_owned();
            let mass = md
                .id_order()
                .iter()
                .map(|&i| p.mass[i as usize])
                .sum::<f64>();
            let both: Vec<(u64, f64)> = (0..n).map(|i| (p.id[i], p.mass[i])).collect();
            (n, mass, both)
        };
        both.extend(self.removed.iter().map(|r| (r.id, r.mass)));
        both.sort_by_key(|b| b.0);
        let accounted = both.iter().map(|b| b.1).sum::<f64>();
        let removed_mass = self.removed.iter().map(|r| r.mass).sum::<f64>();
        let (inserted_grains, inserted_mass) = inserted;
        let supplied = self.initial.1 + inserted_mass;
        let mass_ok = match inserted_grains {
            0 => accounted == supplied,
            _ => (accounted - supplied).abs() <= 1e-12 * supplied,
        };
        let count_ok = self.initial.0 + inserted_grains == n as u64 + self.removed.len() as u64;
        let mut v = json!({
            "initial_grains": self.initial.0,
            "initial_mass": self.initial.1,
            "inserted_grains": inserted_grains,
            "inserted_mass": inserted_mass,
            "present_grains": n,
            "present_mass": present_mass,
            "removed_grains": self.removed.len(),
            "removed_mass": removed_mass,
            "accounted_mass": accounted,
            "mass_gap": accounted - supplied,
            "exact": count_ok && mass_ok,
        });
        if md.has_bodies() {
            v["counted"] = json!("free grains and whole bodies");
        }
        v
    }

    /// The state as bytes (the scenario's keys aside).
    pub fn save(&self, e: &mut Enc) {
        e.len(self.removed.len());
        for r in &self.removed {
            e.u64(r.step);
            e.f64(r.time);
            e.u32(r.outlet);
            e.u64(r.id);
            e.f64(r.mass);
            e.f64(r.diameter);
        }
        e.len(self.sensors.len());
        for s in &self.sensors {
            e.bytes(&s.side);
            e.len(s.crossings.len());
            for &(t, sign, m) in &s.crossings {
                e.f64(t);
                e.u8(sign as u8);
                e.f64(m);
            }
        }
    }

    /// Reads what [`Outlets::save`] wrote into outlets begun from the same
    /// scenario.
    pub fn load(&mut self, d: &mut Dec) -> DecResult<()> {
        let n = d.len(44, "removed grains")?;
        self.removed = (0..n)
            .map(|_| {
                Ok(Removal {
                    step: d.u64("removal step")?,
                    time: d.f64("removal time")?,
                    outlet: d.u32("removal outlet")?,
                    id: d.u64("removed grain")?,
                    mass: d.f64("removed mass")?,
                    diameter: d.f64("removed diameter")?,
                })
            })
            .collect::<DecResult<_>>()?;
        if self
            .removed
            .iter()
            .any(|r| r.outlet as usize >= self.outlets.len())
        {
            return Err("a removal names an outlet the scenario lacks".into());
        }
        let k = d.len(16, "sensors")?;
        if k != self.sensors.len() {
            return Err(format!(
                "flow state holds {k} sensors, the scenario {}",
                self.sensors.len()
            ));
        }
        for s in &mut self.sensors {
            s.side = d.bytes("sensor sides")?.to_vec();
            let c = d.len(17, "sensor crossings")?;
            s.crossings = (0..c)
                .map(|_| {
                    Ok((
                        d.f64("crossing time")?,
                        d.u8("crossing sign")? as i8,
                        d.f64("crossing mass")?,
                    ))
                })
                .collect::<DecResult<_>>()?;
        }
        Ok(())
    }
}
