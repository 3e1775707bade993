//! A contact law over a batch of contacts held in component rows
//! ("lanes"), so that the compiler turns each operation into vector
//! instructions: the square root, the divisions and the sliding test of a
//! law then cost a fraction of a scalar contact each.
//!
//! The kernel is generic over the law ([`ContactModel`] with `LANES`): each
//! lane reads its contact from the rows, does the pair loop's geometry and
//! calls the law's own `evaluate`, the code the one-by-one path runs, so the
//! results are the same bits (a test checks it). A law written with
//! selections instead of branches (as [`super::cundall_strack`] is) then
//! vectorizes. Lanes past `len` hold stale values and are ignored.

use super::contract::{Contact, ContactModel, Step};
use crate::dim::Dim;
use crate::simd::{self, Kernel};
use std::marker::PhantomData;

/// Contacts per batch: enough rows that the vector loop runs long and that
/// the scalar stores filling a batch have left the store buffer before the
/// vector loads read them; small enough to stay in the L1 cache.
pub const LANES: usize = 32;

type Row = [f64; LANES];

/// One batch of contacts in component rows (x, y, z; 2D uses x and y for
/// vectors and z for the spin).
#[derive(Clone, Debug)]
pub struct ContactLanes {
    /// Inputs. `del` points from the second grain to the first.
    pub del: [Row; 3],
    /// Velocity of the first grain minus that of the second.
    pub v_rel: [Row; 3],
    /// ω_i r_i + ω_j r_j, whose cross product with n is the rolling part
    /// (laws without rolling resistance).
    pub spin: [Row; 3],
    /// ω_i and ω_j, for laws with rolling resistance
    /// ([`ContactModel::ROLLING`]) instead of `spin`: the kernel forms the
    /// spin and ω_i − ω_j from them (vectorized, the same arithmetic as the
    /// one-by-one loop's), which saves the batch fill twelve scalar
    /// operations per contact for the same six stores.
    pub omega_i: [Row; 3],
    pub omega_j: [Row; 3],
    pub ri: Row,
    pub rj: Row,
    /// Masses, ∞ for a frozen grain.
    pub mi: Row,
    pub mj: Row,
    /// The pairs' entries in the law's table of coefficients.
    pub pair: [u32; LANES],
    /// The tangential spring; the kernel leaves the updated one here.
    pub spring: [Row; 3],
    /// The rolling spring (laws with rolling history only), likewise.
    pub rolling: [Row; 3],
    /// Outputs: the force on the first grain, and the torques to subtract
    /// from the first and the second grain's sums.
    pub force: [Row; 3],
    pub torque_i: [Row; 3],
    pub torque_j: [Row; 3],
    pub overlap: Row,
}

impl Default for ContactLanes {
    fn default() -> Self {
        let row = [0.0; LANES];
        Self {
            del: [row; 3],
            v_rel: [row; 3],
            spin: [row; 3],
            omega_i: [row; 3],
            omega_j: [row; 3],
            ri: row,
            rj: row,
            mi: row,
            mj: row,
            pair: [0; LANES],
            spring: [row; 3],
            rolling: [row; 3],
            force: [row; 3],
            torque_i: [row; 3],
            torque_j: [row; 3],
            overlap: row,
        }
    }
}

/// `law` on every lane, with the geometry of the pair loop before it
/// (distance, normal, contact-point velocity) and the torques after it.
/// Uses AVX-512 or AVX2 where the processor has them (same bits: no fused
/// multiply-add is formed; a test compares the dispatched and the plain
/// kernel). Meant for laws with `LANES`; the law's rotation is taken as on.
pub fn evaluate_lanes<D: Dim, L: ContactModel>(law: &L, c: &mut ContactLanes, step: Step) {
    simd::run_widest(&mut LawOnLanes::<D, L> {
        law,
        c,
        step,
        dim: PhantomData,
    });
}

/// The lane loop, for one instruction set. A law with a table of pair
/// coefficients (`PAIR_TABLE`) gets a batch whose contacts all take one
/// entry (grains of one material) with that entry fixed: its coefficients
/// are then loaded once, outside the loop, instead of gathered lane by
/// lane, which is what lets the compiler vectorize the loop. The same
/// arithmetic either way.
#[inline(always)]
fn lanes<D: Dim, L: ContactModel>(law: &L, c: &mut ContactLanes, step: Step) {
    let first = c.pair[0];
    if L::PAIR_TABLE && c.pair.iter().all(|&p| p == first) {
        with_update::<D, L>(law, c, step, |_| first);
    } else {
        let pairs = c.pair;
        with_update::<D, L>(law, c, step, |l| pairs[l]);
    }
}

/// [`lane_loop`]; for a law with a rolling spring, compiled once with the
/// springs advancing and once without, so that `step.update` is a constant
/// inside it: the loop body is then one block of straight-line code, which
/// lets the compiler interleave the two springs' independent chains of
/// roots and divisions instead of running one after the other (about 3 %
/// of the Hertz chute's step). Other laws keep the one loop.
#[inline(always)]
fn with_update<D: Dim, L: ContactModel>(
    law: &L,
    c: &mut ContactLanes,
    step: Step,
    pair: impl Fn(usize) -> u32,
) {
    if !L::ROLLING_HISTORY {
        lane_loop::<D, L>(law, c, step, pair);
    } else {
        let update = |update| Step { update, ..step };
        if step.update {
            lane_loop::<D, L>(law, c, update(true), pair);
        } else {
            lane_loop::<D, L>(law, c, update(false), pair);
        }
    }
}

/// [`lanes`]'s loop, with lane l's table entry `pair(l)`.
#[inline(always)]
fn lane_loop<D: Dim, L: ContactModel>(
    law: &L,
    c: &mut ContactLanes,
    step: Step,
    pair: impl Fn(usize) -> u32,
) {
    let three = |r: &[Row; 3], l: usize| [r[0][l], r[1][l], r[2][l]];
    for l in 0..LANES {
        let del = D::from_xyz(three(&c.del, l));
        let (ri, rj) = (c.ri[l], c.rj[l]);
        // The pair loop's geometry: r = |del|, one division for n.
        let r = D::norm(del);
        let overlap = ri + rj - r;
        let n = del * (1.0 / r);
        // Contact-point velocities: ω_i × (−r_i n) − ω_j × (r_j n).
        let (spin, omega_rel) = if L::ROLLING {
            let wi = D::ang_from_xyz(three(&c.omega_i, l));
            let wj = D::ang_from_xyz(three(&c.omega_j, l));
            (wi * ri + wj * rj, wi - wj)
        } else {
            (D::ang_from_xyz(three(&c.spin, l)), D::A::default())
        };
        let v_rel = D::from_xyz(three(&c.v_rel, l)) - D::ang_cross(spin, n);
        let mut spring = D::from_xyz(three(&c.spring, l));
        let contact = Contact::<D> {
            overlap,
            normal: n,
            v_rel,
            mi: c.mi[l],
            mj: c.mj[l],
            ri,
            rj,
            omega_rel,
            pair: pair(l),
        };
        let out = law.evaluate(&contact, &mut spring, step);
        // Lever arms −r_i n and +r_j n, force on j is −F: both torques are
        // −r (n × F_t) with each grain's own radius.
        let nt = D::torque(n, out.tangential);
        let (mut ti, mut tj) = (nt * law.lever(ri, overlap), nt * law.lever(rj, overlap));
        let mut rolling = D::zero();
        if L::ROLLING {
            // The rolling torque T on i (−T on j), as amounts to subtract.
            rolling = D::from_xyz(three(&c.rolling, l));
            let t = law.rolling(&contact, &out, &mut rolling, step);
            ti -= t;
            tj += t;
        }
        let (f, s, rs) = (D::to_xyz(out.force), D::to_xyz(spring), D::to_xyz(rolling));
        let (ti, tj) = (D::ang_to_xyz(ti), D::ang_to_xyz(tj));
        for a in 0..3 {
            if a < D::D {
                c.force[a][l] = f[a];
                c.spring[a][l] = s[a];
                if L::ROLLING_HISTORY {
                    c.rolling[a][l] = rs[a];
                }
            }
            if D::D == 3 || a == 2 {
                c.torque_i[a][l] = ti[a];
                c.torque_j[a][l] = tj[a];
            }
        }
        c.overlap[l] = overlap;
    }
}

/// [`evaluate_lanes`]'s call, compiled for each instruction set.
struct LawOnLanes<'a, D, L> {
    law: &'a L,
    c: &'a mut ContactLanes,
    step: Step,
    dim: PhantomData<D>,
}

impl<D: Dim, L: ContactModel> Kernel for LawOnLanes<'_, D, L> {
    #[inline(always)]
    fn run(&mut self) {
        lanes::<D, L>(self.law, self.c, self.step);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hooke_history::{lammps_law, HookeHistory};
    use crate::dim::{D2, D3};
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// One contact as the scalar pair loop sees it.
    struct Case<D: Dim> {
        del: D::V,
        v_rel: D::V,
        omega_i: D::A,
        omega_j: D::A,
        ri: f64,
        rj: f64,
        mi: f64,
        mj: f64,
        spring: D::V,
        rolling: D::V,
        pair: u32,
    }

    /// The scalar pair loop's geometry and `law` (for the Hooke shape, the
    /// general law, not the lanes' compiled one): force, torques on i and
    /// j (to subtract), spring, overlap, rolling spring.
    fn scalar<D: Dim, L: ContactModel>(law: &L, c: &Case<D>, step: Step) -> [Vec<u64>; 6] {
        let r = D::norm(c.del);
        let overlap = c.ri + c.rj - r;
        let n = c.del * (1.0 / r);
        let spin = c.omega_i * c.ri + c.omega_j * c.rj;
        let v_rel = c.v_rel - D::ang_cross(spin, n);
        let mut spring = c.spring;
        let contact = Contact::<D> {
            overlap,
            normal: n,
            v_rel,
            mi: c.mi,
            mj: c.mj,
            ri: c.ri,
            rj: c.rj,
            omega_rel: c.omega_i - c.omega_j,
            pair: c.pair,
        };
        let out = law.evaluate(&contact, &mut spring, step);
        let nt = D::torque(n, out.tangential);
        let mut rolling = c.rolling;
        let (mut ti, mut tj) = (nt * law.lever(c.ri, overlap), nt * law.lever(c.rj, overlap));
        if L::ROLLING {
            let t = law.rolling(&contact, &out, &mut rolling, step);
            ti -= t;
            tj += t;
        }
        // Lanes of a law without rolling history leave the row as it was.
        if !L::ROLLING_HISTORY {
            rolling = c.rolling;
        }
        let v = |x: D::V| (0..D::D).map(|a| D::get(x, a).to_bits()).collect();
        let a = |x: D::A| D::ang_to_xyz(x).map(f64::to_bits).to_vec();
        [
            v(out.force),
            a(ti),
            a(tj),
            v(spring),
            vec![overlap.to_bits()],
            v(rolling),
        ]
    }

    fn lanes_out<D: Dim>(c: &ContactLanes, l: usize) -> [Vec<u64>; 6] {
        let v = |r: &[Row; 3]| (0..D::D).map(|a| r[a][l].to_bits()).collect();
        let a = |r: &[Row; 3]| {
            let x = D::ang_from_xyz([r[0][l], r[1][l], r[2][l]]);
            D::ang_to_xyz(x).map(f64::to_bits).to_vec()
        };
        [
            v(&c.force),
            a(&c.torque_i),
            a(&c.torque_j),
            v(&c.spring),
            vec![c.overlap[l].to_bits()],
            v(&c.rolling),
        ]
    }

    /// A batch of random contacts (pair entries cycling through `pairs`),
    /// as cases and in lanes (the spin row and the ω_i and ω_j rows alike,
    /// for laws with and without rolling resistance).
    /// `stretch` moves the grains apart by that fraction of r_i + r_j (some
    /// overlaps then negative: kept JKR contacts).
    fn batch<D: Dim>(
        rng: &mut Xoshiro256PlusPlus,
        pairs: u32,
        stretch: f64,
    ) -> (Vec<Case<D>>, ContactLanes) {
        let mut u = || rng.gen_range(-1.0..1.0);
        let cases: Vec<Case<D>> = (0..LANES)
            .map(|l| {
                let v3 = |u: &mut dyn FnMut() -> f64| D::from_xyz([u(), u(), u()]);
                let (ri, rj) = (0.5 + 0.1 * u(), 0.5 + 0.1 * u());
                let dir = v3(&mut u);
                let del = dir * ((ri + rj) * (1.0 + stretch - 2e-3 * (u() + 1.0)) / D::norm(dir));
                let frozen = |m: f64, f: bool| if f { f64::INFINITY } else { m };
                Case {
                    del,
                    v_rel: v3(&mut u) * 3.0,
                    omega_i: D::ang_from_xyz([u(), u(), u()]) * 2.0,
                    omega_j: D::ang_from_xyz([u(), u(), u()]) * 2.0,
                    ri,
                    rj,
                    mi: frozen(1.0 + u().abs(), l % 9 == 4),
                    mj: frozen(1.0 + u().abs(), l % 7 == 3),
                    spring: if l % 5 == 0 {
                        D::zero()
                    } else {
                        v3(&mut u) * 1e-3
                    },
                    rolling: if l % 3 == 0 {
                        D::zero()
                    } else {
                        v3(&mut u) * 1e-4
                    },
                    pair: l as u32 % pairs,
                }
            })
            .collect();
        let mut c = ContactLanes::default();
        for (l, x) in cases.iter().enumerate() {
            let spin = D::ang_to_xyz(x.omega_i * x.ri + x.omega_j * x.rj);
            let (wi, wj) = (D::ang_to_xyz(x.omega_i), D::ang_to_xyz(x.omega_j));
            for (a, w) in spin.into_iter().enumerate() {
                c.spin[a][l] = w;
                c.omega_i[a][l] = wi[a];
                c.omega_j[a][l] = wj[a];
                if a < D::D {
                    c.del[a][l] = D::get(x.del, a);
                    c.v_rel[a][l] = D::get(x.v_rel, a);
                    c.spring[a][l] = D::get(x.spring, a);
                    c.rolling[a][l] = D::get(x.rolling, a);
                }
            }
            (c.ri[l], c.rj[l], c.mi[l], c.mj[l]) = (x.ri, x.rj, x.mi, x.mj);
            c.pair[l] = x.pair;
        }
        (cases, c)
    }

    /// Random contacts, sticking and sliding, fresh springs and frozen
    /// partners, through both the plain and the dispatched (AVX2 where
    /// present) kernel: the same bits as the scalar path, lane by lane.
    fn same_bits<D: Dim>() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut sliding = 0;
        let mut total = 0;
        for gamma_t in [0.0, 25.0] {
            let law = lammps_law(gamma_t);
            let k = HookeHistory::of(&law).unwrap();
            for update in [true, false] {
                for _batch in 0..40 {
                    let (cases, mut c) = batch::<D>(&mut rng, 1, 0.0);
                    let mut plain = c.clone();
                    let step = Step { dt: 1e-4, update };
                    lanes::<D, _>(&k, &mut plain, step);
                    evaluate_lanes::<D, _>(&k, &mut c, step);
                    for (l, x) in cases.iter().enumerate() {
                        let want = scalar(&law, x, step);
                        assert_eq!(lanes_out::<D>(&plain, l), want, "plain lane {l}");
                        assert_eq!(lanes_out::<D>(&c, l), want, "dispatched lane {l}");
                        let f = (0..D::D).map(|a| c.force[a][l]).collect::<Vec<_>>();
                        let n = (0..D::D).map(|a| D::get(x.del, a)).collect::<Vec<_>>();
                        let r = n.iter().map(|v| v * v).sum::<f64>().sqrt();
                        let fn_ = f.iter().zip(&n).map(|(f, n)| f * n / r).sum::<f64>();
                        let ft2 = f.iter().map(|v| v * v).sum::<f64>() - fn_ * fn_;
                        sliding += (ft2.max(0.0).sqrt() > 0.499 * fn_.abs()) as usize;
                        total += 1;
                    }
                }
            }
        }
        // Both regimes were exercised.
        assert!(
            sliding > total / 20 && sliding < total * 19 / 20,
            "{sliding} of {total} sliding"
        );
    }

    /// Runs `law` on random batches of pairs among `pairs` entries, through
    /// the plain and the dispatched kernel, against one contact at a time.
    /// The third field is [`batch`]'s stretch.
    struct SameBits<'a, D: Dim>(&'a mut Xoshiro256PlusPlus, u32, f64, PhantomData<D>);

    impl<D: Dim> crate::contact::RunLaw<()> for SameBits<'_, D> {
        fn run<L: ContactModel>(self, law: &L) {
            for update in [true, false] {
                for _ in 0..40 {
                    let (cases, mut c) = batch::<D>(self.0, self.1, self.2);
                    let mut plain = c.clone();
                    let step = Step { dt: 1e-4, update };
                    lanes::<D, _>(law, &mut plain, step);
                    evaluate_lanes::<D, _>(law, &mut c, step);
                    for (l, x) in cases.iter().enumerate() {
                        let want = scalar(law, x, step);
                        assert_eq!(lanes_out::<D>(&plain, l), want, "plain lane {l}");
                        assert_eq!(lanes_out::<D>(&c, l), want, "dispatched lane {l}");
                    }
                }
            }
        }
    }

    /// The Hertz–Mindlin law of two materials (four pair entries), with
    /// each rolling resistance, on the lanes: the same bits as one contact
    /// at a time.
    fn hertz_same_bits<D: Dim>() {
        use crate::contact::hertz_mindlin::HertzMindlin;
        use crate::contact::material::Material;
        let mat = |name: &str, e: f64, rest: f64, mu: f64| Material {
            rolling_friction: 0.1,
            ..Material::elastic(name, e, 0.25, 1.0, rest, mu)
        };
        let mats = [mat("a", 2e6, 0.8, 0.5), mat("b", 5e6, 0.6, 0.3)];
        let mut law = HertzMindlin::new(&mats, &[], vec![0, 1], vec![], true);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        use crate::contact::rolling::RollingModel;
        for model in [
            RollingModel::None,
            RollingModel::Constant,
            RollingModel::Epsd,
        ] {
            law.rolling = model;
            // One entry (the uniform batches) and four.
            for pairs in [1, 4] {
                law.with_rolling(SameBits::<D>(&mut rng, pairs, 0.0, PhantomData));
            }
        }
        // JKR (δ_c about 1e-3 of r_i + r_j here), contacts in compression and
        // kept beyond touching, without and with constant rolling.
        use crate::contact::cohesion::CohesionModel;
        let sticky = mats.map(|m| Material {
            surface_energy: 100.0,
            ..m
        });
        let law = HertzMindlin::new(&sticky, &[], vec![0, 1], vec![], true);
        let mut law = law.with_cohesion(CohesionModel::Jkr);
        for model in [RollingModel::None, RollingModel::Constant] {
            law.rolling = model;
            for pairs in [1, 4] {
                law.with_rolling(SameBits::<D>(&mut rng, pairs, 1.5e-3, PhantomData));
            }
        }
    }

    /// LAMMPS's `pair granular` preset (two materials, with and without
    /// `rolling sds`) on the lanes: the same bits as one contact at a time.
    fn granular_same_bits<D: Dim>() {
        use crate::contact::hertz_mindlin::HertzMindlin;
        use crate::contact::lammps_granular::{GranularTable, RollingSds};
        use crate::contact::material::Material;
        let mat = |name: &str, e: f64, rest: f64, mu: f64| Material {
            rolling_friction: 0.1,
            ..Material::elastic(name, e, 0.3, 1.0, rest, mu)
        };
        let mats = [mat("a", 2e6, 0.8, 0.5), mat("b", 5e6, 0.6, 0.3)];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(6);
        for rolling in [
            None,
            Some(RollingSds {
                stiffness: 500.0,
                damping: 3.0,
            }),
        ] {
            let law = HertzMindlin::new(&mats, &[], vec![0, 1], vec![], true)
                .with_lammps_granular(GranularTable::new(&mats, &[], rolling));
            for pairs in [1, 4] {
                law.with_rolling(SameBits::<D>(&mut rng, pairs, 0.0, PhantomData));
            }
        }
    }

    #[test]
    fn lammps_granular_same_bits_as_one_by_one() {
        granular_same_bits::<D3>();
        granular_same_bits::<D2>();
    }

    #[test]
    fn hertz_mindlin_same_bits_as_one_by_one() {
        hertz_same_bits::<D3>();
        hertz_same_bits::<D2>();
    }

    #[test]
    fn same_bits_as_the_scalar_kernel_3d() {
        same_bits::<D3>();
    }

    #[test]
    fn same_bits_as_the_scalar_kernel_2d() {
        same_bits::<D2>();
    }
}
