//! What `grains check` prints of a size distribution: the number- and
//! mass-weighted mean diameter, d10, d50 and d90 of each, and max/min.
//! Continuous laws are integrated on a grid of [`GRID`] cells.

use super::SizeLaw;
use serde::Serialize;

/// Cells of the grid on which continuous laws are integrated.
pub const GRID: usize = 20_000;

/// The mean and the quantiles of one weighting (m).
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Stats {
    pub mean: f64,
    pub d10: f64,
    pub d50: f64,
    pub d90: f64,
}

/// A size distribution in numbers.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Summary {
    /// Weighted by number of grains.
    pub number: Stats,
    /// Weighted by mass (m ∝ d^k).
    pub mass: Stats,
    pub min: f64,
    pub max: f64,
    pub max_over_min: f64,
}

/// ∫ f over [a, b] by the midpoint rule on [`GRID`] cells.
pub(super) fn integral(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / GRID as f64;
    (0..GRID).map(|j| f(a + (j as f64 + 0.5) * h)).sum::<f64>() * h
}

/// Mean and quantiles of points `d` with weights `w`; `h` > 0 spreads
/// each point's weight over a cell of that width centred on it (a grid),
/// `h` = 0 keeps the points (classes).
fn stats(d: &[f64], w: &[f64], h: f64) -> Stats {
    let total: f64 = w.iter().sum();
    let mean = d.iter().zip(w).map(|(x, y)| x * y).sum::<f64>() / total;
    let quantile = |q: f64| -> f64 {
        let target = q * total;
        let mut acc = 0.0;
        for (j, (&x, &y)) in d.iter().zip(w).enumerate() {
            if acc + y >= target && y > 0.0 {
                return if h > 0.0 {
                    x - 0.5 * h + h * (target - acc) / y
                } else {
                    x
                };
            }
            acc += y;
            if j + 1 == d.len() {
                return x;
            }
        }
        d[d.len() - 1]
    };
    Stats {
        mean,
        d10: quantile(0.1),
        d50: quantile(0.5),
        d90: quantile(0.9),
    }
}

impl SizeLaw {
    /// The distribution's means and quantiles by number and by mass.
    pub fn summary(&self) -> Summary {
        let k = self.k;
        let (d, w, h): (Vec<f64>, Vec<f64>, f64) = match self.table() {
            Some((d, p)) => (d.to_vec(), p.to_vec(), 0.0),
            None if self.max > self.min => {
                let h = (self.max - self.min) / GRID as f64;
                let d: Vec<f64> = (0..GRID).map(|j| self.min + (j as f64 + 0.5) * h).collect();
                let w = d.iter().map(|&x| self.number_density(x)).collect();
                (d, w, h)
            }
            // One size (a band of width 0).
            None => (vec![self.min], vec![1.0], 0.0),
        };
        let mass: Vec<f64> = d.iter().zip(&w).map(|(x, y)| y * x.powi(k)).collect();
        Summary {
            number: stats(&d, &w, h),
            mass: stats(&d, &mass, h),
            min: self.min,
            max: self.max,
            max_over_min: self.max / self.min,
        }
    }
}

/// The `sizes` entry of `grains check`: the law of the grains placed at the
/// start, with how it was given; null for grains from a file or `add`.
pub fn report(loaded: &crate::scenario::Loaded) -> crate::error::Result<serde_json::Value> {
    let s = &loaded.scenario;
    let Some(law) = super::of_scenario(s, &loaded.base_dir)? else {
        return Ok(serde_json::Value::Null);
    };
    let given = match &s.particles.size {
        Some(spec) => serde_json::to_value(spec).unwrap_or_default(),
        None => serde_json::json!({ "band": { "d0": s.particles.d0, "width": s.particles.width } }),
    };
    Ok(serde_json::json!({
        "given": given,
        "weight": if law.by_mass() { "mass" } else { "number" },
        "mass_exponent": law.exponent(),
        "summary": law.summary(),
    }))
}
