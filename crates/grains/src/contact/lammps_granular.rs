//! LAMMPS's `pair_style granular` with `hertz/material E e ν damping tsuji
//! tangential mindlin NULL 1.0 μ rolling sds k_r γ_r μ_r` (the 2021–2022
//! releases, as Debian's `lmp` ships), written from what those styles
//! compute, for `contact.preset = "lammps-granular"`.
//!
//! Where it differs from [`super::hertz_mindlin`] (same Hertz force, same
//! E* and G*):
//! - damping coefficient: LAMMPS's polynomial fit α(e) of Tsuji's table
//!   ([`tsuji_alpha`]) instead of the closed form from ln e;
//! - the normal damping is α √(m* k) with k = (4/3) E* a (not 2 E* a), and
//!   the tangential damping is the same coefficient times 1.0 (the
//!   `mindlin NULL 1.0` factor), not α √(m* k_t);
//! - the tangential and rolling springs are first turned into the tangent
//!   plane with their length kept (only when their normal part is above
//!   1e-10 of the cap, as LAMMPS tests it), then the step's displacement is
//!   added; [`super::cundall_strack`] adds first and projects without
//!   rescaling (the `gran/hooke/history` order);
//! - the torque of the tangential force acts at r − ξ/2 (the middle of the
//!   overlap), not at r ([`ContactModel::lever`]);
//! - rolling is `sds`: a spring k_r and dashpot γ_r given in force units,
//!   capped at μ_r |F_n|, with the same turn-then-add order.
//!
//! The Coulomb caps take |F_n| with the damping in it (LAMMPS's `Fncrit`
//! for non-cohesive normal models), as the other laws do.

use super::contract::{Contact, ContactModel, ContactOutcome, Step};
use super::mass_scaling::MassScaling;
use super::material::{pair_table, r_star, Material, PairOverride};
use crate::dim::Dim;

/// LAMMPS's threshold on the spring's normal part, relative to the cap,
/// below which the spring is not turned (`EPSILON` in `pair_granular.cpp`).
const FRAME_EPSILON: f64 = 1e-10;

/// The damping coefficient α of LAMMPS's `damping tsuji` for restitution
/// `e`: the sixth-order polynomial fit to Tsuji, Tanaka & Ishida's (1992)
/// table that LAMMPS evaluates (its documentation gives the same numbers).
pub fn tsuji_alpha(e: f64) -> f64 {
    let e2 = e * e;
    let e3 = e2 * e;
    1.2728 - 4.2783 * e + 11.087 * e2 - 22.348 * e3 + 27.467 * (e2 * e2) - 18.022 * (e2 * e3)
        + 4.8218 * (e3 * e3)
}

/// `rolling sds` coefficients shared by every pair (LAMMPS's `pair_coeff *
/// *`): spring and dashpot on the rolling displacement, in force units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RollingSds {
    pub stiffness: f64,
    pub damping: f64,
}

/// One pair's coefficients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GranularPair {
    /// (4/3) E*: the Hertz force is this times ξ a.
    four_thirds_e_star: f64,
    /// 8 G*: k_t = 8 G* a (`mindlin NULL`).
    eight_g_star: f64,
    /// α of `damping tsuji`.
    alpha: f64,
    mu: f64,
    mu_r: f64,
    k_roll: f64,
    /// 1/k_r (∞ without rolling, never read then).
    inv_k_roll: f64,
    gamma_roll: f64,
}

impl GranularPair {
    /// The pair of materials `a` and `b`, as `pair_coeff` with LAMMPS's
    /// mixing: E* and G* by Johnson's rules (LAMMPS's `mix_stiffnessE`,
    /// `mix_stiffnessG`), α, μ and μ_r as geometric means of the two
    /// materials' own (its `mix_geom`), unless `over` gives the pair's
    /// restitution, friction or rolling friction.
    pub fn new(a: &Material, b: &Material, over: &PairOverride, rolling: RollingSds) -> Self {
        let (ea, eb, na, nb) = (
            a.youngs_modulus,
            b.youngs_modulus,
            a.poisson_ratio,
            b.poisson_ratio,
        );
        let e_star = 1.0 / ((1.0 - na * na) / ea + (1.0 - nb * nb) / eb);
        let g_star =
            1.0 / ((2.0 * (2.0 - na) * (1.0 + na) / ea) + (2.0 * (2.0 - nb) * (1.0 + nb) / eb));
        let geom = |x: f64, y: f64| if x == y { x } else { (x * y).sqrt() };
        Self {
            four_thirds_e_star: 4.0 / 3.0 * e_star,
            eight_g_star: 8.0 * g_star,
            alpha: over
                .restitution
                .map(tsuji_alpha)
                .unwrap_or_else(|| geom(tsuji_alpha(a.restitution), tsuji_alpha(b.restitution))),
            mu: over
                .friction
                .unwrap_or_else(|| geom(a.friction, b.friction)),
            mu_r: over
                .rolling_friction
                .unwrap_or_else(|| geom(a.rolling_friction, b.rolling_friction)),
            k_roll: rolling.stiffness,
            inv_k_roll: 1.0 / rolling.stiffness,
            gamma_roll: rolling.damping,
        }
    }

    /// E*, as the law holds it ((4/3) E* over 4/3).
    pub fn e_star(&self) -> f64 {
        0.75 * self.four_thirds_e_star
    }

    /// G*, as the law holds it (8 G* over 8).
    pub fn g_star(&self) -> f64 {
        self.eight_g_star / 8.0
    }

    /// α of `damping tsuji`.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Sliding friction μ.
    pub fn friction(&self) -> f64 {
        self.mu
    }

    /// Rolling friction μ_r.
    pub fn rolling_friction(&self) -> f64 {
        self.mu_r
    }
}

/// The table of a scenario's pairs, indexed as the material law's
/// ([`super::hertz_mindlin::HertzMindlin`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GranularTable {
    pub pairs: Vec<GranularPair>,
    pub rolling: Option<RollingSds>,
}

impl GranularTable {
    /// The pairs of `materials` (`overrides` per pair of their indices).
    pub fn new(
        materials: &[Material],
        overrides: &[((usize, usize), PairOverride)],
        rolling: Option<RollingSds>,
    ) -> Self {
        let pairs = pair_table(materials, overrides, |a, b, over| {
            GranularPair::new(a, b, over, rolling.unwrap_or_default())
        });
        Self { pairs, rolling }
    }
}

/// The law: the material law's lookup (`law`, a
/// [`super::hertz_mindlin::HertzMindlin`]: which table entry a pair or a
/// wall contact takes, and whether grains turn) with LAMMPS's forces;
/// `ROLL` compiles `rolling sds` in.
pub struct LammpsGranular<'a, L, const ROLL: bool> {
    pub law: &'a L,
    pub table: &'a GranularTable,
}

impl<L, const ROLL: bool> LammpsGranular<'_, L, ROLL> {
    #[inline(always)]
    fn entry(&self, pair: u32) -> &GranularPair {
        // SAFETY: `pair` comes from the material law's `pair_index` /
        // `wall_pair_index`, below materials² (checked in
        // `HertzMindlin::new`), and the table has materials² entries
        // (`HertzMindlin::with_lammps_granular` checks it).
        debug_assert!((pair as usize) < self.table.pairs.len());
        unsafe { self.table.pairs.get_unchecked(pair as usize) }
    }
}

/// LAMMPS's spring update and Coulomb cap, for the tangential and the
/// rolling spring alike: turn the spring into the tangent plane keeping its
/// length (when its normal part matters), add `v dt`, take −(k s + γ v), and
/// when that exceeds `cap`, scale the force down to it and set the spring to
/// the length that gives exactly that force. `inv_k` is 1/k (the rolling
/// spring's is tabulated). Selections, not branches, so that the lanes
/// vectorize it; one root and one division each for the turn and the cap
/// (LAMMPS takes two roots for the turn and three divisions for the cap:
/// the same values to rounding).
#[inline(always)]
fn spring_force<D: Dim>(
    spring: &mut D::V,
    v: D::V,
    n: D::V,
    (k, inv_k, gamma, cap): (f64, f64, f64, f64),
    step: Step,
) -> D::V {
    if step.update {
        let s = *spring;
        let along = D::dot(s, n);
        let turn = along.abs() * k > FRAME_EPSILON * cap;
        let projected = s - n * along;
        // |s| / |projected| as √(|s|² / |projected|²); a spring within
        // ~1e-154 rad of the normal is dropped (its direction is noise, and
        // the quotient would overflow). The test is |p|² · 2^1022 > |s|²
        // rather than |p|² > |s|² · 2^-1022: the latter's product is
        // subnormal for any spring shorter than 1, and each subnormal
        // result costs the processor a slow assist.
        let plen2 = D::norm2(projected);
        let scale = if plen2 * (1.0 / f64::MIN_POSITIVE) > D::norm2(s) {
            (D::norm2(s) / plen2).sqrt()
        } else {
            0.0
        };
        let turned = if turn { projected * scale } else { s };
        *spring = turned + v * step.dt;
    }
    let f = -(*spring * k + v * gamma);
    let f2 = D::norm2(f);
    let sliding = f2 > cap * cap;
    let has = D::norm2(*spring) != 0.0;
    // The force scaled to the cap, and the spring that gives it:
    // −(k s + γ v) = capped  ⇔  s = −(capped + γ v) / k.
    let capped = f * (cap / f2.sqrt());
    let cut = -((capped + v * gamma) * inv_k);
    *spring = if sliding && has { cut } else { *spring };
    if !sliding {
        f
    } else if has {
        capped
    } else {
        D::zero()
    }
}

impl<L: ContactModel, const ROLL: bool> ContactModel for LammpsGranular<'_, L, ROLL> {
    const LANES: bool = true;
    const PAIR_TABLE: bool = true;
    const ROLLING: bool = ROLL;
    const ROLLING_HISTORY: bool = ROLL;
    #[inline(always)]
    fn rotation(&self) -> bool {
        self.law.rotation()
    }
    #[inline(always)]
    fn force_factor(&self, _: f64) -> f64 {
        1.0
    }
    #[inline(always)]
    fn pair_index(&self, kind_i: u32, kind_j: u32) -> u32 {
        self.law.pair_index(kind_i, kind_j)
    }
    /// A wall is a flat, infinitely heavy partner of its material, under
    /// the pair law (not LAMMPS's `fix wall/gran`, whose 2021 formulas
    /// differ: see `docs/contact-models.md`).
    #[inline(always)]
    fn wall_pair_index(&self, kind_i: u32, wall: usize) -> u32 {
        self.law.wall_pair_index(kind_i, wall)
    }
    /// LAMMPS's `dist_to_contact = radius − 0.5 δ`.
    #[inline(always)]
    fn lever(&self, r: f64, overlap: f64) -> f64 {
        r - 0.5 * overlap
    }
    #[inline(always)]
    fn evaluate<D: Dim>(&self, c: &Contact<D>, spring: &mut D::V, step: Step) -> ContactOutcome<D> {
        let p = self.entry(c.pair);
        let n = c.normal;
        let r_star = r_star(c.ri, c.rj);
        let m_star = MassScaling::Reduced.damping_mass(c.mi, c.mj);
        let a = (c.overlap * r_star).sqrt();
        // LAMMPS's order: (k δ) a for the force, k a for the damping.
        let elastic = p.four_thirds_e_star * c.overlap * a;
        let damp = p.alpha * (m_star * (p.four_thirds_e_star * a)).sqrt();
        let vn = D::dot(c.v_rel, n);
        let fn_total = elastic - damp * vn;
        let vt = c.v_rel - n * vn;
        let kt = p.eight_g_star * a;
        let cap = p.mu * fn_total.abs();
        let tangential = spring_force::<D>(spring, vt, n, (kt, 1.0 / kt, damp, cap), step);
        ContactOutcome {
            force: n * fn_total + tangential,
            tangential,
            normal_force: fn_total,
        }
    }
    #[inline(always)]
    fn rolling<D: Dim>(
        &self,
        c: &Contact<D>,
        out: &ContactOutcome<D>,
        spring: &mut D::V,
        step: Step,
    ) -> D::A {
        let p = self.entry(c.pair);
        let r_star = r_star(c.ri, c.rj);
        let vr = D::ang_cross(c.omega_rel, c.normal) * r_star;
        let cap = p.mu_r * out.normal_force.abs();
        let fr = spring_force::<D>(
            spring,
            vr,
            c.normal,
            (p.k_roll, p.inv_k_roll, p.gamma_roll, cap),
            step,
        );
        D::torque(c.normal, fr) * r_star
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tsuji_damping::restitution_of;
    use crate::dim::D3;
    use glam::DVec3;

    fn material(e: f64, nu: f64, rest: f64, mu: f64) -> Material {
        Material {
            rolling_friction: 0.1,
            ..Material::elastic("m", e, nu, 1.0, rest, mu)
        }
    }

    /// The fit does what LAMMPS does with it: the restitution of a
    /// head-on Hertz collision under damping α(e) √(m* (4/3) E* a) v_n (in
    /// `tsuji_damping`'s reduced collision, α' = α √(2/3)) is the one LAMMPS
    /// itself gives for the e asked of it, from its run of two cast-iron
    /// spheres (`tests/data/lammps/tsuji-pair.in` and `.out`, ten digits),
    /// within 1e-4 (LAMMPS's Verlet at t_c/2000 against this Runge–Kutta;
    /// a coefficient of the polynomial mistyped in its third digit moves
    /// the restitution by more).
    #[test]
    fn tsuji_polynomial_gives_lammps_restitution() {
        let from_lammps = [
            (0.3, 0.4395207026),
            (0.5, 0.6160534909),
            (0.7, 0.7776520844),
            (0.9, 0.9283531959),
            (1.0, 0.9995785795),
        ];
        for (e, lammps) in from_lammps {
            let got = restitution_of(tsuji_alpha(e) * (2.0f64 / 3.0).sqrt());
            assert!(
                (got - lammps).abs() < 1e-4,
                "e = {e}: {got} against {lammps}"
            );
        }
    }

    /// E* = E / (2 (1 − ν²)) and G* = E / (4 (2 − ν)(1 + ν)) for one
    /// material; the geometric means for two.
    #[test]
    fn mixing_as_lammps() {
        let a = material(5.0e7, 0.3, 0.9, 0.5);
        let p = GranularPair::new(&a, &a, &PairOverride::default(), RollingSds::default());
        let e_star = 5.0e7 / (2.0 * (1.0 - 0.09));
        let g_star = 5.0e7 / (4.0 * 1.7 * 1.3);
        assert!((p.four_thirds_e_star / (4.0 / 3.0 * e_star) - 1.0).abs() < 1e-14);
        assert!((p.eight_g_star / (8.0 * g_star) - 1.0).abs() < 1e-14);
        let b = material(5.0e7, 0.3, 0.5, 0.2);
        let q = GranularPair::new(&a, &b, &PairOverride::default(), RollingSds::default());
        let alpha = (tsuji_alpha(0.9) * tsuji_alpha(0.5)).sqrt();
        assert!((q.alpha - alpha).abs() < 1e-15);
        assert!((q.mu - 0.1f64.sqrt()).abs() < 1e-15);
    }

    /// A spring along the normal to within 1e-160 (its projection's square
    /// subnormal) is dropped; one 1e-100 off it turns with its length kept.
    #[test]
    fn spring_along_the_normal_is_dropped() {
        let step = Step {
            dt: 0.1,
            update: true,
        };
        let n = DVec3::Z;
        let turned = |off: f64| {
            let mut s = DVec3::new(off, 0.0, 1e-3);
            spring_force::<D3>(&mut s, DVec3::ZERO, n, (10.0, 0.1, 0.0, 1.0), step);
            s
        };
        assert_eq!(turned(1e-160), DVec3::ZERO);
        let kept = turned(1e-100);
        assert_eq!(kept.z, 0.0);
        assert!((kept.x - 1e-3).abs() < 1e-18, "{kept}");
    }

    /// The spring turns into the new tangent plane with its length kept,
    /// then takes the step's displacement; sliding cuts it back so that
    /// −(k s + γ v) has exactly the cap's length.
    #[test]
    fn spring_turn_keeps_length_then_slides() {
        let step = Step {
            dt: 0.1,
            update: true,
        };
        let n = DVec3::new(1.0, 0.0, 1.0).normalize();
        let mut s = DVec3::new(0.3, 0.4, 0.0);
        let f = spring_force::<D3>(&mut s, DVec3::ZERO, n, (10.0, 0.1, 0.0, 1e9), step);
        assert!(s.dot(n).abs() < 1e-15);
        assert!((s.length() - 0.5).abs() < 1e-15);
        assert!((f + s * 10.0).length() < 1e-14);
        let v = DVec3::new(0.0, 1.0, 0.0);
        let f = spring_force::<D3>(&mut s, v, n, (10.0, 0.1, 2.0, 1.0), step);
        assert!((f.length() - 1.0).abs() < 1e-14);
        assert!((-(s * 10.0 + v * 2.0) - f).length() < 1e-14);
    }
}
