//! Time integrators: the fifth-order Gear predictor–corrector the seeds used,
//! and velocity Verlet (LAMMPS's `nve/sphere`), the cheap second-order choice.
//!
//! Both split a step into a part before the forces are computed (`predict`,
//! or Verlet's first half-kick and drift) and a part after (`correct`, or the
//! second half-kick); the engine calls them around its force phase. Frozen
//! grains are never moved (nor, by the same mask, the sub-spheres of rigid
//! clumps, which `md/clumps` moves with their bodies).

pub mod gear5;
mod tiles;
pub mod velocity_verlet;

/// Grains per parallel chunk of the integrators.
const CHUNK: usize = 4096;

/// The neighbour list's displacement test, done by the integrator while it
/// moves the grains (one pass over the positions instead of two): has any
/// grain, frozen or not, moved more than `sqrt(limit2)` from where it stood
/// at the last build (`reference`, one entry per owned grain)?
#[derive(Clone, Copy, Debug)]
pub struct SkinCheck<'a, V> {
    pub reference: &'a [V],
    pub limit2: f64,
}

impl<V> SkinCheck<'_, V> {
    /// No test (the passes compiled without it ignore it).
    pub fn none() -> Self {
        SkinCheck {
            reference: &[],
            limit2: 0.0,
        }
    }
}

/// What a pass over the grains found: a grain beyond the skin, and the
/// first grain (lowest index, whatever the threads) whose state is not
/// finite when that was asked.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Report {
    pub far: bool,
    pub non_finite: Option<usize>,
}

impl Report {
    /// Two chunks' reports, in grain order.
    fn join(a: Self, b: Self) -> Self {
        Report {
            far: a.far || b.far,
            non_finite: a.non_finite.or(b.non_finite),
        }
    }

    /// Notes grain `i` if its position or velocity is not finite.
    #[inline(always)]
    fn note_finite<D: Dim>(&mut self, i: usize, pos: D::V, vel: D::V) {
        if self.non_finite.is_none() && !(D::is_finite(pos) && D::is_finite(vel)) {
            self.non_finite = Some(i);
        }
    }
}

/// An integrator as one pass over the grains, compiled for the parts it
/// runs: the corrector if `CORRECT` (then the finite-state test if
/// `finite`), the predictor if `PREDICT`, the displacement test if `CHECK`.
trait Passes {
    fn pass<D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool>(
        p: &mut Particles<D>,
        args: PassArgs<D::V>,
    ) -> Report;
}

/// What a pass is given besides the grains.
#[derive(Clone, Copy)]
struct PassArgs<'a, V> {
    dt: f64,
    rotation: bool,
    skin: SkinCheck<'a, V>,
    finite: bool,
}

/// [`Passes::pass`] with the displacement test compiled in when asked for.
fn pass<I: Passes, D: Dim, const CORRECT: bool, const PREDICT: bool>(
    p: &mut Particles<D>,
    (dt, rotation): (f64, bool),
    skin: Option<SkinCheck<D::V>>,
    finite: bool,
) -> Report {
    let args = |skin| PassArgs {
        dt,
        rotation,
        skin,
        finite,
    };
    match skin {
        Some(s) => I::pass::<D, CORRECT, PREDICT, true>(p, args(s)),
        None => I::pass::<D, CORRECT, PREDICT, false>(p, args(SkinCheck::none())),
    }
}

use crate::dim::Dim;
use crate::particles::Particles;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Fifth-order Gear predictor–corrector (Allen & Tildesley), position
    /// corrector constant 3/20 because the forces depend on velocities.
    #[default]
    Gear5,
    /// Velocity Verlet: dissipative forces see the half-step velocities.
    Verlet,
}

impl Integrator {
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Gear5 => "gear5",
            Integrator::Verlet => "verlet",
        }
    }

    /// The part before the forces (Gear-5: the Taylor prediction; Verlet:
    /// the first half-kick and the drift) on the owned grains. With `skin`,
    /// also the neighbour list's displacement test: returns whether a grain
    /// moved beyond it (false without `skin`).
    pub fn predict<D: Dim>(
        self,
        p: &mut Particles<D>,
        dt: f64,
        rotation: bool,
        skin: Option<SkinCheck<D::V>>,
    ) -> bool {
        self.pass::<D, false, true>(p, (dt, rotation), skin, false)
            .far
    }

    /// The part after the forces (Gear-5: the corrector; Verlet: the
    /// second half-kick).
    pub fn correct<D: Dim>(self, p: &mut Particles<D>, dt: f64, rotation: bool) {
        self.pass::<D, true, false>(p, (dt, rotation), None, false);
    }

    /// [`Integrator::correct`] of one step and [`Integrator::predict`] of the
    /// next in one pass over the grains (per grain the same operations in
    /// the same order, so the same bits as the two calls); with `finite`,
    /// also finds the first grain whose corrected position or velocity is
    /// not finite.
    pub fn correct_predict<D: Dim>(
        self,
        p: &mut Particles<D>,
        (dt, rotation): (f64, bool),
        skin: Option<SkinCheck<D::V>>,
        finite: bool,
    ) -> Report {
        self.pass::<D, true, true>(p, (dt, rotation), skin, finite)
    }

    fn pass<D: Dim, const CORRECT: bool, const PREDICT: bool>(
        self,
        p: &mut Particles<D>,
        step: (f64, bool),
        skin: Option<SkinCheck<D::V>>,
        finite: bool,
    ) -> Report {
        match self {
            Integrator::Gear5 => pass::<gear5::Gear5, D, CORRECT, PREDICT>(p, step, skin, finite),
            Integrator::Verlet => {
                pass::<velocity_verlet::Verlet, D, CORRECT, PREDICT>(p, step, skin, finite)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D3;
    use crate::particles::{ParticleRecord, Particles};
    use glam::DVec3;

    /// Grain k moves along x at speed k (no force), grain 0 is frozen.
    fn line(n: u64) -> Particles<D3> {
        let mut p = Particles::new();
        for k in 0..n {
            let mut r = ParticleRecord::new(k, DVec3::new(2.0 * k as f64, 0.0, 0.0), 0.5, 1.0, 0.1);
            r.vel = DVec3::new(k as f64, 0.0, 0.0);
            r.frozen = k == 0;
            p.push_record(r);
        }
        p
    }

    /// The displacement test done in the predictor answers as the neighbour
    /// list's separate pass would: a grain beyond sqrt(limit2) of its
    /// reference, frozen or not, and nothing else.
    #[test]
    fn predictors_report_grains_beyond_the_skin() {
        for integrator in [Integrator::Verlet, Integrator::Gear5] {
            let predict = |p: &mut Particles<D3>, skin: Option<SkinCheck<DVec3>>| {
                integrator.predict(p, 0.1, true, skin)
            };
            let mut p = line(10_000);
            if integrator == Integrator::Gear5 {
                gear5::initialize(&mut p, 0.1);
            }
            let reference = p.pos.clone();
            // After one step of 0.1 the fastest grain has moved 999.9: a
            // limit just below its displacement finds it, one at it does not.
            let moved = 0.1 * 9999.0;
            let check = |limit: f64| {
                Some(SkinCheck {
                    reference: &reference,
                    limit2: limit * limit,
                })
            };
            let mut q = p.clone();
            assert!(
                predict(&mut q, check(moved * (1.0 - 1e-9))),
                "{integrator:?}"
            );
            let mut q = p.clone();
            assert!(
                !predict(&mut q, check(moved * (1.0 + 1e-9))),
                "{integrator:?}"
            );
            assert!(!predict(&mut p.clone(), None));
            // A frozen grain moved by someone else is seen too.
            let mut q = p.clone();
            q.pos[0].y += 2e3;
            assert!(predict(&mut q, check(1e3)), "{integrator:?}");
            assert_eq!(q.pos[0], DVec3::new(0.0, 2e3, 0.0), "frozen grains stay");
        }
    }

    #[test]
    fn fused_pass_names_the_first_non_finite_grain_on_any_thread_count() {
        // Two bad grains in different chunks (10 000 grains span three
        // chunks of CHUNK): the report must name the lower index whatever
        // the threads, so the chunks' reports must join in order.
        for integrator in [Integrator::Verlet, Integrator::Gear5] {
            for threads in [1, 4] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut p = line(10_000);
                if integrator == Integrator::Gear5 {
                    gear5::initialize(&mut p, 0.1);
                }
                p.vel[9000].x = f64::NAN;
                p.vel[5000].x = f64::NAN;
                let report =
                    pool.install(|| integrator.correct_predict(&mut p, (0.1, true), None, true));
                assert_eq!(
                    report.non_finite,
                    Some(5000),
                    "{integrator:?}, {threads} threads"
                );
            }
        }
    }
}
