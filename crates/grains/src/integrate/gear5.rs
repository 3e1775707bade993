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

use super::tiles::{cut, moving_masks, over_tiles, pick, spread, Run, TilePass, ALL_MOVING};
use super::{PassArgs, Passes, Report, CHUNK};
use crate::dim::{components, components_mut, Dim};
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
        let (chunks, inputs) = split(p);
        chunks
            .into_par_iter()
            .with_min_len(crate::parallel::min_len(1))
            .map(|chunk| {
                let pass = GearPass::<D, CORRECT, PREDICT, CHECK> {
                    inputs: &inputs,
                    args,
                };
                let frozen = &inputs.frozen[chunk.first..chunk.first + chunk.pos.len()];
                over_tiles(&pass, chunk, frozen)
            })
            .reduce(Report::default, Report::join)
    }
}

/// The work of [`Gear5`] on one tile.
struct GearPass<'a, D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool> {
    inputs: &'a Inputs<'a, D>,
    args: PassArgs<'a, D::V>,
}

impl<'c, D: Dim, const CORRECT: bool, const PREDICT: bool, const CHECK: bool> TilePass<Chunk<'c, D>>
    for GearPass<'_, D, CORRECT, PREDICT, CHECK>
{
    #[inline(always)]
    fn tile<const MIXED: bool>(&self, mut tile: Chunk<'c, D>) -> Report {
        tile_pass::<D, CORRECT, PREDICT, CHECK, MIXED>(&mut tile, self.inputs, self.args)
    }
}

impl<'a, D: Dim> Run for Chunk<'a, D> {
    fn len(&self) -> usize {
        self.pos.len()
    }

    fn split_front(&mut self, n: usize) -> Chunk<'a, D> {
        let n = n.min(self.pos.len());
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

/// One tile of [`Gear5`]: per grain the operations of the scheme in the
/// module's comment, in the same order whatever the vector width.
#[inline(always)]
fn tile_pass<
    D: Dim,
    const CORRECT: bool,
    const PREDICT: bool,
    const CHECK: bool,
    const MIXED: bool,
>(
    t: &mut Chunk<D>,
    inputs: &Inputs<D>,
    args: PassArgs<D::V>,
) -> Report {
    let PassArgs {
        dt,
        rotation,
        skin,
        finite,
    } = args;
    let len = t.pos.len();
    let range = t.first..t.first + len;
    let frozen = &inputs.frozen[range.clone()];
    let inv_mass = &inputs.inv_mass[range.clone()];
    let inv_inertia = &inputs.inv_inertia[range.clone()];
    let half_dt2 = 0.5 * dt * dt;
    // Which components move: worked out only for a tile with frozen grains.
    let masks;
    let (moving_linear, moving_angular): (&[bool], &[bool]) = if MIXED {
        masks = moving_masks::<D>(frozen, rotation);
        (&masks[0], &masks[1])
    } else {
        (&ALL_MOVING, &ALL_MOVING)
    };
    let mut out = Report::default();
    if CORRECT {
        let factor = spread::<D::V, f64>(len, |k| half_dt2 * inv_mass[k]);
        let force = components(&inputs.force[range.clone()]);
        correct_linear::<D, MIXED>(t, force, &factor, moving_linear, 1.0 / dt);
        // Spins are left alone without rotation.
        if rotation {
            let factor = spread::<D::A, f64>(len, |k| dt * inv_inertia[k]);
            let torque = components(&inputs.torque[range.clone()]);
            correct_angular::<D, MIXED>(t, torque, &factor, moving_angular);
        }
        if finite {
            for k in 0..len {
                out.note_finite::<D>(t.first + k, t.pos[k], t.vel[k]);
            }
        }
    }
    if PREDICT {
        predict_linear::<D, MIXED>(t, moving_linear, dt);
        if rotation {
            predict_angular::<D, MIXED>(t, moving_angular);
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

/// Derivatives below this are set to zero by the corrector.
///
/// Where a grain flies free along an axis, its higher derivatives decay
/// geometrically step after step, down to subnormal numbers (below 2.2e-308),
/// and x86 processors take about a hundred times longer for arithmetic on
/// those: a few thousand such terms tripled the time of this pass on the
/// chute benchmark. A term this small is some 270 orders of magnitude below
/// the rounding of any position or velocity, so dropping it changes no
/// trajectory; it stays far enough above the subnormal range that the
/// corrector's products (coefficients down to 1/60) stay normal.
const NEGLIGIBLE: f64 = 1e-280;

/// `x`, or zero when it is negligible (see [`NEGLIGIBLE`]).
#[inline(always)]
fn flush(x: f64) -> f64 {
    if x.abs() < NEGLIGIBLE {
        0.0
    } else {
        x
    }
}

/// The corrector of positions: Δ = dt²/2 · F/m − r2 (`force` times the
/// spread `factor`), added with the coefficients `C_POS`.
#[inline(always)]
fn correct_linear<D: Dim, const MIXED: bool>(
    t: &mut Chunk<D>,
    force: &[f64],
    factor: &[f64],
    moving: &[bool],
    inv_dt: f64,
) {
    let x = components_mut(t.pos);
    let m = x.len();
    let v = &mut components_mut(t.vel)[..m];
    let [g2, g3, g4, g5] = t.g.each_mut().map(|g| &mut components_mut(g)[..m]);
    let (force, fac, moving) = (&force[..m], &factor[..m], &moving[..m]);
    let c_vel = C_POS[1] * inv_dt;
    for e in 0..m {
        let delta = force[e] * fac[e] - g2[e];
        let go = moving[e];
        x[e] = pick::<MIXED>(go, x[e] + delta * C_POS[0], x[e]);
        v[e] = pick::<MIXED>(go, v[e] + delta * c_vel, v[e]);
        g2[e] = pick::<MIXED>(go, flush(g2[e] + delta), g2[e]);
        g3[e] = pick::<MIXED>(go, flush(g3[e] + delta * C_POS[3]), g3[e]);
        g4[e] = pick::<MIXED>(go, flush(g4[e] + delta * C_POS[4]), g4[e]);
        g5[e] = pick::<MIXED>(go, flush(g5[e] + delta * C_POS[5]), g5[e]);
    }
}

/// The corrector of spins: Δ = dt · τ/I − w1, added with `C_ANG`.
#[inline(always)]
fn correct_angular<D: Dim, const MIXED: bool>(
    t: &mut Chunk<D>,
    torque: &[f64],
    factor: &[f64],
    moving: &[bool],
) {
    let w0 = components_mut(t.omega);
    let m = w0.len();
    let [w1, w2, w3, w4] = t.w.each_mut().map(|w| &mut components_mut(w)[..m]);
    let (torque, fac, moving) = (&torque[..m], &factor[..m], &moving[..m]);
    for e in 0..m {
        let delta = torque[e] * fac[e] - w1[e];
        let go = moving[e];
        w0[e] = pick::<MIXED>(go, w0[e] + delta * C_ANG[0], w0[e]);
        w1[e] = pick::<MIXED>(go, flush(w1[e] + delta), w1[e]);
        w2[e] = pick::<MIXED>(go, flush(w2[e] + delta * C_ANG[2]), w2[e]);
        w3[e] = pick::<MIXED>(go, flush(w3[e] + delta * C_ANG[3]), w3[e]);
        w4[e] = pick::<MIXED>(go, flush(w4[e] + delta * C_ANG[4]), w4[e]);
    }
}

/// The Taylor step of positions (Pascal's triangle on r0..r5).
#[inline(always)]
fn predict_linear<D: Dim, const MIXED: bool>(t: &mut Chunk<D>, moving: &[bool], dt: f64) {
    let inv_dt = 1.0 / dt;
    let x = components_mut(t.pos);
    let m = x.len();
    let v = &mut components_mut(t.vel)[..m];
    let [g2, g3, g4, g5] = t.g.each_mut().map(|g| &mut components_mut(g)[..m]);
    let moving = &moving[..m];
    for e in 0..m {
        let (r2, r3, r4, r5) = (g2[e], g3[e], g4[e], g5[e]);
        let go = moving[e];
        x[e] = pick::<MIXED>(go, x[e] + (v[e] * dt + r2 + r3 + r4 + r5), x[e]);
        v[e] = pick::<MIXED>(
            go,
            v[e] + (r2 * 2.0 + r3 * 3.0 + r4 * 4.0 + r5 * 5.0) * inv_dt,
            v[e],
        );
        g2[e] = pick::<MIXED>(go, r2 + r3 * 3.0 + r4 * 6.0 + r5 * 10.0, r2);
        g3[e] = pick::<MIXED>(go, r3 + r4 * 4.0 + r5 * 10.0, r3);
        g4[e] = pick::<MIXED>(go, r4 + r5 * 5.0, r4);
    }
}

/// The Taylor step of spins (Pascal's triangle on w0..w4).
#[inline(always)]
fn predict_angular<D: Dim, const MIXED: bool>(t: &mut Chunk<D>, moving: &[bool]) {
    let w0 = components_mut(t.omega);
    let m = w0.len();
    let [w1, w2, w3, w4] = t.w.each_mut().map(|w| &mut components_mut(w)[..m]);
    let moving = &moving[..m];
    for e in 0..m {
        let (a1, a2, a3, a4) = (w1[e], w2[e], w3[e], w4[e]);
        let go = moving[e];
        w0[e] = pick::<MIXED>(go, w0[e] + (a1 + a2 + a3 + a4), w0[e]);
        w1[e] = pick::<MIXED>(go, a1 + a2 * 2.0 + a3 * 3.0 + a4 * 4.0, a1);
        w2[e] = pick::<MIXED>(go, a2 + a3 * 3.0 + a4 * 6.0, a2);
        w3[e] = pick::<MIXED>(go, a3 + a4 * 4.0, a3);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use crate::integrate::tiles::TILE;
    use crate::integrate::Integrator;
    use crate::particles::ParticleRecord;
    use glam::{DVec2, DVec3};

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

    /// The corrector and predictor of one grain, vector by vector as the
    /// module's comment writes them: what the pass over components must
    /// reproduce bit for bit.
    fn reference_step(p: &mut Particles<D3>, i: usize, dt: f64) {
        if p.frozen[i] {
            return;
        }
        let delta = p.force[i] * (0.5 * dt * dt * p.inv_mass[i]) - p.gear[0][i];
        p.pos[i] += delta * C_POS[0];
        p.vel[i] += delta * (C_POS[1] * (1.0 / dt));
        for k in 0..4 {
            p.gear[k][i] += delta * C_POS[k + 2];
        }
        let delta = p.torque[i] * (dt * p.inv_inertia[i]) - p.gear_ang[0][i];
        p.omega[i] += delta * C_ANG[0];
        for k in 0..4 {
            p.gear_ang[k][i] += delta * C_ANG[k + 1];
        }
        let [r2, r3, r4, r5] = [0, 1, 2, 3].map(|k| p.gear[k][i]);
        p.pos[i] += p.vel[i] * dt + r2 + r3 + r4 + r5;
        p.vel[i] += (r2 * 2.0 + r3 * 3.0 + r4 * 4.0 + r5 * 5.0) * (1.0 / dt);
        p.gear[0][i] = r2 + r3 * 3.0 + r4 * 6.0 + r5 * 10.0;
        p.gear[1][i] = r3 + r4 * 4.0 + r5 * 10.0;
        p.gear[2][i] = r4 + r5 * 5.0;
        let [a1, a2, a3, a4] = [0, 1, 2, 3].map(|k| p.gear_ang[k][i]);
        p.omega[i] += a1 + a2 + a3 + a4;
        p.gear_ang[0][i] = a1 + a2 * 2.0 + a3 * 3.0 + a4 * 4.0;
        p.gear_ang[1][i] = a2 + a3 * 3.0 + a4 * 6.0;
        p.gear_ang[2][i] = a3 + a4 * 4.0;
    }

    /// The fused pass (tiles, components, the widest vectors) gives the
    /// bits of the plain per-grain scheme, frozen grains untouched, over
    /// several tiles and a ragged last one. Only the second tile has frozen
    /// grains, so both kinds of tile (with and without selections) are met.
    #[test]
    fn pass_over_components_matches_the_plain_scheme() {
        let n = 3 * TILE + 17;
        let dt = 1e-3;
        let mut p = Particles::<D3>::new();
        let wave = |i: usize, a: f64| DVec3::new((i as f64 + a).sin(), (1.3 * i as f64).cos(), a);
        for i in 0..n {
            let mut r =
                ParticleRecord::new(i as u64, wave(i, 0.0), 0.5, 1.0 + 0.01 * i as f64, 0.1);
            r.vel = wave(i, 0.5);
            r.omega = wave(i, 0.7);
            r.frozen = (TILE..2 * TILE).contains(&i) && i % 7 == 3;
            p.push_record(r);
        }
        p.force
            .iter_mut()
            .enumerate()
            .for_each(|(i, f)| *f = wave(i, 2.0));
        p.torque
            .iter_mut()
            .enumerate()
            .for_each(|(i, t)| *t = wave(i, 3.0));
        initialize(&mut p, dt);
        // Non-trivial higher derivatives.
        for k in 0..4 {
            for i in 0..n {
                p.gear[k][i] = wave(i, 4.0 + k as f64) * 1e-6;
                p.gear_ang[k][i] = wave(i, 8.0 + k as f64) * 1e-5;
            }
        }
        let mut want = p.clone();
        (0..n).for_each(|i| reference_step(&mut want, i, dt));
        Integrator::Gear5.correct_predict(&mut p, (dt, true), None, false);
        assert_eq!(p.pos, want.pos);
        assert_eq!(p.vel, want.vel);
        assert_eq!(p.omega, want.omega);
        assert_eq!(p.gear, want.gear);
        assert_eq!(p.gear_ang, want.gear_ang);
        let f = (TILE..2 * TILE).find(|i| i % 7 == 3).unwrap();
        assert!(!p.frozen[3] && p.frozen[f] && p.pos[f] == wave(f, 0.0));
    }

    /// A grain that leaves a contact flies free: its higher derivatives
    /// decay step after step. They must reach zero, never subnormal numbers
    /// (arithmetic on those is about a hundred times slower).
    #[test]
    fn free_flight_history_decays_to_zero_not_to_subnormals() {
        let dt = 1e-3;
        let mut p = Particles::<D3>::new();
        p.push_record(ParticleRecord::new(
            0,
            DVec3::new(1.0, 0.0, 0.0),
            0.5,
            1.0,
            1.0,
        ));
        p.force[0] = -p.pos[0] * 1e4;
        initialize(&mut p, dt);
        let subnormal = |p: &Particles<D3>| {
            p.gear
                .iter()
                .chain(&p.gear_ang)
                .flatten()
                .any(|v| v.to_array().iter().any(|x| *x != 0.0 && !x.is_normal()))
        };
        let mut seen = false;
        for step in 0..3000 {
            Integrator::Gear5.predict(&mut p, dt, true, None);
            // A spring for 20 steps, then free flight.
            p.force[0] = if step < 20 {
                -p.pos[0] * 1e4
            } else {
                DVec3::ZERO
            };
            p.torque[0] = if step < 20 { DVec3::X } else { DVec3::ZERO };
            Integrator::Gear5.correct(&mut p, dt, true);
            seen |= subnormal(&p);
        }
        assert!(!seen, "a subnormal derivative was stored");
        assert!(p.gear.iter().all(|g| g[0] == DVec3::ZERO), "{:?}", p.gear);
    }
}
