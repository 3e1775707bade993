//! The MD engine of a [`super::Session`].

use super::held::{Column, Contacts, Held};
use crate::dim::Dim;
use crate::engine::Engine;
use crate::error::Result;
use crate::io::contact_records::Snapshot;
use crate::io::BodyRow;
use crate::md::Md;
use crate::measure::granular_temperature;
use crate::output::{md_summary, THERMO_COLUMNS};
use crate::runner::saved::Opened;
use crate::scenario::{build_md, Loaded, Resolved};
use rayon::prelude::*;
use serde_json::{Map, Value};
use std::sync::{Arc, Mutex};

struct MdEngine<D: Dim> {
    md: Md<D>,
    resolved: Resolved,
    /// The id order of the store and the neighbour build it was taken at:
    /// the store is reordered only when the list is rebuilt, and reading
    /// the arrays of a large system (10^6 grains) must stay fast.
    order: Mutex<Option<(u64, Arc<Vec<u32>>)>>,
}

type Built = (Box<dyn Held>, (u64, u64), u64);

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
pub(super) fn restore<D: Dim>(opened: &Opened) -> Result<(Box<dyn Held>, u64)> {
    let (md, resolved) = opened.md::<D>()?;
    let (engine, _, every) = wrap(md, resolved, opened.plan());
    Ok((engine, every))
}

/// The start of an output buffer shared by the threads of a scatter.
struct Base<T>(*mut T);
// SAFETY: the threads write disjoint entries (see `MdEngine::gather`).
unsafe impl<T: Send> Sync for Base<T> {}

impl<D: Dim> MdEngine<D> {
    /// The place in ascending id order of each store entry (cached until
    /// the next neighbour build, the only time the store is reordered).
    fn order(&self) -> Arc<Vec<u32>> {
        let builds = self.md.neighbor_builds();
        let mut cache = self.order.lock().unwrap_or_else(|e| e.into_inner());
        match &*cache {
            Some((b, order)) if *b == builds => Arc::clone(order),
            _ => {
                // The rank in id order of each store entry.
                let order = self.md.id_order();
                let mut rank = vec![0u32; order.len()];
                for (k, &i) in order.iter().enumerate() {
                    rank[i as usize] = k as u32;
                }
                let rank = Arc::new(rank);
                *cache = Some((builds, Arc::clone(&rank)));
                rank
            }
        }
    }

    /// `width` numbers per grain from `get` into `out`, in id order. The
    /// store is read in its own order and each grain's numbers written to
    /// their place (in parallel): reading in id order would wait on a
    /// cache miss per grain of a large system.
    fn gather<T: Send>(&self, out: &mut [T], width: usize, get: impl Fn(usize, &mut [T]) + Sync) {
        let rank = self.order();
        assert_eq!(out.len(), rank.len() * width);
        let base = Base(out.as_mut_ptr());
        rank.par_chunks(4096).enumerate().for_each(|(c, ranks)| {
            let base = &base;
            for (j, &k) in ranks.iter().enumerate() {
                // SAFETY: `rank` is a permutation of 0..n, so every grain
                // writes its own `width` entries of `out` (n * width long,
                // checked above) and no two threads write the same one.
                let o = unsafe {
                    std::slice::from_raw_parts_mut(base.0.add(k as usize * width), width)
                };
                get(c * 4096 + j, o);
            }
        });
    }

    /// One number per grain, in id order.
    fn scalars<T: Copy + Default + Send + Sync>(&self, v: &[T]) -> Vec<T> {
        let mut out = vec![T::default(); self.len()];
        self.gather(&mut out, 1, |i, o| o[0] = v[i]);
        out
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

impl<D: Dim> Held for MdEngine<D> {
    fn engine(&self) -> &dyn Engine {
        &self.md
    }
    fn engine_mut(&mut self) -> &mut dyn Engine {
        &mut self.md
    }
    fn len(&self) -> usize {
        self.md.particles.n_owned()
    }
    fn thermo_columns(&self) -> &'static [&'static str] {
        &THERMO_COLUMNS
    }
    fn thermo_row(&self) -> Vec<f64> {
        let md = &self.md;
        vec![
            md.step as f64,
            md.time,
            md.kinetic_energy(),
            md.rotational_energy(),
            granular_temperature(&md.particles),
            md.stats.contacts as f64,
            md.stats.max_overlap,
        ]
    }
    fn ids(&self) -> Vec<u64> {
        self.scalars(&self.md.particles.id)
    }
    fn fill(&self, col: Column, out: &mut [f64]) {
        let p = &self.md.particles;
        let vector = |v: &[D::V], out: &mut [f64]| {
            self.gather(out, D::D, |i, o| {
                o.copy_from_slice(&D::to_xyz(v[i])[..D::D])
            })
        };
        match col {
            Column::Positions => vector(&p.pos, out),
            Column::Velocities => vector(&p.vel, out),
            Column::AngularVelocities if D::D == 2 => {
                self.gather(out, 1, |i, o| o[0] = D::ang_to_xyz(p.omega[i])[2])
            }
            Column::AngularVelocities => {
                self.gather(out, 3, |i, o| o.copy_from_slice(&D::ang_to_xyz(p.omega[i])))
            }
            Column::Diameters => self.gather(out, 1, |i, o| o[0] = 2.0 * p.radius[i]),
            Column::Masses => self.gather(out, 1, |i, o| o[0] = p.mass[i]),
        }
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
        self.md.kinetic_energy()
    }
    fn rotational_energy(&self) -> f64 {
        self.md.rotational_energy()
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
    fn snapshot(&self) -> Option<Snapshot> {
        Some(crate::measure::fields::snapshot(&self.md.view()))
    }
    fn body_rows(&self) -> Vec<BodyRow> {
        self.md.body_rows().unwrap_or_default()
    }
    fn summary(&self, loaded: &Loaded, stepped: u64, wall_seconds: f64) -> Map<String, Value> {
        let md = &self.md;
        let mut s = md_summary(loaded, md, &self.resolved, md.step, stepped, wall_seconds);
        crate::md::contract::scalars(md, &mut s, wall_seconds);
        s
    }
}
