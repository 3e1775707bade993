//! Velocity Verlet in the kick–drift–kick form of LAMMPS's `nve/sphere`:
//! v += ½ dt F/m, x += dt v, ω += ½ dt τ/I; forces (with the half-step
//! velocities); v += ½ dt F/m, ω += ½ dt τ/I.
//!
//! Grains are independent, so both halves run over parallel chunks; the
//! drift also does the neighbour list's displacement test.

use super::{PassArgs, Passes, Report, SkinCheck, CHUNK};
use crate::dim::Dim;
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
        let PassArgs {
            dt,
            rotation,
            skin,
            finite,
        } = args;
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
            .enumerate()
            .map(|(c, ((pos, vel), omega))| {
                let chunk = Moving {
                    first: c * CHUNK,
                    pos,
                    vel,
                    omega,
                };
                pass_chunk::<D, CORRECT, PREDICT, CHECK>(&inputs, chunk, dt, rotation, skin, finite)
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

/// One chunk of grains: its first grain's index and its slices.
struct Moving<'a, D: Dim> {
    first: usize,
    pos: &'a mut [D::V],
    vel: &'a mut [D::V],
    omega: &'a mut [D::A],
}

/// One chunk of [`Verlet`].
#[inline(always)]
fn pass_chunk<D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool>(
    g: &Inputs<D>,
    Moving {
        first,
        pos,
        vel,
        omega,
    }: Moving<D>,
    dt: f64,
    rotation: bool,
    skin: SkinCheck<D::V>,
    finite: bool,
) -> Report {
    let half = 0.5 * dt;
    let n = pos.len();
    let range = first..first + n;
    let reference = if CHECK {
        &skin.reference[range.clone()]
    } else {
        skin.reference
    };
    // The chunk's own slices, all of length n, checked once here so that
    // the loop runs without a bounds check per array and grain.
    let (force, torque) = (&g.force[range.clone()], &g.torque[range.clone()]);
    let (inv_m, inv_i) = (&g.inv_m[range.clone()], &g.inv_i[range.clone()]);
    let frozen = &g.frozen[range];
    assert!(vel.len() == n && omega.len() == n);
    let mut out = Report::default();
    for k in 0..n {
        if CORRECT && !frozen[k] {
            vel[k] += force[k] * (half * inv_m[k]);
            if rotation {
                omega[k] += torque[k] * (half * inv_i[k]);
            }
        }
        if CORRECT && finite {
            out.note_finite::<D>(first + k, pos[k], vel[k]);
        }
        if PREDICT && !frozen[k] {
            vel[k] += force[k] * (half * inv_m[k]);
            pos[k] += vel[k] * dt;
            if rotation {
                omega[k] += torque[k] * (half * inv_i[k]);
            }
        }
        // Every grain, frozen ones too: something else may have moved them.
        if CHECK {
            out.far |= D::norm2(pos[k] - reference[k]) > skin.limit2;
        }
    }
    out
}
