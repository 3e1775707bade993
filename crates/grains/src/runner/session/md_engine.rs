//! The MD engine of a [`super::Session`].

use super::{Contacts, Engine};
use crate::checkpoint::engine as ckengine;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::measure::granular_temperature;
use crate::runner::checkpointing::Found;
use crate::runner::md_summary;
use crate::runner::output::THERMO_COLUMNS;
use crate::scenario::{build_md, Loaded, Resolved};
use rayon::prelude::*;
use serde_json::{json, Map, Value};
use std::sync::{Arc, Mutex};

struct MdEngine<D: Dim> {
    md: Md<D>,
    resolved: Resolved,
    /// The id order of the store and the neighbour build it was taken at:
    /// the store is reordered only when the list is rebuilt, and reading
    /// the arrays of a large system (10^6 grains) must stay fast.
    order: Mutex<Option<(u64, Arc<Vec<u32>>)>>,
}

type Built = (Box<dyn Engine>, (u64, u64), u64);

/// The engine `grains run` builds for an MD scenario, its (relaxation,
/// measured) steps and its output interval.
pub(super) fn build<D: Dim>(loaded: &Loaded) -> Result<Built> {
    let (md, resolved) = build_md::<D>(loaded)?;
    let plan = (resolved.relax_steps, resolved.measure_steps);
    Ok(wrap(md, resolved, plan))
}

fn wrap<D: Dim>(mut md: Md<D>, resolved: Resolved, plan: (u64, u64)) -> Built {
    md.timing.reset();
    let every = resolved.output_every;
    let engine = MdEngine {
        md,
        resolved,
        order: Mutex::new(None),
    };
    (Box::new(engine), plan, every)
}

/// The engine of an MD checkpoint and its output interval.
pub(super) fn restore<D: Dim>(found: &Found) -> Result<(Box<dyn Engine>, u64)> {
    let (md, resolved) = found.restore_built::<D>()?;
    let (engine, _, every) = wrap(md, resolved, found.plan);
    Ok((engine, every))
}

impl<D: Dim> MdEngine<D> {
    /// Store indices in ascending id order (cached until the next rebuild).
    fn order(&self) -> Arc<Vec<u32>> {
        let builds = self.md.neighbor_builds();
        let mut cache = self.order.lock().unwrap_or_else(|e| e.into_inner());
        match &*cache {
            Some((b, order)) if *b == builds => Arc::clone(order),
            _ => {
                let order = Arc::new(self.md.id_order());
                *cache = Some((builds, Arc::clone(&order)));
                order
            }
        }
    }

    /// `width` numbers per grain from `get`, flat, in id order (in
    /// parallel: a million grains are tens of megabytes).
    fn gather<T: Copy + Default + Send + Sync>(
        &self,
        width: usize,
        get: impl Fn(usize, &mut [T]) + Sync,
    ) -> Vec<T> {
        let order = self.order();
        let mut out = vec![T::default(); order.len() * width];
        out.par_chunks_mut(width * 4096)
            .zip(order.par_chunks(4096))
            .for_each(|(o, idx)| {
                for (o, &i) in o.chunks_exact_mut(width).zip(idx) {
                    get(i as usize, o);
                }
            });
        out
    }

    /// One vector per grain, flat, in id order.
    fn vectors(&self, v: &[D::V]) -> Vec<f64> {
        self.gather(D::D, |i, o| o.copy_from_slice(&D::to_xyz(v[i])[..D::D]))
    }

    /// One number per grain, in id order.
    fn scalars<T: Copy + Default + Send + Sync>(&self, v: &[T]) -> Vec<T> {
        self.gather(1, |i, o| o[0] = v[i])
    }
}

/// Flat numbers as vectors of `D`.
fn unflatten<D: Dim>(flat: &[f64]) -> Vec<D::V> {
    flat.chunks_exact(D::D)
        .map(|c| {
            let mut x = [0.0; 3];
            x[..D::D].copy_from_slice(c);
            D::from_xyz(x)
        })
        .collect()
}

impl<D: Dim> Engine for MdEngine<D> {
    fn dim(&self) -> usize {
        D::D
    }
    fn len(&self) -> usize {
        self.md.particles.n_owned()
    }
    fn step(&self) -> u64 {
        self.md.step
    }
    fn time(&self) -> f64 {
        self.md.time
    }
    fn dt(&self) -> f64 {
        self.md.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        self.md.run(n)
    }
    fn thermo_columns(&self) -> &'static [&'static str] {
        &THERMO_COLUMNS
    }
    fn thermo_row(&self) -> Vec<f64> {
        let md = &self.md;
        vec![
            md.step as f64,
            md.time,
            md.particles.kinetic_energy(),
            md.particles.rotational_energy(),
            granular_temperature(&md.particles),
            md.stats.contacts as f64,
            md.stats.max_overlap,
        ]
    }
    fn ids(&self) -> Vec<u64> {
        self.scalars(&self.md.particles.id)
    }
    fn positions(&self) -> Vec<f64> {
        self.vectors(&self.md.particles.pos)
    }
    fn velocities(&self) -> Vec<f64> {
        self.vectors(&self.md.particles.vel)
    }
    fn angular_velocities(&self) -> Vec<f64> {
        let w = &self.md.particles.omega;
        match D::D {
            2 => self.gather(1, |i, o| o[0] = D::ang_to_xyz(w[i])[2]),
            _ => self.gather(3, |i, o| o.copy_from_slice(&D::ang_to_xyz(w[i]))),
        }
    }
    fn diameters(&self) -> Vec<f64> {
        let mut d = self.scalars(&self.md.particles.radius);
        d.iter_mut().for_each(|r| *r *= 2.0);
        d
    }
    fn masses(&self) -> Vec<f64> {
        self.scalars(&self.md.particles.mass)
    }
    fn frozen(&self) -> Vec<bool> {
        self.scalars(&self.md.particles.frozen)
    }
    fn set_state(&mut self, pos: Option<&[f64]>, vel: Option<&[f64]>) -> Result<()> {
        let pos = pos.map(unflatten::<D>);
        let vel = vel.map(unflatten::<D>);
        let md = &mut self.md;
        crate::parallel::on_pool(|| md.set_state(pos.as_deref(), vel.as_deref()))
    }
    fn kinetic_energy(&self) -> f64 {
        self.md.particles.kinetic_energy()
    }
    fn rotational_energy(&self) -> f64 {
        self.md.particles.rotational_energy()
    }
    fn granular_temperature(&self) -> f64 {
        granular_temperature(&self.md.particles)
    }
    fn contacts(&self) -> Result<Contacts> {
        let c = self.md.contact_list();
        let flat = |v: &[D::V]| {
            v.iter()
                .flat_map(|&x| D::to_xyz(x).into_iter().take(D::D))
                .collect()
        };
        Ok(Contacts {
            normal: flat(&c.normal),
            force: flat(&c.force),
            ids: c.ids,
            overlap: c.overlap,
        })
    }
    fn summary(&self, loaded: &Loaded, stepped: u64, wall_seconds: f64) -> Map<String, Value> {
        let md = &self.md;
        let mut s = md_summary(loaded, md, &self.resolved, md.step, stepped, wall_seconds);
        s.insert("neighbor_builds".into(), json!(md.neighbor_builds()));
        s.insert("phase_seconds".into(), md.timing.to_json(wall_seconds, 1.0));
        s
    }
    fn checkpoint(&self) -> Result<Vec<u8>> {
        ckengine::encode(&self.md).map_err(|e| match e {
            Error::Input(m) => Error::input(format!("save_checkpoint: {m}")),
            other => other,
        })
    }
}
