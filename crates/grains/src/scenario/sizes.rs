//! Size distributions of the grains made at the start: uniform, normal,
//! lognormal, a discrete table or a laboratory's sieve curve, by number or
//! by mass, cut to [min, max], drawn from the scenario's diameter stream.
//!
//! A law by mass gives the share of the grains' mass in each size; its
//! number law is the mass law times d^−k, normalised, with k the exponent
//! of the mass model (3 for spheres, also 2D grains with the sphere mass
//! model; 2 for disks). Every law is drawn by number, exactly:
//!
//! - lognormal by mass: lognormal by number with μ − kσ² and the same σ
//!   (the mass density times d^−k is again lognormal);
//! - uniform by mass and sieve curves: piecewise, each interval's number
//!   weight and the inverse CDF of d^−k inside it in closed form;
//! - normal by mass: a draw of the mass law accepted with probability
//!   (min/d)^k (rejection sampling under the bound min^−k);
//! - discrete: class fractions by number p_i d_i^−k / Σ_j p_j d_j^−k.
//!
//! Truncation: a draw of a continuous law outside [min, max] is thrown away
//! and drawn again, which gives the law restricted to [min, max] and
//! renormalised; a table is cut at min and max (a sieve curve interpolated
//! there) and renormalised.

mod sieve;
mod summary;

pub use summary::{report, Stats, Summary};

use super::placement::{stream, STREAM_DIAMETERS};
use super::schema::{Placement, Scenario, SizeDistribution, SizeSpec, SizeWeight};
use crate::error::{Error, Result};
use crate::particles::MassModel;
use rand::Rng;
use std::path::Path;

/// Largest ratio of the largest to the smallest diameter. The neighbour
/// search bins grains in cells as wide as the largest grain, so at a ratio
/// r each cell holds about r³ of the smallest grains (3D): beyond 20 a
/// grain's candidate pairs run into the thousands.
pub const MAX_RATIO: f64 = 20.0;

/// Least share of a continuous law that its bounds may keep: below it the
/// bounds, not the law, shape the grains (and redrawing would crawl).
const MIN_KEPT: f64 = 1e-3;

/// Draws tried for one grain before giving up; with [`MIN_KEPT`] and
/// [`MAX_RATIO`] a grain needs about 10⁷ tries at the very worst.
const MAX_TRIES: u64 = 1_000_000_000;

/// How the law is drawn (all in diameters, metres).
#[derive(Clone, Debug)]
enum Shape {
    /// Uniform by number: d = min + u (max − min), the band's formula.
    Uniform,
    /// Intervals `edges[i]..edges[i + 1]` with a constant density
    /// `density[i]` of the given weight inside; by mass (`power`) the
    /// number density is that times d^−k. `cum` is the cumulative number
    /// share at each interval's upper edge.
    Piecewise {
        edges: Vec<f64>,
        density: Vec<f64>,
        cum: Vec<f64>,
        power: bool,
    },
    /// A normal law of the given weight (mean, std of the untruncated law).
    Normal { mean: f64, std: f64, by_mass: bool },
    /// The number law: ln d normal with mean `mu`, deviation `sigma`.
    LogNormal { mu: f64, sigma: f64 },
    /// Classes with their number shares and the cumulative shares.
    Classes {
        d: Vec<f64>,
        p: Vec<f64>,
        cum: Vec<f64>,
    },
}

/// A checked size distribution, ready to draw diameters from.
#[derive(Clone, Debug)]
pub struct SizeLaw {
    shape: Shape,
    min: f64,
    max: f64,
    /// Mass ∝ d^k.
    k: i32,
    by_mass: bool,
}

/// The exponent of the diameter in a grain's mass.
pub fn mass_exponent(model: MassModel) -> i32 {
    match model {
        MassModel::Sphere => 3,
        MassModel::Disk => 2,
    }
}

const KEY: &str = "particles.size";

fn positive(name: &str, v: Option<f64>, law: &str) -> Result<f64> {
    match v {
        Some(x) if x.is_finite() && x > 0.0 => Ok(x),
        Some(x) => Err(Error::input(format!(
            "{KEY}.{name} = {x}: must be a positive length in metres"
        ))),
        None => Err(Error::input(format!(
            "{KEY}.{name} is required for distribution = \"{law}\""
        ))),
    }
}

/// Refuses the keys a law does not read, by name.
fn unused(spec: &SizeSpec, law: &str, allowed: &[&str]) -> Result<()> {
    let given = [
        ("mean", spec.mean.is_some()),
        ("std", spec.std.is_some()),
        ("classes", spec.classes.is_some()),
        ("file", spec.file.is_some()),
    ];
    for (name, present) in given {
        if present && !allowed.contains(&name) {
            return Err(Error::input(format!(
                "{KEY}.{name} does not apply to distribution = \"{law}\" (it takes {})",
                allowed
                    .iter()
                    .chain(["min", "max", "weight"].iter())
                    .copied()
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
    }
    Ok(())
}

/// Optional bounds of a table: positive, min ≤ max when both are given
/// (equal bounds keep one class).
fn bounds(spec: &SizeSpec) -> Result<(f64, f64)> {
    let lo = match spec.min {
        Some(_) => positive("min", spec.min, "")?,
        None => 0.0,
    };
    let hi = match spec.max {
        Some(_) => positive("max", spec.max, "")?,
        None => f64::INFINITY,
    };
    if lo > hi {
        return Err(Error::input(format!(
            "{KEY}: min = {lo} must not exceed max = {hi}"
        )));
    }
    Ok((lo, hi))
}

impl SizeLaw {
    /// The law of `particles.size`; a sieve file is read relative to `base`.
    pub fn new(spec: &SizeSpec, model: MassModel, base: &Path) -> Result<Self> {
        let k = mass_exponent(model);
        let weight = spec.weight.unwrap_or(match spec.distribution {
            SizeDistribution::Sieve => SizeWeight::Mass,
            _ => SizeWeight::Number,
        });
        let by_mass = weight == SizeWeight::Mass;
        let law = match spec.distribution {
            SizeDistribution::Uniform => {
                unused(spec, "uniform", &[])?;
                let (min, max) = continuous_bounds(spec, "uniform")?;
                let shape = if by_mass {
                    Shape::piecewise(vec![min, max], vec![1.0], true, k)
                } else {
                    Shape::Uniform
                };
                Self::with(shape, min, max, k, by_mass)
            }
            SizeDistribution::Normal => {
                unused(spec, "normal", &["mean", "std"])?;
                let (min, max) = continuous_bounds(spec, "normal")?;
                let mean = positive("mean", spec.mean, "normal")?;
                let std = positive("std", spec.std, "normal")?;
                let law = Self::with(Shape::Normal { mean, std, by_mass }, min, max, k, by_mass);
                // The share of the weight law inside the bounds.
                let kept =
                    summary::integral(min, max, |d| (-0.5 * ((d - mean) / std).powi(2)).exp())
                        / (std * (2.0 * std::f64::consts::PI).sqrt());
                kept_enough(kept, "normal")?;
                law
            }
            SizeDistribution::Lognormal => {
                unused(spec, "lognormal", &["mean", "std"])?;
                let (min, max) = continuous_bounds(spec, "lognormal")?;
                let mean = positive("mean", spec.mean, "lognormal")?;
                let std = positive("std", spec.std, "lognormal")?;
                // Mean m and deviation s of d give the law of ln d.
                let sigma2 = (1.0 + (std / mean).powi(2)).ln();
                let sigma = sigma2.sqrt();
                let mu_weight = mean.ln() - 0.5 * sigma2;
                let mu = if by_mass {
                    mu_weight - k as f64 * sigma2
                } else {
                    mu_weight
                };
                let kept = summary::integral(min, max, |d| {
                    (-0.5 * ((d.ln() - mu_weight) / sigma).powi(2)).exp() / d
                }) / (sigma * (2.0 * std::f64::consts::PI).sqrt());
                kept_enough(kept, "lognormal")?;
                Self::with(Shape::LogNormal { mu, sigma }, min, max, k, by_mass)
            }
            SizeDistribution::Discrete => {
                unused(spec, "discrete", &["classes"])?;
                Self::classes(spec, k, by_mass)?
            }
            SizeDistribution::Sieve => {
                unused(spec, "sieve", &["file"])?;
                let Some(name) = &spec.file else {
                    return Err(Error::input(format!(
                        "{KEY}.file is required for distribution = \"sieve\" (a CSV of \
                         diameter in m, cumulative % passing)"
                    )));
                };
                let path = if Path::new(name).is_absolute() {
                    Path::new(name).to_path_buf()
                } else {
                    base.join(name)
                };
                let (edges, share) = sieve::read(&path, name, bounds(spec)?)?;
                let (min, max) = (edges[0], edges[edges.len() - 1]);
                let density = share
                    .iter()
                    .zip(edges.windows(2))
                    .map(|(s, e)| s / (e[1] - e[0]))
                    .collect();
                Self::with(
                    Shape::piecewise_density(edges, density, by_mass, k),
                    min,
                    max,
                    k,
                    by_mass,
                )
            }
        };
        law.check_ratio()?;
        Ok(law)
    }

    /// The uniform band of `particles.d0` and `particles.width`.
    pub fn band(d0: f64, width: f64) -> Self {
        let band = crate::particles::SizeBand { d0, width };
        Self::with(Shape::Uniform, band.min(), band.max(), 3, false)
    }

    fn with(shape: Shape, min: f64, max: f64, k: i32, by_mass: bool) -> Self {
        Self {
            shape,
            min,
            max,
            k,
            by_mass,
        }
    }

    fn classes(spec: &SizeSpec, k: i32, by_mass: bool) -> Result<Self> {
        let Some(rows) = &spec.classes else {
            return Err(Error::input(format!(
                "{KEY}.classes is required for distribution = \"discrete\": rows of \
                 [diameter in m, fraction]"
            )));
        };
        let (lo, hi) = bounds(spec)?;
        let mut table = Vec::with_capacity(rows.len());
        for (i, row) in rows.iter().enumerate() {
            let &[d, f] = row.as_slice() else {
                return Err(Error::input(format!(
                    "{KEY}.classes[{i}] has {} numbers: give [diameter in m, fraction]",
                    row.len()
                )));
            };
            if !(d.is_finite() && d > 0.0) {
                return Err(Error::input(format!(
                    "{KEY}.classes[{i}]: diameter {d} must be a positive length in metres"
                )));
            }
            if !(f.is_finite() && f >= 0.0) {
                return Err(Error::input(format!(
                    "{KEY}.classes[{i}]: fraction {f} must be 0 or more"
                )));
            }
            table.push((d, f));
        }
        let total: f64 = table.iter().map(|c| c.1).sum();
        if table.is_empty() || (total - 1.0).abs() > 1e-6 {
            return Err(Error::input(format!(
                "{KEY}.classes: the fractions sum to {total}, not 1 (within 1e-6)"
            )));
        }
        table.sort_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(w) = table.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(Error::input(format!(
                "{KEY}.classes: diameter {} appears twice",
                w[0].0
            )));
        }
        table.retain(|&(d, f)| f > 0.0 && d >= lo && d <= hi);
        if table.is_empty() {
            return Err(Error::input(format!(
                "{KEY}: no class with a fraction above 0 lies within min and max"
            )));
        }
        // By mass, the number of grains in a class is its mass over d^k.
        let weights: Vec<f64> = table
            .iter()
            .map(|&(d, f)| if by_mass { f / d.powi(k) } else { f })
            .collect();
        let sum: f64 = weights.iter().sum();
        let p: Vec<f64> = weights.iter().map(|w| w / sum).collect();
        let cum = cumulative(&p);
        let d: Vec<f64> = table.iter().map(|c| c.0).collect();
        let (min, max) = (d[0], d[d.len() - 1]);
        Ok(Self::with(
            Shape::Classes { d, p, cum },
            min,
            max,
            k,
            by_mass,
        ))
    }

    fn check_ratio(&self) -> Result<()> {
        let ratio = self.max / self.min;
        if ratio > MAX_RATIO {
            return Err(Error::input(format!(
                "{KEY}: the largest diameter {:e} m is {ratio:.1} times the smallest {:e} m; at \
                 most {MAX_RATIO}: the neighbour search bins grains in cells as wide as the \
                 largest, each of which would hold thousands of the smallest",
                self.max, self.min
            )));
        }
        Ok(())
    }

    /// Smallest and largest diameter a draw can give (m).
    pub fn min(&self) -> f64 {
        self.min
    }
    pub fn max(&self) -> f64 {
        self.max
    }

    /// Whether the law was given by mass.
    pub fn by_mass(&self) -> bool {
        self.by_mass
    }

    /// The exponent k of the diameter in a grain's mass (m ∝ d^k).
    pub fn exponent(&self) -> i32 {
        self.k
    }

    /// `count` diameters from the stream of (seed, diameters): the same on
    /// any number of threads, as they are drawn one after another.
    pub fn draw(&self, count: usize, seed: u64) -> Result<Vec<f64>> {
        let mut rng = stream(seed, STREAM_DIAMETERS);
        (0..count).map(|_| self.one(&mut rng)).collect()
    }

    /// One diameter from `rng` (an inlet's stream of one grain).
    pub fn draw_with(&self, rng: &mut impl Rng) -> Result<f64> {
        self.one(rng)
    }

    fn one(&self, rng: &mut impl Rng) -> Result<f64> {
        let (min, max) = (self.min, self.max);
        match &self.shape {
            Shape::Uniform => Ok(min + rng.gen::<f64>() * (max - min)),
            Shape::Classes { d, cum, .. } => {
                let u = rng.gen::<f64>();
                Ok(d[cum.partition_point(|&c| c <= u).min(d.len() - 1)])
            }
            Shape::Piecewise {
                edges, cum, power, ..
            } => {
                let u = rng.gen::<f64>();
                let i = cum.partition_point(|&c| c <= u).min(cum.len() - 1);
                let (a, b) = (edges[i], edges[i + 1]);
                let v = rng.gen::<f64>();
                let d = if *power {
                    inverse_power(a, b, self.k, v)
                } else {
                    a + v * (b - a)
                };
                Ok(d.clamp(a, b))
            }
            Shape::Normal { mean, std, by_mass } => self.redraw(rng, |rng| {
                let d = mean + std * gauss(rng);
                let kept = d >= min && d <= max;
                // Rejection: a mass-law draw kept with probability (min/d)^k.
                let accepted = !*by_mass || (kept && rng.gen::<f64>() < (min / d).powi(self.k));
                (kept && accepted).then_some(d)
            }),
            Shape::LogNormal { mu, sigma } => self.redraw(rng, |rng| {
                let d = (mu + sigma * gauss(rng)).exp();
                (d >= min && d <= max).then_some(d)
            }),
        }
    }

    /// Draws until `try_one` keeps one.
    fn redraw<R: Rng>(
        &self,
        rng: &mut R,
        mut try_one: impl FnMut(&mut R) -> Option<f64>,
    ) -> Result<f64> {
        for _ in 0..MAX_TRIES {
            if let Some(d) = try_one(rng) {
                return Ok(d);
            }
        }
        Err(Error::input(format!(
            "{KEY}: no diameter within [{:e}, {:e}] m after {MAX_TRIES} draws; widen min and max",
            self.min, self.max
        )))
    }

    /// The number density at d, up to a constant factor.
    fn number_density(&self, d: f64) -> f64 {
        let k = self.k;
        match &self.shape {
            Shape::Uniform => 1.0,
            Shape::Piecewise {
                edges,
                density,
                power,
                ..
            } => {
                let i = edges[1..]
                    .partition_point(|&e| e < d)
                    .min(density.len() - 1);
                density[i] * if *power { d.powi(-k) } else { 1.0 }
            }
            Shape::Normal { mean, std, by_mass } => {
                let w = (-0.5 * ((d - mean) / std).powi(2)).exp();
                if *by_mass {
                    w * d.powi(-k)
                } else {
                    w
                }
            }
            Shape::LogNormal { mu, sigma } => (-0.5 * ((d.ln() - mu) / sigma).powi(2)).exp() / d,
            Shape::Classes { .. } => 0.0,
        }
    }

    /// The classes and their number shares, for a discrete law.
    fn table(&self) -> Option<(&[f64], &[f64])> {
        match &self.shape {
            Shape::Classes { d, p, .. } => Some((d, p)),
            _ => None,
        }
    }
}

impl Shape {
    /// Intervals with shares `share` of the given weight.
    fn piecewise(edges: Vec<f64>, share: Vec<f64>, power: bool, k: i32) -> Self {
        let density = share
            .iter()
            .zip(edges.windows(2))
            .map(|(s, e)| s / (e[1] - e[0]))
            .collect();
        Self::piecewise_density(edges, density, power, k)
    }

    fn piecewise_density(edges: Vec<f64>, density: Vec<f64>, power: bool, k: i32) -> Self {
        // Number weight of an interval: its density times ∫ d^−k (by mass)
        // or its width (by number).
        let weights: Vec<f64> = density
            .iter()
            .zip(edges.windows(2))
            .map(|(rho, e)| {
                let (a, b) = (e[0], e[1]);
                rho * if power {
                    (a.powi(1 - k) - b.powi(1 - k)) / (k - 1) as f64
                } else {
                    b - a
                }
            })
            .collect();
        let sum: f64 = weights.iter().sum();
        let cum = cumulative(&weights.iter().map(|w| w / sum).collect::<Vec<_>>());
        Shape::Piecewise {
            edges,
            density,
            cum,
            power,
        }
    }
}

/// Running sums of shares that add up to 1, the last set to exactly 1.
fn cumulative(p: &[f64]) -> Vec<f64> {
    let mut acc = 0.0;
    let mut cum: Vec<f64> = p
        .iter()
        .map(|x| {
            acc += x;
            acc
        })
        .collect();
    if let Some(last) = cum.last_mut() {
        *last = 1.0;
    }
    cum
}

/// The diameter at which the CDF of d^−k on [a, b] reaches v.
fn inverse_power(a: f64, b: f64, k: i32, v: f64) -> f64 {
    let e = 1 - k;
    let (fa, fb) = (a.powi(e), b.powi(e));
    (fa - v * (fa - fb)).powf(1.0 / e as f64)
}

/// A standard normal deviate (Box–Muller, the cosine branch; one pair of
/// uniforms per deviate, so each draw uses a fixed count of numbers).
fn gauss(rng: &mut impl Rng) -> f64 {
    let u1 = rng.gen::<f64>();
    let u2 = rng.gen::<f64>();
    (-2.0 * (1.0 - u1).ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn continuous_bounds(spec: &SizeSpec, law: &str) -> Result<(f64, f64)> {
    let min = positive("min", spec.min, law)?;
    let max = positive("max", spec.max, law)?;
    if min >= max {
        return Err(Error::input(format!(
            "{KEY}: min = {min} must be below max = {max}"
        )));
    }
    Ok((min, max))
}

fn kept_enough(kept: f64, law: &str) -> Result<()> {
    if kept < MIN_KEPT {
        return Err(Error::input(format!(
            "{KEY}: min and max keep {:.2e} of the {law} law (at least {MIN_KEPT}): move them \
             towards the mean",
            kept
        )));
    }
    Ok(())
}

/// The law of a scenario's lattice, random or packed grains: `particles.size`, or
/// the band of d0 and width; `None` for grains from a file or `add` only.
pub fn of_scenario(s: &Scenario, base: &Path) -> Result<Option<SizeLaw>> {
    let ps = &s.particles;
    if !matches!(
        ps.placement,
        Placement::Lattice | Placement::Random | Placement::Packed
    ) {
        return Ok(None);
    }
    Ok(Some(match &ps.size {
        Some(spec) => SizeLaw::new(spec, ps.mass_model, base)?,
        None => SizeLaw::band(ps.d0, ps.width),
    }))
}

/// Completes `particles.size` once the scenario is read: refuses the
/// band's width beside it, fills in its bounds (a table's ends) and, unless
/// `d0_given`, sets d0 to its number-mean diameter (the length unit of
/// `run.skin` and the flow settings).
pub fn complete(s: &mut Scenario, d0_given: bool, base: &Path) -> Result<()> {
    let ps = &mut s.particles;
    let Some(spec) = &ps.size else {
        return Ok(());
    };
    if ps.width != 0.0 {
        return Err(Error::input(
            "particles.width is the uniform band's; with particles.size give its min and max instead",
        ));
    }
    let law = SizeLaw::new(spec, ps.mass_model, base)?;
    if !d0_given {
        ps.d0 = law.summary().number.mean;
    }
    let spec = ps.size.as_mut().expect("checked above");
    spec.min.get_or_insert(law.min);
    spec.max.get_or_insert(law.max);
    Ok(())
}
