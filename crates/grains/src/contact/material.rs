//! Materials and what a pair of them gives a contact: the effective moduli
//! E* and G*, and the pair's restitution and friction.
//!
//! Mixing rules (Johnson 1985 for the moduli):
//! - 1/E* = (1 − ν_i²)/E_i + (1 − ν_j²)/E_j;
//! - 1/G* = (2 − ν_i)/G_i + (2 − ν_j)/G_j with G = E / (2 (1 + ν));
//! - restitution, friction, rolling friction: the smaller of the two
//!   (the weaker surface decides), unless a material pair overrides it;
//! - surface energy: the geometric mean √(Γ_i Γ_j).
//!
//! A wall is infinitely heavy and flat (R → ∞, so R* = R_i, m* = m_i); its
//! material enters E* and G* like a grain's.

/// One material, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// kg/m³.
    pub density: f64,
    /// Pa.
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub restitution: f64,
    /// Sliding friction μ.
    pub friction: f64,
    /// Rolling friction μ_r (dimensionless).
    pub rolling_friction: f64,
    /// J/m².
    pub surface_energy: f64,
}

impl Material {
    /// Shear modulus G = E / (2 (1 + ν)).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// A material of the tests without rolling friction or cohesion.
    #[cfg(test)]
    pub(crate) fn elastic(name: &str, e: f64, nu: f64, rho: f64, rest: f64, mu: f64) -> Self {
        Self {
            name: name.into(),
            density: rho,
            youngs_modulus: e,
            poisson_ratio: nu,
            restitution: rest,
            friction: mu,
            rolling_friction: 0.0,
            surface_energy: 0.0,
        }
    }
}

/// What a pair may override of the mixed values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairOverride {
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub rolling_friction: Option<f64>,
    pub surface_energy: Option<f64>,
}

/// The coefficients of one pair of materials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairCoefficients {
    /// Effective Young's modulus E*.
    pub e_star: f64,
    /// Effective shear modulus G*.
    pub g_star: f64,
    pub restitution: f64,
    pub friction: f64,
    pub rolling_friction: f64,
    pub surface_energy: f64,
}

impl PairCoefficients {
    /// The mixed coefficients of materials `a` and `b`, then `over`.
    pub fn mix(a: &Material, b: &Material, over: &PairOverride) -> Self {
        let e_star = 1.0
            / ((1.0 - a.poisson_ratio.powi(2)) / a.youngs_modulus
                + (1.0 - b.poisson_ratio.powi(2)) / b.youngs_modulus);
        let g_star = 1.0
            / ((2.0 - a.poisson_ratio) / a.shear_modulus()
                + (2.0 - b.poisson_ratio) / b.shear_modulus());
        Self {
            e_star,
            g_star,
            restitution: over.restitution.unwrap_or(a.restitution.min(b.restitution)),
            friction: over.friction.unwrap_or(a.friction.min(b.friction)),
            rolling_friction: over
                .rolling_friction
                .unwrap_or(a.rolling_friction.min(b.rolling_friction)),
            surface_energy: over
                .surface_energy
                .unwrap_or((a.surface_energy * b.surface_energy).sqrt()),
        }
    }
}

/// R* = R_i R_j / (R_i + R_j); R_i against a wall (R_j infinite, flat).
#[inline(always)]
pub fn r_star(ri: f64, rj: f64) -> f64 {
    if rj.is_infinite() {
        ri
    } else {
        ri * rj / (ri + rj)
    }
}

/// The table of every ordered pair of `materials` (entry `a * n + b`),
/// each made by `make` from the two materials and the pair's override
/// (`overrides` names a pair in either order; none: the mixing rules).
pub fn pair_table<T>(
    materials: &[Material],
    overrides: &[((usize, usize), PairOverride)],
    make: impl Fn(&Material, &Material, &PairOverride) -> T,
) -> Vec<T> {
    let mut pairs = Vec::with_capacity(materials.len() * materials.len());
    for (a, ma) in materials.iter().enumerate() {
        for (b, mb) in materials.iter().enumerate() {
            let over = overrides
                .iter()
                .find(|((x, y), _)| (*x, *y) == (a, b) || (*x, *y) == (b, a))
                .map(|(_, o)| o.clone())
                .unwrap_or_default();
            pairs.push(make(ma, mb, &over));
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn glass() -> Material {
        Material {
            name: "glass".into(),
            density: 2500.0,
            youngs_modulus: 63e9,
            poisson_ratio: 0.23,
            restitution: 0.9,
            friction: 0.3,
            rolling_friction: 0.01,
            surface_energy: 0.0,
        }
    }

    #[test]
    fn like_materials_mix_to_the_textbook_moduli() {
        let g = glass();
        let p = PairCoefficients::mix(&g, &g, &PairOverride::default());
        // E* = E / (2 (1 − ν²)); G* = G / (2 (2 − ν)).
        let e = 63e9 / (2.0 * (1.0 - 0.23f64.powi(2)));
        let gs = 63e9 / (2.0 * 1.23) / (2.0 * 1.77);
        assert!((p.e_star / e - 1.0).abs() < 1e-14);
        assert!((p.g_star / gs - 1.0).abs() < 1e-14);
        assert_eq!((p.restitution, p.friction), (0.9, 0.3));
    }

    #[test]
    fn unlike_materials_take_the_weaker_surface_unless_overridden() {
        let g = glass();
        let mut s = glass();
        s.friction = 0.6;
        s.restitution = 0.5;
        s.surface_energy = 0.04;
        let mut gg = g.clone();
        gg.surface_energy = 0.01;
        let p = PairCoefficients::mix(&gg, &s, &PairOverride::default());
        assert_eq!((p.restitution, p.friction), (0.5, 0.3));
        assert!((p.surface_energy - 0.02).abs() < 1e-15);
        let over = PairOverride {
            friction: Some(0.45),
            ..Default::default()
        };
        assert_eq!(PairCoefficients::mix(&g, &s, &over).friction, 0.45);
    }
}
