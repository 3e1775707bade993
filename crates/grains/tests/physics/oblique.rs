//! Chung & Ooi (2011) tests 4–6 on the Hertz–Mindlin law through the
//! whole engine: a sphere (Al oxide, R = 2.5 mm, μ = 0.092) hitting a
//! rigid plane obliquely, at a constant speed over the whole range of
//! incidence (test 4), at a constant normal speed with a growing
//! tangential one (test 5), and at a constant normal speed with a growing
//! initial spin (test 6), elastic (e = 1) and damped (e = 0.5).
//!
//! The reference is the same two-body problem integrated independently
//! here, from the law as docs/contact-models.md writes it (not the
//! engine's code): Hertz's normal force with Tsuji damping, Mindlin's
//! no-slip tangential stiffness k_t = 8 G* a on a Cundall–Strack spring
//! that the tangential velocity of the contact point stretches, damped by
//! α √(m* k_t), the whole capped at μ |F_n| (the spring cut back to the
//! cap while it slides), for the rigid sphere's translation and spin.
//! It is classical Runge–Kutta at h = t_c/1e5 with the cap applied after
//! each step; the cap's switches are resolved to one step, 1e-5 t_c.
//! Chung & Ooi compare codes with Maw, Barber & Fawcett's (1976) analysis
//! of Mindlin–Deresiewicz partial slip; this law has no partial slip
//! within the contact area, so in the sticking regime it is the
//! independent integration of this law, not MBF's curves, that gives the
//! expected numbers. In the gross-sliding regime both reduce to
//! rigid-body theory, v_t' = v_t − 2 μ v_n and ω' R = 5 μ v_n when elastic,
//! which the test checks on the reference as well (damped, the normal
//! force's attractive tail adds to the friction impulse, see [`compare`]).
//!
//! Tolerance: the engine's step is t_c/2000. Elastic, its rebound is the
//! reference's within 6e-6 of the incident speed (measured); with damping
//! (e = 0.5) velocity Verlet takes the damping force at the predicted
//! velocity, an error first order in dt/t_c, and the normal rebound
//! differs by 7e-5 at t_c/2000; the damped collisions run at t_c/8000
//! (see [`engine`]). Held to 5e-5 of the incident speed, except the
//! damped tangential rebound and spin, 1e-3 ([`engine`] says why). A
//! Mindlin stiffness off by 2× moves the sticking rebound by tens of per
//! cent; tangential damping left out moves the e = 0.5 ones.

use super::chung_ooi::{collide, hertz, material, rigid, sphere_mass, tsuji_alpha_hm, Body};
use glam::DVec3;
use grains::contact::hertz_mindlin::HertzMindlin;

const E: f64 = 3.8e11;
const NU: f64 = 0.23;
const RHO: f64 = 4000.0;
const MU: f64 = 0.092;
const R: f64 = 0.0025;

/// The rebound (v_t', v_n', ω' R) of the reference integration of a sphere
/// arriving with tangential speed `vt`, normal speed `vn` (towards the
/// plane) and spin `spin` = ω R about the axis that rolls it along +x.
fn reference(vt: f64, vn: f64, spin: f64, rest: f64) -> [f64; 3] {
    let m = sphere_mass(RHO, R);
    let inertia = 0.4 * m * R * R;
    // The rigid plane enters neither E* nor G*: E* = E/(1 − ν²),
    // G* = G/(2 − ν) with G = E/(2(1 + ν)) (Johnson 1985, Mindlin 1949).
    let e_s = E / (1.0 - NU * NU);
    let g_s = E / (2.0 * (1.0 + NU)) / (2.0 - NU);
    let alpha = if rest < 1.0 {
        tsuji_alpha_hm(rest)
    } else {
        0.0
    };
    let (_, _, t_c) = hertz(m, R, e_s, vn);
    let h = t_c / 1e5;
    // State: overlap x, its rate u, centre's tangential speed v, spin
    // w = ω R (positive rolls along +x), spring s (the contact point's
    // tangential displacement over the plane).
    // Forces for a state: (F_n, F_t) and the cap, with the spring as given.
    let forces = |x: f64, u: f64, v: f64, w: f64, s: f64| {
        let x = x.max(0.0);
        let a = (R * x).sqrt();
        let sn = 2.0 * e_s * a;
        let f_n = 2.0 / 3.0 * sn * x + alpha * (m * sn).sqrt() * u;
        let kt = 8.0 * g_s * a;
        let gt = alpha * (m * kt).sqrt();
        // The contact point moves at v − ω R over the plane.
        let slip = v - w;
        let trial = -(kt * s + gt * slip);
        let cap = MU * f_n.abs();
        let f_t = if trial.abs() > cap {
            cap * trial.signum()
        } else {
            trial
        };
        (f_n, f_t, kt, gt, slip, cap)
    };
    let deriv = |y: [f64; 5]| {
        let [x, u, v, w, s] = y;
        let (f_n, f_t, _, _, slip, _) = forces(x, u, v, w, s);
        // ẋ = u; m u̇ = −F_n; m v̇ = F_t; I ω̇ = −R F_t, so ẇ = −R² F_t / I;
        // ṡ = slip.
        [u, -f_n / m, f_t / m, -R * R * f_t / inertia, slip]
    };
    let mut y = [0.0, vn, vt, spin, 0.0];
    let mut t = 0.0;
    loop {
        let add = |y: [f64; 5], k: [f64; 5], c: f64| std::array::from_fn(|i| y[i] + c * k[i]);
        let k1 = deriv(y);
        let k2 = deriv(add(y, k1, 0.5 * h));
        let k3 = deriv(add(y, k2, 0.5 * h));
        let k4 = deriv(add(y, k3, h));
        let next: [f64; 5] =
            std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        if next[0] <= 0.0 {
            // Separation within the step: interpolate to x = 0.
            let f = y[0] / (y[0] - next[0]);
            let at: [f64; 5] = std::array::from_fn(|i| y[i] + f * (next[i] - y[i]));
            return [at[2], -at[1], at[3]];
        }
        y = next;
        // Sliding: the spring is cut back to the cap.
        let (_, _, kt, gt, slip, cap) = forces(y[0], y[1], y[2], y[3], y[4]);
        let trial = kt * y[4] + gt * slip;
        if trial.abs() > cap && kt > 0.0 {
            let damp = gt * slip / kt;
            y[4] = (y[4] + damp) * (cap / trial.abs()) - damp;
        }
        t += h;
        assert!(t < 10.0 * t_c, "the reference never separates");
    }
}

/// The engine's rebound (v_t', v_n', ω' R) for the same arrival.
/// Damped, at dt = t_c/8000 rather than t_c/2000: the damped normal force
/// changes sign just before the grain leaves (Tsuji damping pulls), so the
/// Coulomb cap μ |F_n| passes through zero and cuts the spring there,
/// while k_t → 0 makes the spring's share of the damped force singular;
/// at t_c/2000 the step that lands nearest that instant decides how much
/// of the spring is left (3.8e-3 of the speed in the spin at 10°,
/// e = 0.5), at t_c/8000 within 1e-4 of the reference. The reference
/// itself moves by 4e-4 of the speed between h = t_c/1e4 and t_c/1e6 at
/// v_t = 0.1 m/s: the damped tangential rebound and spin are held to 1e-3
/// of the incident speed, the rest to 5e-5.
fn engine(vt: f64, vn: f64, spin: f64, rest: f64) -> [f64; 3] {
    let fine = if rest < 1.0 { 8.0 } else { 1.0 };
    let mats = [material("Al oxide", E, NU, RHO, rest, MU), rigid()];
    let m = sphere_mass(RHO, R);
    let (_, _, t_c) = hertz(m, R, E / (1.0 - NU * NU), vn);
    let law = HertzMindlin::new(&mats, &[], vec![0], vec![1], true);
    let mut a = Body::new(R, RHO, 0, DVec3::new(vt, 0.0, -vn));
    a.omega = DVec3::new(0.0, spin / R, 0.0);
    let out = collide(law, a, None, t_c / fine);
    [out.vel[0].x, out.vel[0].z, out.omega[0].y * R]
}

/// Compares the engine with the reference for each arrival, within 2e-3
/// of `scale` (the incident speed), and checks the rigid-body limits where
/// the sphere slides throughout.
fn compare(arrivals: &[(f64, f64, f64)], rest: f64, scale: f64, what: &str) {
    for &(vt, vn, spin) in arrivals {
        let want = reference(vt, vn, spin, rest);
        let got = engine(vt, vn, spin, rest);
        for (k, name) in ["v_t'", "v_n'", "ω'R"].iter().enumerate() {
            let tol = if k != 1 && rest < 1.0 { 1e-3 } else { 5e-5 };
            assert!(
                (got[k] - want[k]).abs() < tol * scale,
                "{what}, e = {rest}, v_t {vt}, v_n {vn}, ωR {spin}: {name} {:.6} against {:.6}",
                got[k],
                want[k]
            );
        }
        // One tangential impulse J turns and slows the grain: Δ(ω R) =
        // (5/2) J/m and Δv_t = −J/m (angular momentum about the contact
        // point kept; the engine's own bookkeeping, to rounding).
        let turned = got[2] - spin;
        assert!(
            (turned - 2.5 * (vt - got[0])).abs() < 1e-6 * scale,
            "{what}: impulse {turned} against {}",
            2.5 * (vt - got[0])
        );
        // Energy: the law's tangential spring −k_t(a) s with a stiffness
        // that falls as the contact unloads gives back up to 1e-5 of the
        // energy more than it took (measured in the reference as in the
        // engine: LAMMPS's `mindlin` without `rescale` does the same), so
        // the gain is held to the reference's within 2e-4 of the energy
        // (the normal rebound's tolerance) and below 3e-5.
        let energy = |v: f64, u: f64, w: f64| v * v + u * u + 0.4 * w * w;
        let before = energy(vt, vn, spin);
        let gain = energy(got[0], got[1], got[2]) / before - 1.0;
        let gain_ref = energy(want[0], want[1], want[2]) / before - 1.0;
        assert!(
            (gain - gain_ref).abs() < 2e-4 && gain < 3e-5,
            "{what}: energy gained {gain:e}, reference {gain_ref:e}"
        );
        // Elastic gross sliding (the slip never reverses): rigid-body
        // theory is exact. It holds where |v_t − ωR| > (7/2) μ (1 + e) v_n.
        // Damped, the normal force turns attractive before the grain
        // leaves and the cap μ |F_n| then adds to the friction impulse, so
        // rigid-body theory does not hold.
        if rest == 1.0 && (vt - spin).abs() > 1.1 * 7.0 * MU * vn {
            let j = MU * (vn + want[1]) * (vt - spin).signum();
            assert!(
                (want[0] - (vt - j)).abs() < 1e-4 * scale,
                "{what}: rigid v_t"
            );
            assert!(
                (want[2] - (spin + 2.5 * j)).abs() < 1e-4 * scale,
                "{what}: rigid ωR"
            );
        }
    }
}

/// Test 4: 3.9 m/s at incidences from 2° to 88° from the normal; sticking
/// below about 33° (tan θ < (7/2) μ (1 + e)), sliding above.
#[test]
fn test4_oblique_impact_over_the_whole_range_of_incidence() {
    let v = 3.9;
    let arrivals: Vec<_> = [
        2.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 45.0, 60.0, 75.0, 88.0,
    ]
    .iter()
    .map(|deg: &f64| {
        let th = deg.to_radians();
        (v * th.sin(), v * th.cos(), 0.0)
    })
    .collect();
    for rest in [1.0, 0.5] {
        compare(&arrivals, rest, v, "test 4");
    }
}

/// Test 5: a constant normal speed of 1 m/s, tangential speeds from 0.02
/// to 2 m/s (Ψ = v_t / (μ v_n) from 0.2 to 22).
#[test]
fn test5_constant_normal_speed_growing_tangential_speed() {
    let arrivals: Vec<_> = [0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0]
        .iter()
        .map(|&vt| (vt, 1.0, 0.0))
        .collect();
    for rest in [1.0, 0.5] {
        compare(&arrivals, rest, 1.0, "test 5");
    }
}

/// Test 6: a constant normal speed of 1 m/s, no tangential speed, an
/// initial spin ω R from 0.02 to 2 m/s (the contact point slips at
/// −ω R).
#[test]
fn test6_constant_normal_speed_growing_spin() {
    let arrivals: Vec<_> = [0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0]
        .iter()
        .map(|&spin| (0.0, 1.0, spin))
        .collect();
    for rest in [1.0, 0.5] {
        compare(&arrivals, rest, 1.0, "test 6");
    }
}

/// The grazing impact of LAMMPS PR 5007 (μ = 0.5, 76° from the normal,
/// elastic normal), Al oxide at 3.9 m/s, grain on grain (the two mirrored:
/// each at 3.9 m/s): no energy gained, and the pair's angular momentum
/// about its centre kept (1e-3, as the lever arms allow: 2e-4 measured;
/// the lever arms are the radii, not the distances to a common contact
/// point, so the pair's torque about its centre is −ξ n × F_t, of order
/// ξ/R = 2e-4 of the momentum exchanged).
#[test]
fn grazing_impact_of_two_grains_gains_no_energy() {
    let mu = 0.5;
    let mats = [material("Al oxide", E, NU, RHO, 1.0, mu), rigid()];
    let m = sphere_mass(RHO, R);
    let th = 76f64.to_radians();
    let v = 3.9;
    let (vt, vn) = (v * th.sin(), v * th.cos());
    // The pair: reduced mass m/2, radius R/2, modulus E/(2(1 − ν²)), 2v_n.
    let (_, _, t_c) = hertz(0.5 * m, 0.5 * R, E / (2.0 * (1.0 - NU * NU)), 2.0 * vn);
    let law = HertzMindlin::new(&mats, &[], vec![0, 0], vec![1], true);
    let a = Body::new(R, RHO, 0, DVec3::new(vt, 0.0, -vn));
    let b = Body::new(R, RHO, 0, DVec3::new(-vt, 0.0, vn));
    let out = collide(law, a, Some(b), t_c);
    let energy = |vel: DVec3, w: DVec3| {
        0.5 * m * vel.length_squared() + 0.2 * m * R * R * w.length_squared()
    };
    // The pair is point-symmetric: grain b has grain a's energy.
    let before = energy(a.vel, DVec3::ZERO);
    assert!(
        energy(out.vel[0], out.omega[0]) <= before * (1.0 + 1e-9),
        "energy grew"
    );
    // L_y = m (z v_x − x v_z) + I ω_y, per grain (the pair's is twice).
    let l = |x: DVec3, v: DVec3, w: f64| m * (x.z * v.x - x.x * v.z) + 0.4 * m * R * R * w;
    let x0 = DVec3::new(0.0, 0.0, R * (1.0 + 1e-3));
    let l0 = l(x0, a.vel, 0.0);
    let l1 = l(out.pos[0], out.vel[0], out.omega[0].y);
    assert!(
        (l1 / l0 - 1.0).abs() < 1e-3,
        "angular momentum {l1} against {l0}"
    );
    assert!(out.omega[0].y * R > 0.5 * mu * vn, "no spin");
}
