//! Velocity Verlet in the kick–drift–kick form of LAMMPS's `nve/sphere`:
//! v += ½ dt F/m, x += dt v, ω += ½ dt τ/I; forces (with the half-step
//! velocities); v += ½ dt F/m, ω += ½ dt τ/I.
//!
//! Grains are independent, so both halves run over parallel chunks; the
//! drift also does the neighbour list's displacement test.

use super::tiles::{cut, moving_masks, over_tiles, pick, spread, Run, TilePass, ALL_MOVING};
use super::{PassArgs, Passes, Report, CHUNK};
use crate::dim::{components, components_mut, Components, Dim};
use crate::particles::Particles;
use rayon::prelude::*;

/// The Verlet passes of [`Integrator`](super::Integrator), each one pass over
/// the owned grains in parallel chunks: the second half-kick
/// if `CORRECT`, then the first half-kick and drift if `PREDICT`, the
/// displacement test if `CHECK`.
pub(super) struct Verlet;

impl Passes for Verlet {
    fn pass<D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool>(
        p: &mut Particles<D>,
        args: PassArgs<D::V>,
    ) -> Report {
        let n = p.n_owned();
        let inputs = Inputs {
            force: &p.force,
            torque: &p.torque,
            inv_m: &p.inv_mass,
            inv_i: &p.inv_inertia,
            frozen: &p.frozen,
        };
        p.pos[..n]
            .par_chunks_mut(CHUNK)
            .zip(p.vel[..n].par_chunks_mut(CHUNK))
            .zip(p.omega[..n].par_chunks_mut(CHUNK))
            .with_min_len(crate::parallel::min_len(1))
            .enumerate()
            .map(|(c, ((pos, vel), omega))| {
                let pass = VerletPass::<D, CORRECT, PREDICT, CHECK> {
                    inputs: &inputs,
                    args,
                };
                let first = c * CHUNK;
                let frozen = &inputs.frozen[first..first + pos.len()];
                let run = Moving {
                    first,
                    pos,
                    vel,
                    omega,
                };
                over_tiles(&pass, run, frozen)
            })
            .reduce(Report::default, Report::join)
    }
}

/// Per-grain inputs of the kicks.
struct Inputs<'a, D: Dim> {
    force: &'a [D::V],
    torque: &'a [D::A],
    inv_m: &'a [f64],
    inv_i: &'a [f64],
    frozen: &'a [bool],
}

/// A run of grains: its first grain's index and its slices.
struct Moving<'a, D: Dim> {
    first: usize,
    pos: &'a mut [D::V],
    vel: &'a mut [D::V],
    omega: &'a mut [D::A],
}

/// The work of [`Verlet`] on one tile.
struct VerletPass<'a, D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool> {
    inputs: &'a Inputs<'a, D>,
    args: PassArgs<'a, D::V>,
}

impl<'c, D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool>
    TilePass<Moving<'c, D>> for VerletPass<'_, D, CORRECT, PREDICT, CHECK>
{
    #[inline(always)]
    fn tile<const MIXED: bool>(&self, tile: Moving<'c, D>) -> Report {
        tile_pass::<D, CORRECT, PREDICT, CHECK, MIXED>(tile, self.inputs, self.args)
    }
}

impl<'a, D: Dim> Run for Moving<'a, D> {
    fn len(&self) -> usize {
        self.pos.len()
    }

    fn split_front(&mut self, n: usize) -> Moving<'a, D> {
        let n = n.min(self.pos.len());
        let first = self.first;
        self.first += n;
        Moving {
            first,
            pos: cut(&mut self.pos, n),
            vel: cut(&mut self.vel, n),
            omega: cut(&mut self.omega, n),
        }
    }
}

/// One tile of [`Verlet`], component by component: per grain the
/// operations of the module's comment, in the same order whatever the
/// vector width (the second half-kick, then the first of the next step:
/// the same force, added twice).
#[inline(always)]
fn tile_pass<
    D: Dim,
    const CORRECT: bool,
    const PREDICT: bool,
    const CHECK: bool,
    const MIXED: bool,
>(
    t: Moving<D>,
    g: &Inputs<D>,
    args: PassArgs<D::V>,
) -> Report {
    let PassArgs {
        dt,
        rotation,
        skin,
        finite,
    } = args;
    let half = 0.5 * dt;
    let len = t.pos.len();
    let range = t.first..t.first + len;
    let frozen = &g.frozen[range.clone()];
    let (inv_m, inv_i) = (&g.inv_m[range.clone()], &g.inv_i[range.clone()]);
    // Which components move: worked out only for a tile with frozen grains.
    let masks;
    let (moving_linear, moving_angular): (&[bool], &[bool]) = if MIXED {
        masks = moving_masks::<D>(frozen, rotation);
        (&masks[0], &masks[1])
    } else {
        (&ALL_MOVING, &ALL_MOVING)
    };
    let mut out = Report::default();
    let kick = spread::<D::V, f64>(len, |k| half * inv_m[k]);
    let force = components(&g.force[range.clone()]);
    if CORRECT && PREDICT && !finite {
        // Both kicks and the drift in one loop: the same operations.
        kick_and_drift::<MIXED, true, true>(t.vel, t.pos, force, &kick, moving_linear, dt);
    } else {
        // The finite-state test reads the grains between the two kicks.
        if CORRECT {
            kick_and_drift::<MIXED, false, false>(t.vel, t.pos, force, &kick, moving_linear, dt);
            if finite {
                for k in 0..len {
                    out.note_finite::<D>(t.first + k, t.pos[k], t.vel[k]);
                }
            }
        }
        if PREDICT {
            kick_and_drift::<MIXED, false, true>(t.vel, t.pos, force, &kick, moving_linear, dt);
        }
    }
    if rotation {
        let spin_kick = spread::<D::A, f64>(len, |k| half * inv_i[k]);
        let w = components_mut(t.omega);
        let m = w.len();
        let torque = &components(&g.torque[range.clone()])[..m];
        let (spin_kick, moving) = (&spin_kick[..m], &moving_angular[..m]);
        let kicks = CORRECT as usize + PREDICT as usize;
        for e in 0..m {
            for _ in 0..kicks {
                w[e] = pick::<MIXED>(moving[e], w[e] + torque[e] * spin_kick[e], w[e]);
            }
        }
    }
    // Every grain, frozen ones too: something else may have moved them.
    if CHECK {
        let reference = &skin.reference[range];
        for (x, r) in t.pos.iter().zip(reference) {
            out.far |= D::norm2(*x - *r) > skin.limit2;
        }
    }
    out
}

/// Over a tile's components: the half-kick `v += F · kick` once, or twice
/// when `TWICE` (the corrector's, then the predictor's), then the drift
/// `x += v dt` if `DRIFT`; frozen grains' components kept.
#[inline(always)]
fn kick_and_drift<const MIXED: bool, const TWICE: bool, const DRIFT: bool>(
    vel: &mut [impl Components],
    pos: &mut [impl Components],
    force: &[f64],
    kick: &[f64],
    moving: &[bool],
    dt: f64,
) {
    let v = components_mut(vel);
    let m = v.len();
    let x = &mut components_mut(pos)[..m];
    let (force, kick, moving) = (&force[..m], &kick[..m], &moving[..m]);
    for e in 0..m {
        let go = moving[e];
        let mut ve = pick::<MIXED>(go, v[e] + force[e] * kick[e], v[e]);
        if TWICE {
            ve = pick::<MIXED>(go, ve + force[e] * kick[e], ve);
        }
        v[e] = ve;
        if DRIFT {
            x[e] = pick::<MIXED>(go, x[e] + ve * dt, x[e]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use crate::integrate::tiles::TILE;
    use crate::integrate::Integrator;
    use crate::particles::ParticleRecord;

    /// Grains over three and a half tiles, frozen ones only in the second
    /// tile, with forces and torques set.
    fn grains<D: Dim>(n: usize) -> Particles<D> {
        let wave =
            |i: usize, a: f64| D::from_xyz([(i as f64 + a).sin(), (1.3 * i as f64).cos(), a.cos()]);
        let spin = |i: usize, a: f64| D::ang_from_xyz([(i as f64 * a).cos(), a, (i as f64).sin()]);
        let mut p = Particles::<D>::new();
        for i in 0..n {
            let mut r =
                ParticleRecord::new(i as u64, wave(i, 0.0), 0.5, 1.0 + 0.01 * i as f64, 0.1);
            r.vel = wave(i, 0.5);
            r.omega = spin(i, 0.7);
            r.frozen = (TILE..2 * TILE).contains(&i) && i % 7 == 3;
            p.push_record(r);
        }
        for i in 0..n {
            p.force[i] = wave(i, 2.0);
            p.torque[i] = spin(i, 3.0);
        }
        p
    }

    /// The kick–drift–kick of one grain, vector by vector as the module's
    /// comment writes it: what the pass over components must reproduce bit
    /// for bit.
    fn plain<D: Dim>(p: &mut Particles<D>, i: usize, dt: f64, correct: bool, predict: bool) {
        if p.frozen[i] {
            return;
        }
        let half = 0.5 * dt;
        let kicks = correct as usize + predict as usize;
        for k in 0..kicks {
            p.vel[i] += p.force[i] * (half * p.inv_mass[i]);
            p.omega[i] += p.torque[i] * (half * p.inv_inertia[i]);
            if predict && k + 1 == kicks {
                p.pos[i] += p.vel[i] * dt;
            }
        }
    }

    fn matches_the_plain_scheme<D: Dim>() {
        let n = 3 * TILE + 17;
        let dt = 1e-3;
        let base = grains::<D>(n);
        for (correct, predict, finite) in [
            (true, true, false),
            (true, true, true),
            (true, false, false),
            (false, true, false),
        ] {
            let mut want = base.clone();
            (0..n).for_each(|i| plain(&mut want, i, dt, correct, predict));
            let mut p = base.clone();
            let v = Integrator::Verlet;
            match (correct, predict) {
                (true, true) => {
                    v.correct_predict(&mut p, (dt, true), None, finite);
                }
                (true, false) => v.correct(&mut p, dt, true),
                _ => {
                    v.predict(&mut p, dt, true, None);
                }
            }
            let case = format!("{}D, correct {correct}, predict {predict}", D::D);
            assert_eq!(p.pos, want.pos, "{case}");
            assert_eq!(p.vel, want.vel, "{case}");
            assert_eq!(p.omega, want.omega, "{case}");
            let f = (TILE..2 * TILE).find(|i| i % 7 == 3).unwrap();
            assert!(p.frozen[f] && p.pos[f] == base.pos[f] && p.vel[f] == base.vel[f]);
            assert!(p.vel[3] != base.vel[3], "{case}: a moving grain moved");
        }
    }

    /// Tiles with and without frozen grains give the bits of the plain
    /// scheme, in both dimensions, with each combination of the passes
    /// (the fused loop and the split one around the finite-state test).
    #[test]
    fn pass_over_components_matches_the_plain_scheme() {
        matches_the_plain_scheme::<D2>();
        matches_the_plain_scheme::<D3>();
    }

    /// Without rotation the spins stay as they are.
    #[test]
    fn spins_stay_without_rotation() {
        let mut p = grains::<D3>(50);
        let omega = p.omega.clone();
        Integrator::Verlet.correct_predict(&mut p, (1e-3, false), None, false);
        assert_eq!(p.omega, omega);
    }
}
