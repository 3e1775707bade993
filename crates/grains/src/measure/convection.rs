//! Convection strength (seed 002 §3): the mean vertical velocity of the
//! grains in a central band of the box and in the two edge bands, averaged
//! over samples. Upward flow in the centre and downward at the edges is the
//! two-roll pattern of Fig. 2; walls (Fig. 3) reverse or keep it. The same
//! average in columns across the box (`convection_profile.csv` and `.png`)
//! shows where the rolls turn: attached to the walls or not. The mean
//! height of the grains in the same columns shows the heaping the seed sees
//! near its walls (a heap of height h on a flat bed raises a column's mean
//! by about h/2): `heap_height` is the mean height in the edge bands'
//! columns minus that in the central band's. A mean, not the highest grain:
//! the maximum of a column depends on how many grains it holds, and fewer
//! fit in a column at a wall.

use super::plot::{save_plot, Series, Titles, PALETTE};
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::Result;
use crate::io::write_atomic;
use crate::view::GrainView;
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
    /// Sum of the grains' heights per column (samples: `column_n`).
    height_sum: Vec<f64>,
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
            height_sum: vec![0.0; COLUMNS],
        }
    }

    /// Adds the vertical velocities of the grains in the bands now.
    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        let p = &view.grains;
        let lo = D::get(view.domain.lo, 0);
        let l = view.domain.length(0);
        let up = D::vertical();
        for i in 0..p.len() {
            if p.frozen[i] {
                continue;
            }
            // Position across the box in [0, 1), periodic or not.
            let s = ((D::get(p.pos[i], 0) - lo) / l).rem_euclid(1.0);
            let vz = D::get(p.vel[i], up);
            let col = ((s * COLUMNS as f64) as usize).min(COLUMNS - 1);
            self.column_sum[col] += vz;
            self.column_n[col] += 1;
            self.height_sum[col] += D::get(p.pos[i], up);
            if (s - 0.5).abs() < 0.5 * self.band {
                self.center_sum += vz;
                self.center_n += 1;
            } else if s < 0.5 * self.band || s > 1.0 - 0.5 * self.band {
                self.edge_sum += vz;
                self.edge_n += 1;
            }
        }
    }

    /// Mean height of the grains in each column (m); NaN for a column no
    /// grain visited.
    fn mean_heights(&self) -> Vec<f64> {
        column_means(&self.height_sum, &self.column_n)
    }

    /// Mean grain height in the columns of the edge bands minus that in the
    /// columns of the central band (m), the bands of the velocities: positive
    /// when the grains heap up at the edges. NaN when a band holds no column
    /// or a column was never visited.
    pub fn heap_height(&self) -> f64 {
        let h = self.mean_heights();
        let band_mean = |keep: &dyn Fn(f64) -> bool| {
            let v: Vec<f64> = (0..COLUMNS)
                .filter(|&k| keep((k as f64 + 0.5) / COLUMNS as f64))
                .map(|k| h[k])
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        let half = 0.5 * self.band;
        band_mean(&|s| s < half || s > 1.0 - half) - band_mean(&|s| (s - 0.5).abs() < half)
    }

    /// Mean vertical velocity in the central band (m/s).
    pub fn center_vz(&self) -> f64 {
        band_mean(self.center_sum, self.center_n)
    }

    /// Mean vertical velocity per column across the box whose x runs from
    /// `lo` over `width`: (column centre in m, mean v_z in m/s, samples);
    /// NaN for a column no grain visited.
    fn profile(&self, lo: f64, width: f64) -> Vec<(f64, f64, u64)> {
        let means = column_means(&self.column_sum, &self.column_n);
        (0..COLUMNS)
            .map(|k| {
                let x = lo + (k as f64 + 0.5) / COLUMNS as f64 * width;
                (x, means[k], self.column_n[k])
            })
            .collect()
    }

    /// Writes `convection_profile.csv` and the pictures of its two
    /// profiles, `convection_profile.png` and `height_profile.png`.
    pub fn write<D: Dim>(&self, dir: &Path, domain: &Domain<D>) -> Result<()> {
        let rows = self.profile(D::get(domain.lo, 0), domain.length(0));
        let heights = self.mean_heights();
        let mut csv = String::from("x,mean_vz,samples,mean_height\n");
        for ((x, v, n), h) in rows.iter().zip(&heights) {
            let _ = writeln!(csv, "{x},{v},{n},{h}");
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
        save_plot(&dir.join("convection_profile.png"), &[series], true, titles)?;
        let series = Series {
            points: rows
                .iter()
                .zip(&heights)
                .map(|(r, h)| [r.0 * 1e3, h * 1e3])
                .collect(),
            colour: PALETTE[1],
            lines: true,
            errors: None,
        };
        let titles = Titles {
            x: "x (mm)",
            y: "mean grain height (mm)",
        };
        save_plot(&dir.join("height_profile.png"), &[series], false, titles)
    }

    /// Mean vertical velocity in the edge bands (m/s).
    pub fn edge_vz(&self) -> f64 {
        band_mean(self.edge_sum, self.edge_n)
    }
}

/// Per column, the sum over its samples divided by their count; NaN for a
/// column no grain visited (so a plot leaves a gap instead of a false zero).
fn column_means(sums: &[f64], counts: &[u64]) -> Vec<f64> {
    sums.iter()
        .zip(counts)
        .map(|(&s, &n)| if n == 0 { f64::NAN } else { s / n as f64 })
        .collect()
}

/// Mean of a band's samples; 0 before any grain was in the band (the
/// summary holds a number: JSON has no NaN).
fn band_mean(sum: f64, count: u64) -> f64 {
    if count == 0 {
        0.0
    } else {
        sum / count as f64
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
            e.f64(self.height_sum[k]);
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
            c.height_sum[k] = d.f64("convection height sum")?;
        }
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactLaw;
    use crate::dim::D2;
    use crate::md::{Md, MdSettings};
    use crate::particles::{ParticleRecord, Particles};
    use glam::DVec2;

    /// Still disks stacked in columns of a 20 mm box: 3 in the two columns
    /// at each edge (the edge bands of `band = 0.2`), 1 elsewhere. The edge
    /// columns' mean height is two radii above the others', and nothing
    /// moves vertically.
    #[test]
    fn height_profile_finds_the_heap_at_the_walls() {
        let r = 0.4e-3;
        let mut p = Particles::<D2>::new();
        let mut id = 0;
        let mut column = |x: f64, n: usize, p: &mut Particles<D2>| {
            for k in 0..n {
                id += 1;
                let pos = DVec2::new(x, r + 2.0 * r * k as f64);
                p.push_record(ParticleRecord::new(id, pos, r, 1e-6, 1e-13));
            }
        };
        for c in 0..COLUMNS {
            let x = (c as f64 + 0.5) * 1e-3;
            let edge = !(2..COLUMNS - 2).contains(&c);
            column(x, if edge { 3 } else { 1 }, &mut p);
        }
        let domain = Domain::new(DVec2::ZERO, DVec2::new(0.02, 0.02), [true, false, false]);
        let law = ContactLaw {
            kn: 1e3,
            beta: 1.0,
            gamma_n: 0.0,
            gamma_t: 0.0,
            kt: 0.0,
            mu: 0.0,
            scaling: crate::contact::MassScaling::Reduced,
            rotation: false,
        };
        let md = Md::new(p, domain, Vec::new(), MdSettings::new(1e-6, law, 1e-4)).unwrap();
        let mut c = Convection::new(0.2);
        c.sample(&md.view());
        c.sample(&md.view());
        assert!(
            (c.heap_height() - 2.0 * r).abs() < 1e-15,
            "{}",
            c.heap_height()
        );
        assert_eq!(c.center_vz(), 0.0);
        let h = c.mean_heights();
        assert!((h[0] - 3.0 * r).abs() < 1e-15);
        assert!((h[COLUMNS / 2] - r).abs() < 1e-15);
    }
}
