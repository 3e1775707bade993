//! An inlet's mixture of materials: `materials = [{ name, fraction, kind
//! }, …]`, each grain's material drawn by number fraction.
//!
//! Fractions are by number: a grain is of material c with probability
//! fraction_c, whatever its size. Each material arrives as its own kind
//! (grains of one kind share one material), by default 1 + the material's
//! place in `[[materials]]`.

use super::super::materials;
use super::super::schema::{InletSpec, Scenario};
use crate::error::{Error, Result};
use rand::Rng;

/// How far the fractions' sum may stray from 1.
pub const SUM_TOLERANCE: f64 = 1e-9;

/// One material of the mixture: its kind, density, whether its kind is
/// frozen, and the running sum of the fractions up to and including it.
#[derive(Clone, Debug)]
pub struct Component {
    pub kind: u32,
    pub density: f64,
    pub frozen: bool,
    upto: f64,
}

/// The materials an inlet brings (one for an inlet without a mixture).
#[derive(Clone, Debug)]
pub struct Mixture {
    parts: Vec<Component>,
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
            }],
        }
    }

    /// The mixture of the inlet `key` names, `None` without
    /// `materials`; every fraction, name and kind checked.
    pub fn new(s: &Scenario, spec: &InletSpec, key: &str) -> Result<Option<Self>> {
        let Some(list) = &spec.materials else {
            return Ok(None);
        };
        if spec.kind.is_some() {
            return Err(Error::input(format!(
                "{key}.kind and {key}.materials exclude each other: a mixture gives each \
                 material its own kind ({key}.materials[].kind)"
            )));
        }
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
                    "{entry}.fraction = {}: must be in (0, 1] (a fraction by number)",
                    m.fraction
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
            });
        }
        if (sum - 1.0).abs() > SUM_TOLERANCE {
            return Err(Error::input(format!(
                "{key}.materials: the fractions sum to {sum}; they must sum to 1 (within \
                 {SUM_TOLERANCE:e})"
            )));
        }
        Ok(Some(Self { parts }))
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
