//! The Hooke-with-history kernel over a batch of contacts held in component
//! rows ("lanes"), so that the compiler turns each operation into vector
//! instructions: the square root, the two divisions and the sliding test of
//! [`HookeHistory::evaluate`] then cost a fraction of a scalar contact each.
//!
//! Every lane does exactly the operations of the scalar kernel, in the same
//! order, so the results are the same bits (a test checks it). The sliding
//! branch becomes a selection: both outcomes are computed for every lane and
//! the right one kept. Lanes past `len` hold stale values and are ignored.

use super::hooke_history::HookeHistory;
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
    /// ω_i r_i + ω_j r_j, whose cross product with n is the rolling part.
    pub spin: [Row; 3],
    pub ri: Row,
    pub rj: Row,
    /// Masses, ∞ for a frozen grain.
    pub mi: Row,
    pub mj: Row,
    /// The tangential spring; the kernel leaves the updated one here.
    pub spring: [Row; 3],
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
            ri: row,
            rj: row,
            mi: row,
            mj: row,
            spring: [row; 3],
            force: [row; 3],
            torque_i: [row; 3],
            torque_j: [row; 3],
            overlap: row,
        }
    }
}

impl HookeHistory {
    /// [`HookeHistory::evaluate`] on every lane, with the geometry of the
    /// pair loop before it (distance, normal, contact-point velocity) and
    /// the torques after it. Uses AVX-512 or AVX2 where the processor has
    /// them (same bits: no fused multiply-add is formed; a test compares
    /// the dispatched and the plain kernel).
    pub fn evaluate_lanes<D: Dim>(&self, c: &mut ContactLanes, dt: f64, update: bool) {
        simd::run_widest(&mut LawOnLanes::<D> {
            law: self,
            c,
            dt,
            update,
            dim: PhantomData,
        });
    }

    #[inline(always)]
    fn lanes<D: Dim>(&self, c: &mut ContactLanes, dt: f64, update: bool) {
        let three = D::D == 3;
        for l in 0..LANES {
            let [dx, dy, dz] = [
                c.del[0][l],
                c.del[1][l],
                if three { c.del[2][l] } else { 0.0 },
            ];
            let (ri, rj) = (c.ri[l], c.rj[l]);
            // The pair loop's geometry: r = |del|, one division for n.
            let d2 = if three {
                dx * dx + dy * dy + dz * dz
            } else {
                dx * dx + dy * dy
            };
            let r = d2.sqrt();
            let overlap = ri + rj - r;
            let inv = 1.0 / r;
            let (nx, ny, nz) = (dx * inv, dy * inv, dz * inv);
            let [wx, wy, wz] = [c.spin[0][l], c.spin[1][l], c.spin[2][l]];
            // v_rel −= ω × n (3D cross product, or the 2D spin's).
            let (cx, cy, cz) = if three {
                (wy * nz - ny * wz, wz * nx - nz * wx, wx * ny - nx * wy)
            } else {
                (-wz * ny, wz * nx, 0.0)
            };
            let vx = c.v_rel[0][l] - cx;
            let vy = c.v_rel[1][l] - cy;
            let vz = if three { c.v_rel[2][l] - cz } else { 0.0 };
            // Reduced mass, a frozen grain (∞) leaving its partner's.
            let (mi, mj) = (c.mi[l], c.mj[l]);
            let reduced = mi * mj / (mi + mj);
            let dm = if mj.is_infinite() {
                mi
            } else if mi.is_infinite() {
                mj
            } else {
                reduced
            };

            // HookeHistory::evaluate, operation for operation.
            let vn = if three {
                vx * nx + vy * ny + vz * nz
            } else {
                vx * nx + vy * ny
            };
            let fn_total = self.kn * overlap + -self.gamma_n * dm * vn;
            let (tx, ty, tz) = (vx - nx * vn, vy - ny * vn, vz - nz * vn);
            let gamma = self.gamma_t * dm;
            let (mut sx, mut sy, mut sz) = (c.spring[0][l], c.spring[1][l], c.spring[2][l]);
            if update {
                sx += tx * dt;
                sy += ty * dt;
                let along = if three {
                    sz += tz * dt;
                    sx * nx + sy * ny + sz * nz
                } else {
                    sx * nx + sy * ny
                };
                sx -= nx * along;
                sy -= ny * along;
                if three {
                    sz -= nz * along;
                }
            }
            let fx = -(sx * self.kt + tx * gamma);
            let fy = -(sy * self.kt + ty * gamma);
            let fz = -(sz * self.kt + tz * gamma);
            let cap = self.mu * fn_total.abs();
            let (fs2, s2) = if three {
                (fx * fx + fy * fy + fz * fz, sx * sx + sy * sy + sz * sz)
            } else {
                (fx * fx + fy * fy, sx * sx + sy * sy)
            };
            // Sliding: the spring cut back to the capped force (both
            // outcomes computed, one kept).
            let sliding = fs2 > cap * cap;
            let scale = cap / fs2.sqrt();
            let cut = sliding && s2 != 0.0;
            let kill = sliding && s2 == 0.0;
            let ratio = gamma / self.kt;
            let (ex, ey, ez) = (tx * ratio, ty * ratio, tz * ratio);
            let pick = |keep: f64, slid: f64| if cut { slid } else { keep };
            let (sx, sy, sz) = (
                pick(sx, (sx + ex) * scale - ex),
                pick(sy, (sy + ey) * scale - ey),
                pick(sz, (sz + ez) * scale - ez),
            );
            let zero_if = |v: f64| if kill { 0.0 } else { v };
            let (fx, fy, fz) = (
                zero_if(pick(fx, fx * scale)),
                zero_if(pick(fy, fy * scale)),
                zero_if(pick(fz, fz * scale)),
            );

            c.force[0][l] = nx * fn_total + fx;
            c.force[1][l] = ny * fn_total + fy;
            c.spring[0][l] = sx;
            c.spring[1][l] = sy;
            c.overlap[l] = overlap;
            if three {
                c.force[2][l] = nz * fn_total + fz;
                c.spring[2][l] = sz;
                // n × F_t, times each grain's radius.
                let (qx, qy, qz) = (ny * fz - fy * nz, nz * fx - fz * nx, nx * fy - fx * ny);
                c.torque_i[0][l] = qx * ri;
                c.torque_i[1][l] = qy * ri;
                c.torque_i[2][l] = qz * ri;
                c.torque_j[0][l] = qx * rj;
                c.torque_j[1][l] = qy * rj;
                c.torque_j[2][l] = qz * rj;
            } else {
                let q = nx * fy - ny * fx;
                c.torque_i[2][l] = q * ri;
                c.torque_j[2][l] = q * rj;
            }
        }
    }
}

/// [`HookeHistory::evaluate_lanes`]'s call, compiled for each instruction set.
struct LawOnLanes<'a, D> {
    law: &'a HookeHistory,
    c: &'a mut ContactLanes,
    dt: f64,
    update: bool,
    dim: PhantomData<D>,
}

impl<D: Dim> Kernel for LawOnLanes<'_, D> {
    #[inline(always)]
    fn run(&mut self) {
        self.law.lanes::<D>(self.c, self.dt, self.update);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hooke_history::lammps_law;
    use crate::dim::{D2, D3};
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// One contact as the scalar pair loop sees it.
    struct Case<D: Dim> {
        del: D::V,
        v_rel: D::V,
        spin: D::A,
        ri: f64,
        rj: f64,
        mi: f64,
        mj: f64,
        spring: D::V,
    }

    /// The scalar pair loop's geometry and kernel: force, torques on i and
    /// j (to subtract), spring, overlap.
    fn scalar<D: Dim>(k: &HookeHistory, c: &Case<D>, dt: f64, update: bool) -> [Vec<u64>; 5] {
        let r = D::norm(c.del);
        let overlap = c.ri + c.rj - r;
        let n = c.del * (1.0 / r);
        let v_rel = c.v_rel - D::ang_cross(c.spin, n);
        let mut spring = c.spring;
        let dm = HookeHistory::damping_mass(c.mi, c.mj);
        let out = k.evaluate::<D>(overlap, n, v_rel, dm, &mut spring, dt, update);
        let nt = D::torque(n, out.tangential);
        let v = |x: D::V| (0..D::D).map(|a| D::get(x, a).to_bits()).collect();
        let a = |x: D::A| D::ang_to_xyz(x).map(f64::to_bits).to_vec();
        [
            v(out.force),
            a(nt * c.ri),
            a(nt * c.rj),
            v(spring),
            vec![overlap.to_bits()],
        ]
    }

    fn lanes_out<D: Dim>(c: &ContactLanes, l: usize) -> [Vec<u64>; 5] {
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
        ]
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
                    let mut u = || rng.gen_range(-1.0..1.0);
                    let cases: Vec<Case<D>> = (0..LANES)
                        .map(|l| {
                            let v3 = |u: &mut dyn FnMut() -> f64| D::from_xyz([u(), u(), u()]);
                            let (ri, rj) = (0.5 + 0.1 * u(), 0.5 + 0.1 * u());
                            let dir = v3(&mut u);
                            let del = dir * ((ri + rj) * (1.0 - 2e-3 * (u() + 1.0)) / D::norm(dir));
                            let frozen = |m: f64, f: bool| if f { f64::INFINITY } else { m };
                            Case {
                                del,
                                v_rel: v3(&mut u) * 3.0,
                                spin: D::ang_from_xyz([u(), u(), u()]) * 2.0,
                                ri,
                                rj,
                                mi: frozen(1.0 + u().abs(), l % 9 == 4),
                                mj: frozen(1.0 + u().abs(), l % 7 == 3),
                                spring: if l % 5 == 0 {
                                    D::zero()
                                } else {
                                    v3(&mut u) * 1e-3
                                },
                            }
                        })
                        .collect();
                    let mut c = ContactLanes::default();
                    for (l, x) in cases.iter().enumerate() {
                        let spin = D::ang_to_xyz(x.spin);
                        for (a, w) in spin.into_iter().enumerate() {
                            c.spin[a][l] = w;
                            if a < D::D {
                                c.del[a][l] = D::get(x.del, a);
                                c.v_rel[a][l] = D::get(x.v_rel, a);
                                c.spring[a][l] = D::get(x.spring, a);
                            }
                        }
                        (c.ri[l], c.rj[l], c.mi[l], c.mj[l]) = (x.ri, x.rj, x.mi, x.mj);
                    }
                    let mut plain = c.clone();
                    k.lanes::<D>(&mut plain, 1e-4, update);
                    k.evaluate_lanes::<D>(&mut c, 1e-4, update);
                    for (l, x) in cases.iter().enumerate() {
                        let want = scalar(&k, x, 1e-4, update);
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

    #[test]
    fn same_bits_as_the_scalar_kernel_3d() {
        same_bits::<D3>();
    }

    #[test]
    fn same_bits_as_the_scalar_kernel_2d() {
        same_bits::<D2>();
    }
}
