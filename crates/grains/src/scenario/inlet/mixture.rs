//! An inlet's mixture of materials: `materials = [{ name, fraction, kind
//! }, …]`, each grain's material drawn by number or by mass fraction.
//!
//! By number (the default) a grain is of material c with probability
//! fraction_c, whatever its size. By mass (`materials_weight = "mass"`)
//! the fractions w_c are shares of the inserted mass: every material's
//! grains follow the inlet's one size law, so a grain of c weighs ρ_c
//! times the same mean volume, and drawing c with probability
//! p_c = (w_c / ρ_c) / Σ_j (w_j / ρ_j) gives the mass fractions w_c in
//! expectation. Each material arrives as its own kind (grains of one kind
//! share one material), by default 1 + the material's place in
//! `[[materials]]`.

use super::super::materials;
use super::super::schema::{InletSpec, Scenario, SizeWeight};
use crate::error::{Error, Result};
use rand::Rng;
use serde_json::{json, Value};

/// How far the fractions' sum may stray from 1.
pub const SUM_TOLERANCE: f64 = 1e-9;

/// One material of the mixture: its kind, density, whether its kind is
/// frozen, and the running sum of the number fractions up to and
/// including it.
#[derive(Clone, Debug)]
pub struct Component {
    pub kind: u32,
    pub density: f64,
    pub frozen: bool,
    upto: f64,
    /// Its `[[materials]]` name and fraction as given (`grains check`).
    name: String,
    given: f64,
}

/// The materials an inlet brings (one for an inlet without a mixture).
#[derive(Clone, Debug)]
pub struct Mixture {
    parts: Vec<Component>,
    /// Whether the given fractions are by mass.
    by_mass: bool,
}

impl Mixture {
    /// An inlet of one kind.
    pub fn single(kind: u32, density: f64, frozen: bool) -> Self {
        Self {
            parts: vec![Component {
                kind,
                density,
                frozen,
                upto: 1.0,
                name: String::new(),
                given: 1.0,
            }],
            by_mass: false,
        }
    }

    /// The mixture of the inlet `key` names, `None` without
    /// `materials`; every fraction, name and kind checked.
    pub fn new(s: &Scenario, spec: &InletSpec, key: &str) -> Result<Option<Self>> {
        let Some(list) = &spec.materials else {
            if spec.materials_weight.is_some() {
                return Err(Error::input(format!(
                    "{key}.materials_weight is the weight of {key}.materials' fractions, but the \
                     inlet has no materials: give {key}.materials or drop the key"
                )));
            }
            return Ok(None);
        };
        if spec.kind.is_some() {
            return Err(Error::input(format!(
                "{key}.kind and {key}.materials exclude each other: a mixture gives each \
                 material its own kind ({key}.materials[].kind)"
            )));
        }
        let by_mass = spec.materials_weight == Some(SizeWeight::Mass);
        if list.is_empty() {
            return Err(Error::input(format!(
                "{key}.materials is empty: name at least one of the [[materials]] with its fraction"
            )));
        }
        // This inlet's entries of all the mixtures, names resolved.
        let all = materials::materials(s)?;
        let prefix = format!("{key}.materials[");
        let resolved: Vec<_> = (materials::mixture_kinds(s)?.into_iter())
            .filter(|(_, _, k)| k.starts_with(&prefix))
            .collect();
        let mut parts = Vec::with_capacity(list.len());
        let mut sum = 0.0;
        for (j, (m, (kind, index, entry))) in list.iter().zip(resolved).enumerate() {
            if !(m.fraction.is_finite() && m.fraction > 0.0 && m.fraction <= 1.0) {
                return Err(Error::input(format!(
                    "{entry}.fraction = {}: must be in (0, 1] (a fraction by {})",
                    m.fraction,
                    if by_mass { "mass" } else { "number" }
                )));
            }
            if let Some(twice) = list[..j].iter().position(|o| o.name == m.name) {
                return Err(Error::input(format!(
                    "{entry}.name = \"{}\" is {key}.materials[{twice}] again: give each material once",
                    m.name
                )));
            }
            if let Some(other) = parts.iter().position(|p: &Component| p.kind == kind) {
                return Err(Error::input(format!(
                    "{entry} (\"{}\") and {key}.materials[{other}] are both kind {kind}: grains of \
                     one kind share one material; give {entry}.kind another kind",
                    m.name
                )));
            }
            sum += m.fraction;
            parts.push(Component {
                kind,
                density: all[index].density,
                frozen: s.particles.frozen_types.contains(&kind),
                upto: sum,
                name: m.name.clone(),
                given: m.fraction,
            });
        }
        if (sum - 1.0).abs() > SUM_TOLERANCE {
            return Err(Error::input(format!(
                "{key}.materials: the fractions sum to {sum}; they must sum to 1 (within \
                 {SUM_TOLERANCE:e})"
            )));
        }
        if by_mass {
            // Number fractions w_c / ρ_c, normalised, as running sums.
            let total: f64 = parts.iter().map(|p| p.given / p.density).sum();
            let mut upto = 0.0;
            for p in &mut parts {
                upto += p.given / p.density / total;
                p.upto = upto;
            }
        }
        Ok(Some(Self { parts, by_mass }))
    }

    /// What `grains check` prints of a mixture: each material's name,
    /// kind, density, its fraction as given, and the fractions by number
    /// and by mass it is drawn with.
    pub fn report(&self) -> Value {
        let mut below = 0.0;
        let number: Vec<f64> = (self.parts.iter())
            .map(|p| {
                let n = p.upto - below;
                below = p.upto;
                n
            })
            .collect();
        let mass: f64 = self
            .parts
            .iter()
            .zip(&number)
            .map(|(p, n)| n * p.density)
            .sum();
        let parts: Vec<Value> = (self.parts.iter().zip(&number))
            .map(|(p, &n)| {
                json!({
                    "name": p.name,
                    "kind": p.kind,
                    "density": p.density,
                    "fraction": p.given,
                    "number_fraction": n,
                    "mass_fraction": n * p.density / mass,
                })
            })
            .collect();
        json!({ "weight": if self.by_mass { "mass" } else { "number" }, "materials": parts })
    }

    /// Which material grain gets: the first whose running sum exceeds a
    /// uniform draw from `rng` (its own stream; one material draws
    /// nothing).
    pub fn pick(&self, rng: &mut impl Rng) -> usize {
        if self.parts.len() == 1 {
            return 0;
        }
        let u = rng.gen::<f64>();
        (self.parts.iter().position(|p| u < p.upto)).unwrap_or(self.parts.len() - 1)
    }

    pub fn part(&self, c: usize) -> &Component {
        &self.parts[c]
    }

    /// The smallest density of the mixture (the lightest grain's).
    pub fn lightest(&self) -> f64 {
        (self.parts.iter()).fold(f64::INFINITY, |a, p| a.min(p.density))
    }
}

/// The kinds of the grains the inlets of `s` bring, one entry per inlet
/// (per material of a mixture).
pub fn kinds(s: &Scenario) -> Result<Vec<u32>> {
    let mixed = materials::mixture_kinds(s)?;
    let mut out = Vec::new();
    for (i, inlet) in s.inlets.iter().enumerate() {
        if inlet.materials.is_some() {
            let prefix = format!("inlets[{i}].materials[");
            out.extend(
                (mixed.iter())
                    .filter(|(_, _, k)| k.starts_with(&prefix))
                    .map(|x| x.0),
            );
        } else {
            out.push(inlet.kind.unwrap_or(1));
        }
    }
    Ok(out)
}
