//! The Johnson–Kendall–Roberts adhesive contact (Johnson, Kendall &
//! Roberts 1971, Proc. R. Soc. Lond. A 324, 301; Johnson 1985, §5.5), with
//! its hysteresis.
//!
//! With Γ the work of adhesion per unit area (the pair's `surface_energy`),
//! E* and R* the pair's effective modulus and radius, the contact radius a
//! and the overlap δ are tied by
//!
//!   δ = a²/R* − √(2π Γ a / E*),
//!
//! and the normal force (positive pushing apart) is
//!
//!   F = 4 E* a³ / (3 R*) − √(8π Γ E* a³).
//!
//! At zero load a₀³ = 9π Γ R*² / (2 E*) and δ₀ = a₀² / (3 R*). Under a
//! prescribed load the grains come apart at the minimum of F(a),
//! F = −(3/2) π Γ R* (the pull-off force); under a prescribed separation the
//! contact lasts to the minimum of δ(a), at a_f³ = π Γ R*² / (8 E*), the
//! separation δ_c = (3/4) (π² Γ² R* / E*²)^{1/3} beyond touching. A contact
//! forms when the surfaces touch (δ = 0) and is kept while δ > −δ_c: the
//! hysteresis that makes adhesive impacts lose energy.
//!
//! Given δ, a is the largest root of the quartic s⁴ − c R* s − δ R* = 0 in
//! s = √a (c = √(2π Γ / E*)), solved here in closed form (Ferrari's
//! method: the resolvent cubic m³ + δ R* m − c² R*² / 8 = 0 has one positive
//! root on the contact's branch, taken in a form without cancellation).
//! No iteration: the batched lanes and the one-by-one loop run the same
//! arithmetic.

use crate::dim::Dim;
use std::f64::consts::PI;

/// What the loops keep in a contact's rolling slot while it is formed (a
/// JKR law keeps no rolling spring there): any non-zero vector, whose sign
/// a carry over a rebuild may flip.
#[inline(always)]
pub fn mark<D: Dim>() -> D::V {
    D::from_xyz([1.0, 0.0, 0.0])
}

/// The contact radius at overlap `overlap` (negative beyond touching,
/// down to −δ_c), on the stable branch; Hertz's √(R* δ) when Γ = 0.
#[inline(always)]
pub fn contact_radius(overlap: f64, r_star: f64, e_star: f64, gamma: f64) -> f64 {
    let c2 = 2.0 * PI * gamma / e_star;
    let c = c2.sqrt();
    // Resolvent cubic m³ + p m + q = 0, p = δ R*, q = −c² R*² / 8.
    let p = overlap * r_star;
    let half_q = c2 * r_star * r_star / 16.0;
    // Cardano: m = u + v, u³ = −q/2 + √Δ, u v = −p/3; Δ ≥ 0 on the branch
    // (zero at −δ_c, where rounding could take it below).
    let disc = (half_q * half_q + (p / 3.0).powi(3)).max(0.0);
    let u = (half_q + disc.sqrt()).cbrt();
    let v = -p / (3.0 * u);
    // m = (u³ + v³) / (u² − u v + v²): no cancellation whatever the sign of p.
    let m = 2.0 * half_q / (u * u - u * v + v * v);
    let w = (2.0 * m).sqrt();
    let s = 0.5 * (w + (2.0 * c * r_star / w - 2.0 * m).max(0.0).sqrt());
    let hertz = (r_star * overlap).sqrt();
    if gamma > 0.0 {
        s * s
    } else {
        hertz
    }
}

/// The overlap at contact radius `a`: a²/R* − √(2π Γ a / E*).
pub fn overlap_at(a: f64, r_star: f64, e_star: f64, gamma: f64) -> f64 {
    a * a / r_star - (2.0 * PI * gamma * a / e_star).sqrt()
}

/// The elastic-adhesive normal force at contact radius `a`:
/// 4 E* a³ / (3 R*) − √(8π Γ E* a³).
#[inline(always)]
pub fn force(a: f64, r_star: f64, e_star: f64, gamma: f64) -> f64 {
    let a3 = a * a * a;
    4.0 * e_star * a3 / (3.0 * r_star) - (8.0 * PI * gamma * e_star * a3).sqrt()
}

/// The pull-off force (3/2) π Γ R* (under a prescribed load).
#[inline(always)]
pub fn pull_off(gamma: f64, r_star: f64) -> f64 {
    1.5 * PI * gamma * r_star
}

/// (3/4) (π² Γ² / E*²)^{1/3}: the separation δ_c at which a contact breaks
/// is this times R*^{1/3}.
pub fn separation_coefficient(e_star: f64, gamma: f64) -> f64 {
    0.75 * (PI * PI * gamma * gamma / (e_star * e_star)).cbrt()
}

/// The separation beyond touching at which a contact breaks, δ_c.
pub fn separation(r_star: f64, e_star: f64, gamma: f64) -> f64 {
    separation_coefficient(e_star, gamma) * r_star.cbrt()
}

/// The overlap at rest without load, δ₀ = a₀² / (3 R*),
/// a₀³ = 9π Γ R*² / (2 E*).
pub fn equilibrium_overlap(r_star: f64, e_star: f64, gamma: f64) -> f64 {
    let a0 = (9.0 * PI * gamma * r_star * r_star / (2.0 * e_star)).cbrt();
    a0 * a0 / (3.0 * r_star)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form contact radius inverts δ(a) along the whole branch,
    /// from deep in compression to the breaking point a_f.
    #[test]
    fn contact_radius_inverts_the_overlap() {
        for (r, e, g) in [(0.01, 1e7, 0.05), (0.005, 5e9, 0.5), (1.0, 1e6, 3.0)] {
            let a_f = (PI * g * r * r / (8.0 * e)).cbrt();
            for k in 0..200 {
                // a from a_f to 50 a_f, denser near a_f.
                let a = a_f * (1.0 + 49.0 * (k as f64 / 199.0).powi(3));
                let d = overlap_at(a, r, e, g);
                let got = contact_radius(d, r, e, g);
                // Near a_f δ(a) is flat: a is known to √ε there.
                let tol = if k < 3 { 1e-6 } else { 1e-9 };
                assert!(
                    (got / a - 1.0).abs() < tol,
                    "{r} {e} {g} k {k}: {got:e} for {a:e}"
                );
            }
            // δ(a_f) is the breaking separation.
            let d_c = -overlap_at(a_f, r, e, g);
            assert!((d_c / separation(r, e, g) - 1.0).abs() < 1e-12);
        }
        // Without surface energy: Hertz.
        assert_eq!(contact_radius(1e-4, 0.01, 1e7, 0.0), (1e-6f64).sqrt());
    }

    /// The force's closed forms: zero at δ₀, its minimum −(3/2) π Γ R*,
    /// −(5/6) π Γ R* at the breaking point.
    #[test]
    fn force_closed_forms() {
        let (r, e, g) = (0.01, 1e7, 0.05);
        let a0 = contact_radius(equilibrium_overlap(r, e, g), r, e, g);
        assert!(force(a0, r, e, g).abs() < 1e-9 * pull_off(g, r));
        let a_f = (PI * g * r * r / (8.0 * e)).cbrt();
        let f_break = force(a_f, r, e, g);
        assert!((f_break / (-5.0 / 6.0 * PI * g * r) - 1.0).abs() < 1e-12);
        let min = (0..10_000)
            .map(|k| force(a_f + (a0 - a_f) * k as f64 / 9999.0, r, e, g))
            .fold(f64::INFINITY, f64::min);
        assert!((min / -pull_off(g, r) - 1.0).abs() < 1e-6, "{min}");
    }
}
