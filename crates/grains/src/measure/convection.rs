//! Convection strength (seed 002 §3): the mean vertical velocity of the
//! grains in a central band of the box and in the two edge bands, averaged
//! over samples. Upward flow in the centre and downward at the edges is the
//! two-roll pattern of Fig. 2; walls (Fig. 3) reverse or keep it. The same
//! average in columns across the box (`convection_profile.csv` and `.png`)
//! shows where the rolls turn: attached to the walls or not.

use super::plot::{save_plot, Series, Titles, PALETTE};
use crate::checkpoint::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::Result;
use crate::io::write_atomic;
use crate::md::Md;
use std::fmt::Write as _;
use std::path::Path;

/// Columns across the box for the profile of the mean vertical velocity.
pub const COLUMNS: usize = 20;

#[derive(Clone, Debug)]
pub struct Convection {
    /// Fraction of the box width taken by the central band, and by the two
    /// edge bands together.
    pub band: f64,
    center_sum: f64,
    center_n: u64,
    edge_sum: f64,
    edge_n: u64,
    column_sum: Vec<f64>,
    column_n: Vec<u64>,
}

impl Convection {
    pub fn new(band: f64) -> Self {
        Self {
            band,
            center_sum: 0.0,
            center_n: 0,
            edge_sum: 0.0,
            edge_n: 0,
            column_sum: vec![0.0; COLUMNS],
            column_n: vec![0; COLUMNS],
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
            let col = ((s * COLUMNS as f64) as usize).min(COLUMNS - 1);
            self.column_sum[col] += vz;
            self.column_n[col] += 1;
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

    /// Mean vertical velocity per column across the box whose x runs from
    /// `lo` over `width`: (column centre in m, mean v_z in m/s, samples);
    /// NaN for a column no grain visited.
    fn profile(&self, lo: f64, width: f64) -> Vec<(f64, f64, u64)> {
        (0..COLUMNS)
            .map(|k| {
                let x = lo + (k as f64 + 0.5) / COLUMNS as f64 * width;
                let n = self.column_n[k];
                let v = if n == 0 {
                    f64::NAN
                } else {
                    self.column_sum[k] / n as f64
                };
                (x, v, n)
            })
            .collect()
    }

    /// Writes `convection_profile.csv` and `convection_profile.png`.
    pub fn write<D: Dim>(&self, dir: &Path, domain: &Domain<D>) -> Result<()> {
        let rows = self.profile(D::get(domain.lo, 0), domain.length(0));
        let mut csv = String::from("x,mean_vz,samples\n");
        for (x, v, n) in &rows {
            let _ = writeln!(csv, "{x},{v},{n}");
        }
        write_atomic(&dir.join("convection_profile.csv"), csv.as_bytes())?;
        let series = Series {
            points: rows.iter().map(|r| [r.0 * 1e3, r.1]).collect(),
            colour: PALETTE[0],
            lines: true,
            errors: None,
        };
        let titles = Titles {
            x: "x (mm)",
            y: "mean vertical velocity (m/s)",
        };
        save_plot(&dir.join("convection_profile.png"), &[series], true, titles)
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
        for k in 0..COLUMNS {
            e.f64(self.column_sum[k]);
            e.u64(self.column_n[k]);
        }
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let mut c = Self::new(d.f64("convection band")?);
        c.center_sum = d.f64("convection sum")?;
        c.center_n = d.u64("convection count")?;
        c.edge_sum = d.f64("convection sum")?;
        c.edge_n = d.u64("convection count")?;
        for k in 0..COLUMNS {
            c.column_sum[k] = d.f64("convection column sum")?;
            c.column_n[k] = d.u64("convection column count")?;
        }
        Ok(c)
    }
}
