//! Density along the vertical axis against time (pipe flow, density waves):
//! the number of grains per unit length in bins along the vertical axis at
//! every sample. spacetime.csv (one row per sample) and spacetime.png (time
//! to the right, height up, darker = denser).

use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::Result;
use crate::io::{write_atomic, Image, View};
use crate::view::GrainView;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Spacetime {
    lo: f64,
    bin: f64,
    bins: usize,
    rows: Vec<(f64, Vec<f64>)>,
}

impl Spacetime {
    /// Bins of length `bin` (m) over the domain's vertical extent.
    pub fn new<D: Dim>(view: &GrainView<D>, bin: f64) -> Self {
        let v = D::vertical();
        let lo = D::get(view.domain.lo, v);
        let hi = D::get(view.domain.hi, v);
        let bins = ((hi - lo) / bin).ceil().max(1.0) as usize;
        Self {
            lo,
            bin,
            bins,
            rows: Vec::new(),
        }
    }

    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        if self.rows.last().map(|r| r.0) == Some(view.time) {
            return;
        }
        let p = &view.grains;
        let v = D::vertical();
        let mut n = vec![0.0; self.bins];
        for i in 0..p.len() {
            if p.frozen[i] {
                continue;
            }
            let k = ((D::get(p.pos[i], v) - self.lo) / self.bin).floor();
            if k >= 0.0 && (k as usize) < self.bins {
                n[k as usize] += 1.0 / self.bin;
            }
        }
        self.rows.push((view.time, n));
    }

    /// The samples so far (a checkpoint's part), every number as its bits.
    pub fn save(&self, e: &mut Enc) {
        e.len(self.rows.len());
        for (t, n) in &self.rows {
            e.f64(*t);
            e.f64s(n);
        }
    }

    /// The samples [`Spacetime::save`] wrote, into one with the same bins.
    pub fn load(&mut self, d: &mut Dec) -> DecResult<()> {
        let n = d.len(16, "spacetime rows")?;
        let mut rows = Vec::with_capacity(n);
        for _ in 0..n {
            let t = d.f64("spacetime time")?;
            let row = d.f64s("spacetime row")?;
            if row.len() != self.bins {
                let bins = self.bins;
                return Err(format!("spacetime row of {} bins, not {bins}", row.len()));
            }
            rows.push((t, row));
        }
        self.rows = rows;
        Ok(())
    }

    /// Relative standard deviation of the density over bins and samples (a
    /// measure of how strong the density waves are).
    pub fn contrast(&self) -> f64 {
        let all: Vec<f64> = self.rows.iter().flat_map(|r| r.1.iter().copied()).collect();
        if all.is_empty() {
            return 0.0;
        }
        let m = all.iter().sum::<f64>() / all.len() as f64;
        let var = all.iter().map(|x| (x - m).powi(2)).sum::<f64>() / all.len() as f64;
        if m > 0.0 {
            var.sqrt() / m
        } else {
            0.0
        }
    }

    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut csv = String::from("time");
        for k in 0..self.bins {
            let _ = write!(csv, ",z{:.6e}", self.lo + (k as f64 + 0.5) * self.bin);
        }
        csv.push('\n');
        for (t, n) in &self.rows {
            let _ = write!(csv, "{t}");
            for x in n {
                let _ = write!(csv, ",{x}");
            }
            csv.push('\n');
        }
        write_atomic(&dir.join("spacetime.csv"), csv.as_bytes())?;
        if self.rows.is_empty() {
            return Ok(());
        }
        // At most 400 columns: average consecutive samples.
        let stride = self.rows.len().div_ceil(400);
        let cols: Vec<(f64, Vec<f64>)> = self
            .rows
            .chunks(stride)
            .map(|c| {
                let mut n = vec![0.0; self.bins];
                for (_, r) in c {
                    for (a, x) in n.iter_mut().zip(r) {
                        *a += x / c.len() as f64;
                    }
                }
                (c[0].0, n)
            })
            .collect();
        let max = cols
            .iter()
            .flat_map(|r| r.1.iter().copied())
            .fold(0.0, f64::max)
            .max(1e-300);
        let (px_t, px_z) = (
            (400 / cols.len()).max(1) as u32,
            (300 / self.bins).max(1) as u32,
        );
        let (w, h) = (cols.len() as u32 * px_t, self.bins as u32 * px_z);
        let view = View {
            origin: [0.0, 0.0],
            scale: 1.0,
            height: h,
        };
        let mut img = Image::new(w, h, view);
        for (c, (_, n)) in cols.iter().enumerate() {
            for (k, x) in n.iter().enumerate() {
                let g = (255.0 * (1.0 - x / max)).round() as u8;
                for dx in 0..px_t {
                    for dz in 0..px_z {
                        let (px, py) = (c as u32 * px_t + dx, h - 1 - (k as u32 * px_z + dz));
                        let at = (py as usize * w as usize + px as usize) * 3;
                        img.rgb[at..at + 3].copy_from_slice(&[g, g, g]);
                    }
                }
            }
        }
        img.save_png(&dir.join("spacetime.png"))
    }
}
