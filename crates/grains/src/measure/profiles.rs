//! Density and horizontal-velocity profiles versus height (seed 002, conveyor
//! belt): grains are binned by the height of their centre above the bottom of
//! the domain, averaged over every sample of the measurement (the steady
//! state after relaxation). Also the transport velocity: the mean horizontal
//! velocity of the mobile grains, averaged over the samples.

use super::plot::{save_plot, Series, Titles, PALETTE};
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::Result;
use crate::io::write_atomic;
use crate::view::GrainView;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Profiles {
    /// Bin height (m).
    bin: f64,
    /// Height of the bottom of the domain (m).
    base: f64,
    /// Horizontal area (2D: length) of the domain, for densities.
    across: f64,
    dim: usize,
    count: Vec<f64>,
    /// Σ grain volume (2D: area) of the grains binned.
    volume: Vec<f64>,
    vx: Vec<f64>,
    samples: u64,
    transport_sum: f64,
}

impl Profiles {
    pub fn new<D: Dim>(view: &GrainView<D>, bin: f64) -> Self {
        let up = D::vertical();
        let across: f64 = (0..D::D)
            .filter(|&a| a != up)
            .map(|a| view.domain.length(a))
            .product();
        Self {
            bin,
            base: D::get(view.domain.lo, up),
            across,
            dim: D::D,
            count: Vec::new(),
            volume: Vec::new(),
            vx: Vec::new(),
            samples: 0,
            transport_sum: 0.0,
        }
    }

    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        let p = &view.grains;
        let up = D::vertical();
        let (mut sum, mut n) = (0.0, 0usize);
        for i in 0..p.len() {
            if p.frozen[i] {
                continue;
            }
            let vx = D::get(p.vel[i], 0);
            sum += vx;
            n += 1;
            let h = D::get(p.pos[i], up) - self.base;
            if !(h.is_finite() && h >= 0.0) {
                continue;
            }
            let k = (h / self.bin) as usize;
            if k > 100_000 {
                continue;
            }
            if k >= self.count.len() {
                self.count.resize(k + 1, 0.0);
                self.volume.resize(k + 1, 0.0);
                self.vx.resize(k + 1, 0.0);
            }
            let r = p.radius[i];
            self.count[k] += 1.0;
            self.volume[k] += if D::D == 2 {
                PI * r * r
            } else {
                4.0 / 3.0 * PI * r * r * r
            };
            self.vx[k] += vx;
        }
        if n > 0 {
            self.transport_sum += sum / n as f64;
        }
        self.samples += 1;
    }

    /// Mean horizontal velocity of the mobile grains over the run (m/s).
    pub fn transport_velocity(&self) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            self.transport_sum / self.samples as f64
        }
    }

    /// Rows (height of bin centre, number density, packing fraction, mean vx).
    pub fn rows(&self) -> Vec<[f64; 4]> {
        let s = self.samples.max(1) as f64;
        let cell = self.bin * self.across;
        (0..self.count.len())
            .map(|k| {
                let n = self.count[k];
                [
                    (k as f64 + 0.5) * self.bin,
                    n / s / cell,
                    self.volume[k] / s / cell,
                    if n > 0.0 { self.vx[k] / n } else { f64::NAN },
                ]
            })
            .collect()
    }

    /// profiles.csv, profile_density.png (packing fraction against height)
    /// and profile_velocity.png (mean vx against height).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let rows = self.rows();
        let unit = if self.dim == 2 { "m^-2" } else { "m^-3" };
        let mut csv = format!(
            "# {} samples; bin {} m; transport_velocity {} m/s\nheight,number_density_{unit},packing_fraction,vx\n",
            self.samples,
            self.bin,
            self.transport_velocity()
        );
        for r in &rows {
            let _ = writeln!(csv, "{},{},{},{}", r[0], r[1], r[2], r[3]);
        }
        write_atomic(&dir.join("profiles.csv"), csv.as_bytes())?;
        // Height up the vertical axis, as in the seed's description.
        let dens = Series {
            points: rows.iter().map(|r| [r[2], r[0] * 1e3]).collect(),
            colour: PALETTE[0],
            lines: true,
            errors: None,
        };
        let titles = |x| Titles {
            x,
            y: "height (mm)",
        };
        save_plot(
            &dir.join("profile_density.png"),
            &[dens],
            false,
            titles("packing fraction"),
        )?;
        let vel = Series {
            points: rows
                .iter()
                .filter(|r| r[1] * self.bin * self.across * 50.0 >= 1.0 || r[3].is_nan())
                .filter(|r| r[3].is_finite())
                .map(|r| [r[3], r[0] * 1e3])
                .collect(),
            colour: PALETTE[1],
            lines: true,
            errors: None,
        };
        save_plot(
            &dir.join("profile_velocity.png"),
            &[vel],
            false,
            titles("mean vx (m/s)"),
        )
    }
}

/// Checkpoint state (see `runner::checkpointing`).
impl Profiles {
    pub fn save(&self, e: &mut Enc) {
        e.f64(self.bin);
        e.f64(self.base);
        e.f64(self.across);
        e.len(self.dim);
        e.f64s(&self.count);
        e.f64s(&self.volume);
        e.f64s(&self.vx);
        e.u64(self.samples);
        e.f64(self.transport_sum);
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let p = Self {
            bin: d.f64("profile bin")?,
            base: d.f64("profile base")?,
            across: d.f64("profile area")?,
            dim: d.u64("profile dimension")? as usize,
            count: d.f64s("profile counts")?,
            volume: d.f64s("profile volumes")?,
            vx: d.f64s("profile velocities")?,
            samples: d.u64("profile samples")?,
            transport_sum: d.f64("transport sum")?,
        };
        if p.count.len() != p.volume.len() || p.count.len() != p.vx.len() {
            return Err("profiles: bins of different lengths".into());
        }
        Ok(p)
    }
}
