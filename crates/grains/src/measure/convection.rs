//! Convection strength (seed 002 §3): the mean vertical velocity of the
//! grains in a central band of the box and in the two edge bands, averaged
//! over samples. Upward flow in the centre and downward at the edges is the
//! two-roll pattern of Fig. 2; walls (Fig. 3) reverse or keep it.

use crate::checkpoint::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::md::Md;

#[derive(Clone, Debug)]
pub struct Convection {
    /// Fraction of the box width taken by the central band, and by the two
    /// edge bands together.
    pub band: f64,
    center_sum: f64,
    center_n: u64,
    edge_sum: f64,
    edge_n: u64,
}

impl Convection {
    pub fn new(band: f64) -> Self {
        Self {
            band,
            center_sum: 0.0,
            center_n: 0,
            edge_sum: 0.0,
            edge_n: 0,
        }
    }

    /// Adds the vertical velocities of the grains in the bands now.
    pub fn sample<D: Dim>(&mut self, md: &Md<D>) {
        let p = &md.particles;
        let lo = D::get(md.domain.lo, 0);
        let l = md.domain.length(0);
        let up = D::vertical();
        for i in 0..p.n_owned() {
            if p.frozen[i] {
                continue;
            }
            // Position across the box in [0, 1), periodic or not.
            let s = ((D::get(p.pos[i], 0) - lo) / l).rem_euclid(1.0);
            let vz = D::get(p.vel[i], up);
            if (s - 0.5).abs() < 0.5 * self.band {
                self.center_sum += vz;
                self.center_n += 1;
            } else if s < 0.5 * self.band || s > 1.0 - 0.5 * self.band {
                self.edge_sum += vz;
                self.edge_n += 1;
            }
        }
    }

    /// Mean vertical velocity in the central band (m/s).
    pub fn center_vz(&self) -> f64 {
        if self.center_n == 0 {
            0.0
        } else {
            self.center_sum / self.center_n as f64
        }
    }

    /// Mean vertical velocity in the edge bands (m/s).
    pub fn edge_vz(&self) -> f64 {
        if self.edge_n == 0 {
            0.0
        } else {
            self.edge_sum / self.edge_n as f64
        }
    }
}

/// Checkpoint state (see `runner::checkpointing`).
impl Convection {
    pub fn save(&self, e: &mut Enc) {
        e.f64(self.band);
        e.f64(self.center_sum);
        e.u64(self.center_n);
        e.f64(self.edge_sum);
        e.u64(self.edge_n);
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        Ok(Self {
            band: d.f64("convection band")?,
            center_sum: d.f64("convection sum")?,
            center_n: d.u64("convection count")?,
            edge_sum: d.f64("convection sum")?,
            edge_n: d.u64("convection count")?,
        })
    }
}
