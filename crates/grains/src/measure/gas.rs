//! What a DSMC run measures: density and temperature profiles versus
//! height, the origin its thermo rows count from, the validity window.

use crate::codec::{Dec, DecResult, Enc};
use crate::dsmc::collide::{GasDim, Tally};
use crate::dsmc::diagnostics::Validity;
use crate::dsmc::engine::{haff_time, Dsmc};
use crate::settings::DsmcSpec;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;

/// Density and temperature versus height, accumulated over samples.
pub struct GasProfiles {
    lo: f64,
    width: f64,
    count: Vec<f64>,
    vsum: Vec<[f64; 3]>,
    v2: Vec<f64>,
    samples: u64,
}

impl GasProfiles {
    pub fn new<D: GasDim>(sim: &Dsmc<D>, bins: usize) -> Self {
        let v = D::vertical();
        let lo = D::get(sim.domain.lo, v);
        Self {
            lo,
            width: sim.domain.length(v) / bins as f64,
            count: vec![0.0; bins],
            vsum: vec![[0.0; 3]; bins],
            v2: vec![0.0; bins],
            samples: 0,
        }
    }
    pub fn sample<D: GasDim>(&mut self, sim: &Dsmc<D>) {
        let bins = self.count.len();
        for q in &sim.store.p {
            let h = (D::get(q.x, D::vertical()) - self.lo) / self.width;
            if h.is_nan() || h < 0.0 || h as usize >= bins {
                continue;
            }
            let b = h as usize;
            self.count[b] += 1.0;
            for a in 0..D::D {
                self.vsum[b][a] += D::get(q.v, a);
            }
            self.v2[b] += D::norm2(q.v);
        }
        self.samples += 1;
    }
    pub fn encode(&self, e: &mut Enc) {
        e.f64s(&self.count);
        e.len(self.vsum.len());
        self.vsum.iter().flatten().for_each(|&x| e.f64(x));
        e.f64s(&self.v2);
        e.u64(self.samples);
    }
    pub fn decode(&mut self, d: &mut Dec) -> DecResult<()> {
        let bins = self.count.len();
        let count = d.f64s("profile counts")?;
        let n = d.len(24, "profile velocities")?;
        let mut vsum = Vec::with_capacity(n);
        for _ in 0..n {
            vsum.push([d.f64("profile")?, d.f64("profile")?, d.f64("profile")?]);
        }
        let v2 = d.f64s("profile speeds")?;
        if count.len() != bins || vsum.len() != bins || v2.len() != bins {
            return Err(format!("profiles: the scenario has {bins} bins"));
        }
        (self.count, self.vsum, self.v2) = (count, vsum, v2);
        self.samples = d.u64("profile samples")?;
        Ok(())
    }
    pub fn csv<D: GasDim>(&self, sim: &Dsmc<D>) -> String {
        let mut out = String::from("height,number_density,packing_fraction,granular_temperature\n");
        let slab = sim.domain.volume() / sim.domain.length(D::vertical()) * self.width;
        for b in 0..self.count.len() {
            let c = self.count[b];
            let n = c / (self.samples.max(1) as f64 * slab);
            let t = if c > 1.0 {
                let mean2: f64 = (0..D::D).map(|a| (self.vsum[b][a] / c).powi(2)).sum();
                sim.store.mass * (self.v2[b] / c - mean2) / D::D as f64
            } else {
                0.0
            };
            let _ = writeln!(
                out,
                "{},{},{},{}",
                self.lo + (b as f64 + 0.5) * self.width,
                n,
                n * sim.store.particle_volume(),
                t
            );
        }
        out
    }
}

/// Where the measurement began: the time and the collision tallies its
/// thermo rows count from.
#[derive(Clone, Copy, Debug, Default)]
pub struct Origin {
    pub t_start: f64,
    pub c0: Tally,
}

impl Origin {
    /// The thermo row of `sim` (the DSMC runner's thermo.csv columns).
    pub fn row<D: GasDim>(&self, sim: &Dsmc<D>) -> [f64; 6] {
        let n = sim.store.len() as f64;
        [
            sim.step as f64,
            sim.time - self.t_start,
            sim.store.kinetic_energy(),
            sim.store.granular_temperature(),
            2.0 * (sim.totals.collisions - self.c0.collisions) as f64 / n,
            (sim.totals.candidates - self.c0.candidates) as f64 / n,
        ]
    }
}

/// What the measured part of a run accumulates (absent before it starts).
pub struct GasMeasurement {
    pub origin: Origin,
    pub temp0: f64,
    pub validity: Validity,
    pub profiles: Option<GasProfiles>,
}

impl GasMeasurement {
    pub fn new<D: GasDim>(sim: &Dsmc<D>, ds: &DsmcSpec) -> Self {
        Self {
            origin: Origin {
                t_start: sim.time,
                c0: sim.totals,
            },
            temp0: sim.store.granular_temperature(),
            validity: Validity::new(sim, ds.regions),
            profiles: (ds.profile_bins > 0).then(|| GasProfiles::new(sim, ds.profile_bins)),
        }
    }

    pub fn encode(&self, e: &mut Enc) {
        e.f64(self.origin.t_start);
        e.f64(self.temp0);
        e.u64(self.origin.c0.candidates);
        e.u64(self.origin.c0.collisions);
        self.validity.encode(e);
        e.bool(self.profiles.is_some());
        if let Some(p) = &self.profiles {
            p.encode(e);
        }
    }

    pub fn decode<D: GasDim>(sim: &Dsmc<D>, ds: &DsmcSpec, d: &mut Dec) -> DecResult<Self> {
        let mut m = Self::new(sim, ds);
        m.origin.t_start = d.f64("measure start")?;
        m.temp0 = d.f64("initial temperature")?;
        m.origin.c0 = Tally {
            candidates: d.u64("initial candidates")?,
            collisions: d.u64("initial collisions")?,
        };
        m.validity.decode(d)?;
        let has = d.bool("profiles")?;
        match (&mut m.profiles, has) {
            (Some(p), true) => p.decode(d)?,
            (None, false) => {}
            _ => return Err("profiles: presence differs from the scenario".into()),
        }
        Ok(m)
    }

    /// The measurement state as checkpoint bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut e = Enc::default();
        self.encode(&mut e);
        e.buf
    }
}

/// Columns of a DSMC thermo.csv.
pub const THERMO_COLUMNS: [&str; 6] = [
    "step",
    "time",
    "kinetic_energy",
    "granular_temperature",
    "collisions_per_particle",
    "candidates_per_particle",
];

/// The gas's state at the end of a run, for summary.json: kinetic energy,
/// temperature, collisions counted while measuring, Haff's τ0 for an
/// inelastic gas, and the validity diagnostics (shared with the
/// distributed runner).
pub fn gas_summary<D: GasDim>(summary: &mut Map<String, Value>, sim: &Dsmc<D>, m: &GasMeasurement) {
    summary.insert("kinetic_energy".into(), json!(sim.store.kinetic_energy()));
    summary.insert(
        "granular_temperature".into(),
        json!(sim.store.granular_temperature()),
    );
    summary.insert(
        "collisions".into(),
        json!(sim.totals.collisions - m.origin.c0.collisions),
    );
    if sim.settings.restitution < 1.0 {
        let omega0 =
            sim.kinetic_collision_frequency(sim.number_density(), sim.packing_fraction(), m.temp0);
        summary.insert(
            "haff_tau0".into(),
            json!(haff_time(D::D, sim.settings.restitution, omega0)),
        );
        summary.insert("haff_initial_temperature".into(), json!(m.temp0));
    }
    summary.insert("validity".into(), m.validity.summary(sim));
}
