//! Validity of DSMC during a run (seed 000 §4): the method holds only if
//! (i) the gas is collisional (Knudsen number λ/L below 1, L the smallest
//! box length), (ii) the mean free path exceeds the cell size, (iii) the
//! mean time between collisions exceeds the time step. Measured per region
//! (horizontal slabs of cell layers) from the collisions that happened:
//! ω = 2 C / (⟨N⟩ Δt), λ = ⟨|v|⟩ / ω, τ_c = 1 / ω.

use super::collide::GasDim;
use super::engine::Dsmc;
use crate::codec::{Dec, DecResult, Enc};
use serde_json::{json, Value};

#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    particle_samples: f64,
    samples: u64,
    speed_sum: f64,
    collisions: u64,
    time: f64,
}

impl Acc {
    fn add(&mut self, o: &Acc) {
        self.particle_samples += o.particle_samples;
        self.speed_sum += o.speed_sum;
        self.collisions += o.collisions;
    }
    fn mean_particles(&self) -> f64 {
        self.particle_samples / self.samples.max(1) as f64
    }
    /// Collision frequency per particle.
    fn omega(&self) -> f64 {
        let n = self.mean_particles();
        if n <= 0.0 || self.time <= 0.0 {
            return 0.0;
        }
        2.0 * self.collisions as f64 / (n * self.time)
    }
    fn mean_speed(&self) -> f64 {
        self.speed_sum / self.particle_samples.max(1.0)
    }
    fn mean_free_path(&self) -> f64 {
        let w = self.omega();
        if w > 0.0 {
            self.mean_speed() / w
        } else {
            f64::INFINITY
        }
    }
}

/// Per-region validity measurements and the warnings they raised.
pub struct Validity {
    regions: usize,
    layers_per_region: Vec<(usize, usize)>,
    bounds: Vec<(f64, f64)>,
    total: Vec<Acc>,
    total_time: f64,
    last_time: f64,
    warned: Vec<[bool; 3]>,
    pub warnings: Vec<String>,
}

fn fmt_num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3e}")
    } else {
        "infinite".into()
    }
}

impl Validity {
    /// `regions` horizontal slabs (at most one per layer of cells).
    pub fn new<D: GasDim>(sim: &Dsmc<D>, regions: usize) -> Self {
        let layers = sim.grid.layers();
        let regions = regions.clamp(1, layers);
        let v = D::vertical();
        let mut layers_per_region = Vec::new();
        let mut bounds = Vec::new();
        for r in 0..regions {
            let (a, b) = (r * layers / regions, (r + 1) * layers / regions);
            layers_per_region.push((a, b));
            let lo = sim.grid.lo[v];
            bounds.push((
                lo + a as f64 * sim.grid.size[v],
                lo + b as f64 * sim.grid.size[v],
            ));
        }
        Self {
            regions,
            layers_per_region,
            bounds,
            total: vec![Acc::default(); regions],
            total_time: 0.0,
            last_time: sim.time,
            warned: vec![[false; 3]; regions],
            warnings: Vec::new(),
        }
    }

    /// Reads the collisions since the last sample (clearing the cells'
    /// counters) and the particles now; checks the window's figures and
    /// returns the new warnings.
    pub fn sample<D: GasDim>(&mut self, sim: &mut Dsmc<D>) -> Vec<String> {
        let dt_window = sim.time - self.last_time;
        self.last_time = sim.time;
        let per_layer = sim.grid.cells_per_layer();
        let mut window = vec![Acc::default(); self.regions];
        // Region of each cell layer.
        let mut region_of = vec![0usize; sim.grid.layers()];
        for (r, &(a, b)) in self.layers_per_region.iter().enumerate() {
            region_of[a..b].fill(r);
            let w = &mut window[r];
            for c in a * per_layer..b * per_layer {
                w.collisions += sim.cells[c].collisions as u64;
            }
            w.samples = 1;
            w.time = dt_window;
        }
        for (c, q) in sim.particles_with_cells() {
            let w = &mut window[region_of[c / per_layer]];
            w.particle_samples += 1.0;
            w.speed_sum += D::norm(q.v);
        }
        for st in &mut sim.cells {
            st.collisions = 0;
        }
        let mut new = Vec::new();
        if dt_window > 0.0 {
            let lmin = (0..D::D)
                .map(|a| sim.domain.length(a))
                .fold(f64::INFINITY, f64::min);
            let cell = sim.grid.max_edge();
            let dt = sim.settings.dt;
            for (r, w) in window.iter().enumerate() {
                if w.mean_particles() < 2.0 {
                    continue;
                }
                let lambda = w.mean_free_path();
                let omega = w.omega();
                let tau = if omega > 0.0 {
                    1.0 / omega
                } else {
                    f64::INFINITY
                };
                let (lo, hi) = self.bounds[r];
                let name = ["x", "y", "z"][D::vertical()];
                let region = format!("region {r} ({name} in [{lo:.4e}, {hi:.4e}) m)");
                let fails = [
                    (lambda >= lmin).then(|| format!("(i) not collisional: mean free path {} m is not below the box size {} m (Knudsen number {})", fmt_num(lambda), fmt_num(lmin), fmt_num(lambda / lmin))),
                    (lambda <= cell).then(|| format!("(ii) mean free path {} m is not larger than the cell size {} m (ratio {})", fmt_num(lambda), fmt_num(cell), fmt_num(lambda / cell))),
                    (tau <= dt).then(|| format!("(iii) mean collision time {} s is not larger than the time step {} s (ratio {})", fmt_num(tau), fmt_num(dt), fmt_num(tau / dt))),
                ];
                for (k, f) in fails.into_iter().enumerate() {
                    if let Some(msg) = f {
                        if !self.warned[r][k] {
                            self.warned[r][k] = true;
                            let w =
                                format!("DSMC validity at t = {:.4e} s, {region}: {msg}", sim.time);
                            new.push(w.clone());
                            self.warnings.push(w);
                        }
                    }
                }
            }
        }
        for (t, w) in self.total.iter_mut().zip(&window) {
            t.add(w);
            t.samples += 1;
        }
        self.total_time += dt_window;
        new
    }

    /// The accumulated state, for a checkpoint (the region layout is
    /// rebuilt from the engine by [`Validity::new`]).
    pub fn encode(&self, e: &mut Enc) {
        e.len(self.total.len());
        for a in &self.total {
            e.f64(a.particle_samples);
            e.u64(a.samples);
            e.f64(a.speed_sum);
            e.u64(a.collisions);
            e.f64(a.time);
        }
        e.f64(self.total_time);
        e.f64(self.last_time);
        for w in &self.warned {
            w.iter().for_each(|&b| e.bool(b));
        }
        e.len(self.warnings.len());
        self.warnings.iter().for_each(|w| e.str(w));
    }

    /// Reads back what [`Validity::encode`] wrote into a `Validity` built
    /// by [`Validity::new`] for the same engine and region count.
    pub fn decode(&mut self, d: &mut Dec) -> DecResult<()> {
        let n = d.len(40, "validity regions")?;
        if n != self.regions {
            return Err(format!(
                "validity: {n} regions, the scenario has {}",
                self.regions
            ));
        }
        for a in &mut self.total {
            *a = Acc {
                particle_samples: d.f64("validity")?,
                samples: d.u64("validity")?,
                speed_sum: d.f64("validity")?,
                collisions: d.u64("validity")?,
                time: d.f64("validity")?,
            };
        }
        self.total_time = d.f64("validity time")?;
        self.last_time = d.f64("validity time")?;
        for w in &mut self.warned {
            for b in w.iter_mut() {
                *b = d.bool("validity warned")?;
            }
        }
        let n = d.len(8, "validity warnings")?;
        self.warnings = (0..n)
            .map(|_| d.str("validity warning"))
            .collect::<DecResult<_>>()?;
        Ok(())
    }

    /// Figures over the whole run, per region and overall.
    pub fn summary<D: GasDim>(&self, sim: &Dsmc<D>) -> Value {
        let mut all = Acc::default();
        let regions: Vec<Value> = self
            .total
            .iter()
            .enumerate()
            .map(|(r, a)| {
                let mut a = *a;
                a.time = self.total_time;
                all.add(&a);
                let omega = a.omega();
                json!({
                    "region": r,
                    "lo": self.bounds[r].0, "hi": self.bounds[r].1,
                    "mean_particles": a.mean_particles(),
                    "collisions_per_particle": omega * self.total_time,
                    "mean_free_path": a.mean_free_path(),
                    "mean_collision_time": if omega > 0.0 { 1.0 / omega } else { f64::INFINITY },
                    "mean_free_path_over_cell": a.mean_free_path() / sim.grid.max_edge(),
                    "mean_collision_time_over_dt": if omega > 0.0 { 1.0 / (omega * sim.settings.dt) } else { f64::INFINITY },
                })
            })
            .collect();
        all.samples = self.total.first().map_or(1, |a| a.samples);
        all.time = self.total_time;
        let omega = all.omega();
        json!({
            "cell_size": sim.grid.max_edge(),
            "dt": sim.settings.dt,
            "collisions_per_particle": omega * self.total_time,
            "mean_free_path": all.mean_free_path(),
            "mean_collision_time": if omega > 0.0 { 1.0 / omega } else { f64::INFINITY },
            "mean_free_path_over_cell": all.mean_free_path() / sim.grid.max_edge(),
            "mean_collision_time_over_dt": if omega > 0.0 { 1.0 / (omega * sim.settings.dt) } else { f64::INFINITY },
            "regions": regions,
            "warnings": self.warnings,
        })
    }
}
