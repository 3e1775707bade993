//! The Hertz–Mindlin contact between materials: Hertz's normal force,
//! Tsuji-form damping set from the pair's restitution, Mindlin's
//! tangential stiffness with the Cundall–Strack history and the Coulomb cap.
//!
//! With R* = R_i R_j / (R_i + R_j) (R_i against a wall), m* the reduced
//! mass (m_i against a wall or a frozen grain), a = √(R* ξ) the contact
//! radius:
//! - normal: F_n = (4/3) E* √R* ξ^{3/2} − α √(m* S_n) v_n, S_n = 2 E* a;
//! - tangential: k_t = 8 G* a on the Cundall–Strack spring, damping
//!   α √(m* k_t) on the tangential velocity, the whole capped at μ |F_n|;
//! - α from the pair's restitution ([`super::tsuji_damping`]).
//!
//! In 2D a disk is a sphere of the same radius moving in the plane (as in
//! LAMMPS's 2D granular runs): the same formulas, with the disk's mass.
//! Pairs of materials are looked up by the grains' `kind` (each kind has one
//! material) and by the wall's index. Written without branches, the law
//! runs on the batched lanes of the pair loop.

use super::cohesion::{dmt_pull_off, CohesionModel};
use super::contract::{Contact, ContactModel, ContactOutcome, Step};
use super::cundall_strack::Tangential;
use super::jkr;
use super::lammps_granular::{GranularTable, LammpsGranular};
use super::law::ContactLaw;
use super::mass_scaling::MassScaling;
use super::material::{pair_table, r_star, Material, PairCoefficients, PairOverride};
use super::registered::{Registered, RunLaw};
use super::rolling::{epsd_damping, rolling_torque, RollingContact, RollingModel};
use super::tsuji_damping::alpha_for_restitution;
use crate::dim::Dim;
use crate::error::{Error, Result};

/// The coefficients one pair of materials gives the law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzPair {
    /// 2 E*: S_n = 2 E* a.
    two_e_star: f64,
    /// 8 G*: k_t = 8 G* a.
    eight_g_star: f64,
    /// Damping coefficient α.
    alpha: f64,
    mu: f64,
    /// Rolling friction μ_r.
    mu_r: f64,
    /// 2π Γ: the DMT pull-off force per unit R* (0 without cohesion).
    two_pi_gamma: f64,
    /// Γ: the JKR law's, and kept for [`HertzMindlin::with_cohesion`].
    surface_energy: f64,
    /// (3/4) (π² Γ² / E*²)^{1/3}: a JKR contact breaks this times R*^{1/3}
    /// beyond touching ([`super::jkr::separation_coefficient`]).
    jkr_reach: f64,
}

impl HertzPair {
    pub fn new(p: &PairCoefficients) -> Self {
        Self {
            two_e_star: 2.0 * p.e_star,
            eight_g_star: 8.0 * p.g_star,
            alpha: alpha_for_restitution(p.restitution),
            mu: p.friction,
            mu_r: p.rolling_friction,
            two_pi_gamma: 0.0,
            surface_energy: p.surface_energy,
            jkr_reach: jkr::separation_coefficient(p.e_star, p.surface_energy),
        }
    }

    /// The damping coefficient α (Tsuji form) the pair's restitution gave.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }
}

/// The Hertz–Mindlin law of a set of materials.
#[derive(Clone, Debug, PartialEq)]
pub struct HertzMindlin {
    materials: usize,
    /// `pairs[a * materials + b]`.
    pairs: Vec<HertzPair>,
    /// The mixed coefficients each entry of `pairs` was made from (what
    /// `grains check` prints).
    coefficients: Vec<PairCoefficients>,
    /// The material of each grain kind.
    material_of_kind: Vec<u32>,
    /// The material of every grain kind, when they all have one: contacts
    /// then need no lookup of the grains' kinds.
    grain_material: Option<u32>,
    /// The material of each wall.
    wall_material: Vec<u32>,
    pub rotation: bool,
    /// The rolling resistance ([`HertzMindlin::with_rolling`] runs it).
    pub rolling: RollingModel,
    /// The cohesion ([`HertzMindlin::with_cohesion`] sets it).
    cohesion: CohesionModel,
    /// LAMMPS's `pair granular` forces instead of these
    /// ([`HertzMindlin::with_lammps_granular`]).
    granular: Option<GranularTable>,
}

impl HertzMindlin {
    /// The law for `materials` (with `overrides` per pair of their indices),
    /// grains of kind k being of material `material_of_kind[k]` and wall w
    /// of `wall_material[w]`.
    pub fn new(
        materials: &[Material],
        overrides: &[((usize, usize), PairOverride)],
        material_of_kind: Vec<u32>,
        wall_material: Vec<u32>,
        rotation: bool,
    ) -> Self {
        let n = materials.len();
        assert!(
            material_of_kind
                .iter()
                .chain(&wall_material)
                .all(|&m| (m as usize) < n),
            "a material index beyond the {n} materials"
        );
        let coefficients = pair_table(materials, overrides, PairCoefficients::mix);
        let pairs = coefficients.iter().map(HertzPair::new).collect();
        let first = material_of_kind.first().copied();
        let grain_material = first.filter(|&m| material_of_kind.iter().all(|&k| k == m));
        Self {
            materials: n,
            pairs,
            coefficients,
            material_of_kind,
            grain_material,
            wall_material,
            rotation,
            rolling: RollingModel::None,
            cohesion: CohesionModel::None,
            granular: None,
        }
    }

    /// The law with LAMMPS's `pair granular` forces
    /// ([`super::lammps_granular`]) for the same materials, grain kinds and
    /// walls: `contact.preset = "lammps-granular"`. Its rolling resistance
    /// is `table.rolling` (`rolling sds`), which sets [`Self::rolling`].
    pub fn with_lammps_granular(mut self, table: GranularTable) -> Self {
        assert_eq!(table.pairs.len(), self.pairs.len(), "one entry per pair");
        self.rolling = if table.rolling.is_some() {
            RollingModel::Epsd
        } else {
            RollingModel::None
        };
        self.granular = Some(table);
        self
    }

    /// Whether the law is LAMMPS's `pair granular` preset.
    pub fn is_lammps_granular(&self) -> bool {
        self.granular.is_some()
    }

    /// The law with cohesion `model` from the pairs' surface energy.
    pub fn with_cohesion(mut self, model: CohesionModel) -> Self {
        self.cohesion = model;
        for p in &mut self.pairs {
            p.two_pi_gamma = match model {
                // JKR's force is its own (`evaluate_with`), no added pull.
                CohesionModel::None | CohesionModel::Jkr => 0.0,
                CohesionModel::Dmt => dmt_pull_off(p.surface_energy, 1.0),
            };
        }
        self
    }

    /// The law with its rolling resistance compiled in, handed to `run`
    /// (one compiled kernel per model; none without rolling).
    #[inline(always)]
    pub fn with_rolling<R>(&self, run: impl RunLaw<R>) -> R {
        if let Some(table) = &self.granular {
            return if table.rolling.is_some() {
                run.run(&LammpsGranular::<_, true> { law: self, table })
            } else {
                run.run(&LammpsGranular::<_, false> { law: self, table })
            };
        }
        let jkr = self.cohesion == CohesionModel::Jkr;
        match (self.rolling, jkr) {
            (RollingModel::None, false) => run.run(self),
            (RollingModel::Constant, false) => run.run(&Rolled::<1, false>(self)),
            (RollingModel::Epsd, false) => run.run(&Rolled::<2, false>(self)),
            (RollingModel::None, true) => run.run(&Rolled::<0, true>(self)),
            (RollingModel::Constant, true) => run.run(&Rolled::<1, true>(self)),
            // A JKR contact keeps its mark where epsd keeps its rolling
            // spring: `MaterialLaw::check` and the scenario refuse the pair.
            (RollingModel::Epsd, true) => unreachable!("jkr with epsd rolling is refused"),
        }
    }

    /// The cohesion model.
    pub fn cohesion(&self) -> CohesionModel {
        self.cohesion
    }

    /// Whether contacts keep a second history (the epsd rolling spring or
    /// the JKR contact mark) in the rolling slots.
    pub fn keeps_second_history(&self) -> bool {
        self.rolling.has_history() || self.cohesion == CohesionModel::Jkr
    }

    /// The largest JKR breaking separation δ_c among pairs of grains of
    /// radius at most `max_radius` (and walls); 0 without JKR.
    pub fn max_reach(&self, max_radius: f64) -> f64 {
        if self.cohesion != CohesionModel::Jkr {
            return 0.0;
        }
        // R* ≤ the grain's radius, against a grain or a wall.
        let most = self.pairs.iter().map(|p| p.jkr_reach).fold(0.0, f64::max);
        most * max_radius.cbrt()
    }

    /// The coefficients of materials `a` and `b`.
    pub fn pair(&self, a: usize, b: usize) -> &HertzPair {
        &self.pairs[a * self.materials + b]
    }

    /// The mixed coefficients (E*, G*, restitution, friction, rolling
    /// friction, surface energy) that materials `a` and `b` gave the law.
    pub fn coefficients(&self, a: usize, b: usize) -> &PairCoefficients {
        &self.coefficients[a * self.materials + b]
    }

    /// The sliding and rolling friction (μ, μ_r) of materials `a` and `b`,
    /// from the table the kernel runs (LAMMPS's mixing under that preset).
    pub fn friction(&self, a: usize, b: usize) -> (f64, f64) {
        let k = a * self.materials + b;
        match &self.granular {
            Some(t) => (t.pairs[k].friction(), t.pairs[k].rolling_friction()),
            None => (self.pairs[k].mu, self.pairs[k].mu_r),
        }
    }

    /// The material of each grain kind (the kinds no grain has: 0).
    pub fn kind_materials(&self) -> &[u32] {
        &self.material_of_kind
    }

    /// The material of each wall.
    pub fn wall_materials(&self) -> &[u32] {
        &self.wall_material
    }

    /// LAMMPS's `pair granular` table when the law is that preset.
    pub fn granular(&self) -> Option<&GranularTable> {
        self.granular.as_ref()
    }

    /// The coefficients of table entry `pair`.
    #[inline(always)]
    fn entry(&self, pair: u32) -> &HertzPair {
        // SAFETY: `pair` comes from `pair_index`/`wall_pair_index`, whose
        // materials are below `materials` (checked in `new`), so the entry
        // exists; unchecked, the lanes need no bounds-check exit.
        debug_assert!((pair as usize) < self.pairs.len());
        unsafe { self.pairs.get_unchecked(pair as usize) }
    }

    /// The material of grain kind `kind` (no lookup when all kinds have
    /// one: the pair pass asks for every contact).
    #[inline(always)]
    fn material(&self, kind: u32) -> u32 {
        match self.grain_material {
            Some(m) => m,
            None => self.material_of_kind[kind as usize],
        }
    }
}

impl ContactModel for HertzMindlin {
    const LANES: bool = true;
    const PAIR_TABLE: bool = true;
    #[inline(always)]
    fn rotation(&self) -> bool {
        self.rotation
    }
    #[inline(always)]
    fn force_factor(&self, _: f64) -> f64 {
        1.0
    }
    #[inline(always)]
    fn pair_index(&self, kind_i: u32, kind_j: u32) -> u32 {
        self.material(kind_i) * self.materials as u32 + self.material(kind_j)
    }
    #[inline(always)]
    fn wall_pair_index(&self, kind_i: u32, wall: usize) -> u32 {
        self.material(kind_i) * self.materials as u32 + self.wall_material[wall]
    }
    #[inline(always)]
    fn evaluate<D: Dim>(&self, c: &Contact<D>, spring: &mut D::V, step: Step) -> ContactOutcome<D> {
        self.evaluate_with::<D, false>(c, spring, step)
    }
}

impl HertzMindlin {
    /// The law on one contact; with `JKR`, the JKR force and contact
    /// radius ([`super::jkr`]) replace Hertz's (the overlap may then be
    /// negative, down to −δ_c).
    #[inline(always)]
    fn evaluate_with<D: Dim, const JKR: bool>(
        &self,
        c: &Contact<D>,
        spring: &mut D::V,
        step: Step,
    ) -> ContactOutcome<D> {
        let p = self.entry(c.pair);
        let n = c.normal;
        let r_star = r_star(c.ri, c.rj);
        let m_star = MassScaling::Reduced.damping_mass(c.mi, c.mj);
        let vn = D::dot(c.v_rel, n);
        let (a, sn, fn_total, load);
        if JKR {
            let e_star = 0.5 * p.two_e_star;
            let gamma = p.surface_energy;
            a = jkr::contact_radius(c.overlap, r_star, e_star, gamma);
            sn = p.two_e_star * a;
            let elastic = jkr::force(a, r_star, e_star, gamma);
            fn_total = elastic - p.alpha * (m_star * sn).sqrt() * vn;
            // F_n + 2 F_po, F_po = (3/2) π Γ R* (LAMMPS's Fncrit for jkr).
            load = fn_total + 2.0 * jkr::pull_off(gamma, r_star);
        } else {
            a = (r_star * c.overlap).sqrt();
            sn = p.two_e_star * a;
            // (4/3) E* √R* ξ^{3/2} = (2/3) S_n ξ.
            let elastic = 2.0 / 3.0 * sn * c.overlap;
            // DMT's pull 2π Γ R* (zero without cohesion: the same bits).
            let pull = p.two_pi_gamma * r_star;
            fn_total = elastic - p.alpha * (m_star * sn).sqrt() * vn - pull;
            // The load the caps scale: F_n + 2 F_po (LAMMPS's Fncrit).
            load = fn_total + 2.0 * pull;
        }
        let vt = c.v_rel - n * vn;
        let kt = p.eight_g_star * a;
        let tangential = Tangential {
            kt,
            gamma: p.alpha * (m_star * kt).sqrt(),
            mu: p.mu,
        }
        .force::<D>(spring, vt, n, load.abs(), step, true);
        ContactOutcome {
            force: n * fn_total + tangential,
            tangential,
            normal_force: load,
        }
    }
}

/// A material law as a run holds it: the law, and the spring–dashpot
/// stand-in of its stiffness that the time step was estimated from.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialLaw {
    pub hertz: HertzMindlin,
    pub estimate: ContactLaw,
}

impl Registered for MaterialLaw {
    #[inline(always)]
    fn with_kernel<R>(&self, run: impl RunLaw<R>) -> R {
        self.hertz.with_rolling(run)
    }
    fn rotation(&self) -> bool {
        self.hertz.rotation
    }
    fn estimate(&self) -> &ContactLaw {
        &self.estimate
    }
    fn rolling(&self) -> RollingModel {
        self.hertz.rolling
    }
    fn cohesion(&self) -> CohesionModel {
        self.hertz.cohesion
    }
    fn keeps_second_history(&self) -> bool {
        self.hertz.keeps_second_history()
    }

    /// JKR contacts are kept up to δ_c beyond touching, in the rolling
    /// slots: the Verlet skin must list every pair that close (a pair
    /// farther than the skin at a rebuild is not listed), and no epsd
    /// spring may need the slots.
    fn check(&self, max_radius: f64, skin: f64) -> Result<()> {
        let law = &self.hertz;
        if law.cohesion != CohesionModel::Jkr {
            return Ok(());
        }
        if law.rolling == RollingModel::Epsd {
            return Err(Error::input(
                "contact.cohesion = \"jkr\" with contact.rolling = \"epsd\": not supported yet (both \
                 keep a history per contact in the same place); use contact.rolling = \"constant\" or \
                 \"none\"",
            ));
        }
        let reach = law.max_reach(max_radius);
        if reach >= skin {
            return Err(Error::input(format!(
                "contact.cohesion = \"jkr\": the pull-off separation δ_c = {reach:e} m of the largest \
                 grains is not below the Verlet skin {skin:e} m, so a stretched contact could leave the \
                 neighbour list; raise run.skin"
            )));
        }
        Ok(())
    }
}

/// The Hertz–Mindlin law with rolling resistance `MODEL` (0 none, 1
/// constant, 2 epsd; [`super::rolling`]) and, with `JKR`, JKR cohesion
/// ([`super::jkr`]; never with epsd).
pub struct Rolled<'a, const MODEL: u8, const JKR: bool>(&'a HertzMindlin);

impl<const MODEL: u8, const JKR: bool> ContactModel for Rolled<'_, MODEL, JKR> {
    const LANES: bool = true;
    const PAIR_TABLE: bool = true;
    const ROLLING: bool = MODEL != 0;
    const ROLLING_HISTORY: bool = MODEL == 2;
    const BONDED: bool = JKR;
    #[inline(always)]
    fn rotation(&self) -> bool {
        self.0.rotation
    }
    #[inline(always)]
    fn force_factor(&self, _: f64) -> f64 {
        1.0
    }
    #[inline(always)]
    fn pair_index(&self, kind_i: u32, kind_j: u32) -> u32 {
        self.0.pair_index(kind_i, kind_j)
    }
    #[inline(always)]
    fn wall_pair_index(&self, kind_i: u32, wall: usize) -> u32 {
        self.0.wall_pair_index(kind_i, wall)
    }
    #[inline(always)]
    fn evaluate<D: Dim>(&self, c: &Contact<D>, spring: &mut D::V, step: Step) -> ContactOutcome<D> {
        self.0.evaluate_with::<D, JKR>(c, spring, step)
    }
    #[inline(always)]
    fn reach(&self, pair: u32, ri: f64, rj: f64) -> f64 {
        if JKR {
            self.0.entry(pair).jkr_reach * r_star(ri, rj).cbrt()
        } else {
            0.0
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
        let p = self.0.entry(c.pair);
        let r_star = r_star(c.ri, c.rj);
        let (k, gamma) = if MODEL == 2 {
            // Ai's 2.25 μ_r² times the normal stiffness 2 E* a.
            let k = 2.25 * p.mu_r * p.mu_r * p.two_e_star * (r_star * c.overlap).sqrt();
            (k, epsd_damping(k, (c.mi, c.ri), (c.mj, c.rj), r_star))
        } else {
            (0.0, 0.0)
        };
        let rc = RollingContact {
            r_star,
            cap: p.mu_r * out.normal_force.abs(),
            k,
            gamma,
        };
        rolling_torque::<D, MODEL>(c.omega_rel, c.normal, rc, spring, step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Grains all of one material take that material's entry without a
    /// lookup, walls their own column; grains of two materials look both
    /// up. Entry a · n + b for materials a and b.
    #[test]
    fn pair_indices_with_and_without_one_grain_material() {
        let mats = [
            Material::elastic("steel", 2e11, 0.3, 7800.0, 0.5, 0.5),
            Material::elastic("sand", 1e8, 0.25, 2600.0, 0.5, 0.5),
        ];
        let one = HertzMindlin::new(&mats, &[], vec![1, 1, 1], vec![0, 1], true);
        assert_eq!(one.grain_material, Some(1));
        assert_eq!(one.pair_index(0, 2), 3);
        assert_eq!(one.wall_pair_index(2, 0), 2);
        assert_eq!(one.wall_pair_index(2, 1), 3);
        let two = HertzMindlin::new(&mats, &[], vec![0, 1], vec![0, 1], true);
        assert_eq!(two.grain_material, None);
        assert_eq!(two.pair_index(0, 1), 1);
        assert_eq!(two.pair_index(1, 0), 2);
        assert_eq!(two.wall_pair_index(1, 0), 2);
        assert_eq!(two.wall_pair_index(0, 1), 1);
    }
}
