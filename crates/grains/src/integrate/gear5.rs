//! Fifth-order Gear predictor–corrector (Allen & Tildesley, appendix E).
//!
//! Positions carry the scaled derivatives r_k = dt^k/k! · d^k x/dt^k for
//! k = 0..5 (r1 is kept as the velocity itself; r2..r5 live in
//! `Particles::gear`). The predictor is the Taylor step (Pascal's triangle);
//! the corrector adds c_k Δ with Δ = dt²/2 · F/m − r2(predicted) and
//! c = (3/20, 251/360, 1, 11/18, 1/6, 1/60): 3/20 rather than 3/16 because the
//! contact forces depend on the velocities.
//!
//! Angular velocities obey a first-order equation, ω' = τ/I, integrated with
//! the five-value Gear scheme for first-order equations:
//! w_k = dt^k/k! · d^k ω/dt^k for k = 0..4, c = (251/720, 1, 11/12, 1/3, 1/24).

use super::{PassArgs, Passes, Report, SkinCheck, CHUNK};
use crate::dim::Dim;
use crate::particles::Particles;
use rayon::prelude::*;

const C_POS: [f64; 6] = [
    3.0 / 20.0,
    251.0 / 360.0,
    1.0,
    11.0 / 18.0,
    1.0 / 6.0,
    1.0 / 60.0,
];
const C_ANG: [f64; 5] = [251.0 / 720.0, 1.0, 11.0 / 12.0, 1.0 / 3.0, 1.0 / 24.0];

/// Allocates the history and seeds it from the current forces (the higher
/// derivatives start at zero). Call once the forces at t = 0 are known.
pub fn initialize<D: Dim>(p: &mut Particles<D>, dt: f64) {
    p.ensure_gear_history(4, 4);
    let n = p.len();
    for k in 0..4 {
        p.gear[k].iter_mut().for_each(|g| *g = D::zero());
        p.gear_ang[k].iter_mut().for_each(|g| *g = D::A::default());
    }
    for i in 0..n.min(p.n_owned()) {
        p.gear[0][i] = p.force[i] * (0.5 * dt * dt * p.inv_mass[i]);
        p.gear_ang[0][i] = p.torque[i] * (dt * p.inv_inertia[i]);
    }
}

/// One chunk of grains: its slices of the state and of the history.
struct Chunk<'a, D: Dim> {
    first: usize,
    pos: &'a mut [D::V],
    vel: &'a mut [D::V],
    g: [&'a mut [D::V]; 4],
    omega: &'a mut [D::A],
    w: [&'a mut [D::A]; 4],
}

/// Read-only per-grain inputs.
struct Inputs<'a, D: Dim> {
    frozen: &'a [bool],
    force: &'a [D::V],
    torque: &'a [D::A],
    inv_mass: &'a [f64],
    inv_inertia: &'a [f64],
}

/// Cuts the owned grains into fixed chunks (the cut depends on the grain
/// count only, so any thread count does the same arithmetic per grain).
fn split<D: Dim>(p: &mut Particles<D>) -> (Vec<Chunk<'_, D>>, Inputs<'_, D>) {
    let n = p.n_owned();
    let [g2, g3, g4, g5] = &mut p.gear[..] else {
        panic!("gear5::initialize was not called");
    };
    let [w1, w2, w3, w4] = &mut p.gear_ang[..] else {
        panic!("gear5::initialize was not called");
    };
    let mut vel = p.vel[..n].chunks_mut(CHUNK);
    let mut omega = p.omega[..n].chunks_mut(CHUNK);
    let mut g = [g2, g3, g4, g5].map(|g| g[..n].chunks_mut(CHUNK));
    let mut w = [w1, w2, w3, w4].map(|w| w[..n].chunks_mut(CHUNK));
    let mut next = move || {
        (
            vel.next().unwrap(),
            omega.next().unwrap(),
            g.each_mut().map(|g| g.next().unwrap()),
            w.each_mut().map(|w| w.next().unwrap()),
        )
    };
    let chunks = p.pos[..n]
        .chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, pos)| {
            let (vel, omega, g, w) = next();
            Chunk {
                first: c * CHUNK,
                pos,
                vel,
                g,
                omega,
                w,
            }
        })
        .collect();
    let inputs = Inputs {
        frozen: &p.frozen[..n],
        force: &p.force[..n],
        torque: &p.torque[..n],
        inv_mass: &p.inv_mass[..n],
        inv_inertia: &p.inv_inertia[..n],
    };
    (chunks, inputs)
}

/// The Gear-5 passes of [`Integrator`](super::Integrator), each one pass over
/// the owned grains in parallel chunks: the corrector if
/// `CORRECT`, then the predictor if `PREDICT`, the displacement test if
/// `CHECK`.
pub(super) struct Gear5;

impl Passes for Gear5 {
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
        let (chunks, inputs) = split(p);
        chunks
            .into_par_iter()
            .map(|mut c| {
                if !(CORRECT && PREDICT) {
                    return pass_chunk::<D, CORRECT, PREDICT, CHECK>(
                        &mut c, &inputs, dt, rotation, skin, finite,
                    );
                }
                // Both halves in one loop keep about twenty arrays live, more
                // than the registers hold; one loop each over a tile that stays
                // in the L1 cache reads the grains from memory once all the same.
                let mut out = Report::default();
                while !c.pos.is_empty() {
                    let mut tile = c.split_front(TILE);
                    let corrected = pass_chunk::<D, true, false, false>(
                        &mut tile, &inputs, dt, rotation, skin, finite,
                    );
                    let predicted = pass_chunk::<D, false, true, CHECK>(
                        &mut tile, &inputs, dt, rotation, skin, false,
                    );
                    out = Report::join(out, Report::join(corrected, predicted));
                }
                out
            })
            .reduce(Report::default, Report::join)
    }
}

/// Grains per tile of the fused pass: their state and history (about 500
/// bytes each with rotation in 3D) fit in a 48 KB L1 cache.
const TILE: usize = 64;

impl<'a, D: Dim> Chunk<'a, D> {
    /// Cuts the first `n` grains (or all that are left) off the chunk.
    fn split_front(&mut self, n: usize) -> Chunk<'a, D> {
        let n = n.min(self.pos.len());
        fn cut<'a, T>(s: &mut &'a mut [T], n: usize) -> &'a mut [T] {
            let (front, back) = std::mem::take(s).split_at_mut(n);
            *s = back;
            front
        }
        let first = self.first;
        self.first += n;
        Chunk {
            first,
            pos: cut(&mut self.pos, n),
            vel: cut(&mut self.vel, n),
            g: self.g.each_mut().map(|g| cut(g, n)),
            omega: cut(&mut self.omega, n),
            w: self.w.each_mut().map(|w| cut(w, n)),
        }
    }
}

/// One chunk of [`Gear5`].
#[inline(always)]
fn pass_chunk<D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool>(
    c: &mut Chunk<D>,
    inputs: &Inputs<D>,
    dt: f64,
    rotation: bool,
    skin: SkinCheck<D::V>,
    finite: bool,
) -> Report {
    let half_dt2 = 0.5 * dt * dt;
    let inv_dt = 1.0 / dt;
    let len = c.pos.len();
    let range = c.first..c.first + len;
    let frozen = &inputs.frozen[range.clone()];
    let force = &inputs.force[range.clone()];
    let torque = &inputs.torque[range.clone()];
    let inv_mass = &inputs.inv_mass[range.clone()];
    let inv_inertia = &inputs.inv_inertia[range.clone()];
    let reference = if CHECK {
        &skin.reference[range]
    } else {
        skin.reference
    };
    let [g2, g3, g4, g5] = &mut c.g;
    let [w1, w2, w3, w4] = &mut c.w;
    let (g2, g3, g4, g5) = (
        &mut g2[..len],
        &mut g3[..len],
        &mut g4[..len],
        &mut g5[..len],
    );
    let (pos, vel, omega) = (&mut *c.pos, &mut c.vel[..len], &mut c.omega[..len]);
    let (w1, w2, w3, w4) = (
        &mut w1[..len],
        &mut w2[..len],
        &mut w3[..len],
        &mut w4[..len],
    );
    let mut out = Report::default();
    for k in 0..len {
        if CORRECT && !frozen[k] {
            let delta = force[k] * (half_dt2 * inv_mass[k]) - g2[k];
            pos[k] += delta * C_POS[0];
            vel[k] += delta * (C_POS[1] * inv_dt);
            g2[k] += delta;
            g3[k] += delta * C_POS[3];
            g4[k] += delta * C_POS[4];
            g5[k] += delta * C_POS[5];
            if rotation {
                let delta = torque[k] * (dt * inv_inertia[k]) - w1[k];
                omega[k] += delta * C_ANG[0];
                w1[k] += delta;
                w2[k] += delta * C_ANG[2];
                w3[k] += delta * C_ANG[3];
                w4[k] += delta * C_ANG[4];
            }
        }
        if CORRECT && finite {
            out.note_finite::<D>(c.first + k, pos[k], vel[k]);
        }
        if PREDICT && !frozen[k] {
            let (r2, r3, r4, r5) = (g2[k], g3[k], g4[k], g5[k]);
            pos[k] += vel[k] * dt + r2 + r3 + r4 + r5;
            vel[k] += (r2 * 2.0 + r3 * 3.0 + r4 * 4.0 + r5 * 5.0) * inv_dt;
            g2[k] = r2 + r3 * 3.0 + r4 * 6.0 + r5 * 10.0;
            g3[k] = r3 + r4 * 4.0 + r5 * 10.0;
            g4[k] = r4 + r5 * 5.0;
            if rotation {
                let (a1, a2, a3, a4) = (w1[k], w2[k], w3[k], w4[k]);
                omega[k] += a1 + a2 + a3 + a4;
                w1[k] = a1 + a2 * 2.0 + a3 * 3.0 + a4 * 4.0;
                w2[k] = a2 + a3 * 3.0 + a4 * 6.0;
                w3[k] = a3 + a4 * 4.0;
            }
        }
        // Every grain, frozen ones too: something else may have moved them.
        if CHECK {
            out.far |= D::norm2(pos[k] - reference[k]) > skin.limit2;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use crate::integrate::Integrator;
    use crate::particles::ParticleRecord;
    use glam::DVec2;

    /// A harmonic oscillator x'' = −x integrated over one period returns to
    /// its start with an error that falls fast with dt.
    fn period_error(dt: f64) -> f64 {
        let mut p = Particles::<D2>::new();
        p.push_record(ParticleRecord::new(0, DVec2::new(1.0, 0.0), 0.5, 1.0, 1.0));
        p.force[0] = -p.pos[0];
        let steps = (2.0 * std::f64::consts::PI / dt).round() as usize;
        let dt = 2.0 * std::f64::consts::PI / steps as f64;
        initialize(&mut p, dt);
        for _ in 0..steps {
            Integrator::Gear5.predict(&mut p, dt, false, None);
            p.force[0] = -p.pos[0];
            Integrator::Gear5.correct(&mut p, dt, false);
        }
        (p.pos[0] - DVec2::new(1.0, 0.0)).length()
    }

    #[test]
    fn harmonic_oscillator_is_high_order() {
        let e1 = period_error(0.02);
        let e2 = period_error(0.01);
        assert!(e1 < 1e-9, "{e1}");
        // Started with zero higher derivatives, the global error is fourth
        // order (measured ratio 15.9 per halving of dt).
        assert!(e1 / e2 > 12.0, "ratio {}", e1 / e2);
    }
}
