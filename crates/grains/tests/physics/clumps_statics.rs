//! Rigid clumps at rest on an incline, against statics: a rod lying along
//! the slope slides when tan θ > μ, and a tower stands until its centre of
//! mass passes over the downhill edge of its base, tan θ > b/h.
//!
//! The incline is the floor z = 0 with gravity turned by θ about y, so that
//! the slope runs down along +x: g = g (sin θ, 0, −cos θ). The tilt is
//! brought up from 0 to θ over a ramp slow against the contacts' and the
//! body's rocking periods (a quasi-static tilt, so that no released spring
//! or impact decides the outcome), then held. Each angle is 3° from its
//! threshold, on either side.

use super::clumps::{big_box, floor, hooke, rod, settings, spec, sphere_mass, R};
use glam::DVec3;
use grains::md::Md;
use grains::rigid::{Shape, SubSphere};
use grains::{Particles, D3};

const G: f64 = 9.81;

/// What one tilt did: the centre of mass's downhill velocity when the hold
/// began and ended, its displacement over the hold, the largest angle the
/// body turned by, and the hold's length.
struct Tilted {
    v_start: f64,
    v_end: f64,
    moved: f64,
    turned: f64,
    hold: f64,
}

/// A body of `shape` put at rest with its centre of mass at `pos` on the
/// floor, the tilt ramped from 0 to `theta` over `ramp` seconds and held
/// `hold` seconds, friction `mu` on the floor (linear spring–dashpot with
/// the Cundall–Strack spring).
fn tilt(shape: Shape<D3>, pos: DVec3, theta: f64, mu: f64, ramp: f64, hold: f64) -> Tilted {
    let (kn, gamma_n, dt) = (1e4, 1e4, 2e-6);
    let mut law = hooke(kn, gamma_n);
    law.kt = 2.0 / 7.0 * kn;
    law.gamma_t = 0.5 * gamma_n;
    law.mu = mu;
    law.rotation = true;
    let mut s = settings(law, dt);
    s.gravity = DVec3::new(0.0, 0.0, -G);
    let mut md = Md::new(Particles::new(), big_box(), floor(), s).unwrap();
    let q0 = [1.0, 0.0, 0.0, 0.0];
    md.add_bodies(vec![shape], vec![spec(pos, q0, DVec3::ZERO, DVec3::ZERO)])
        .unwrap();
    let turned = |md: &Md<D3>| {
        let q = md.bodies().unwrap().bodies[0].quat;
        let dot: f64 = q.iter().zip(q0).map(|(a, b)| a * b).sum();
        2.0 * dot.abs().min(1.0).acos()
    };
    // The tilt is raised every `chunk` steps, in steps of θ/(ramp/chunk dt).
    let chunk = 100;
    let ramp_chunks = (ramp / (chunk as f64 * dt)).round() as u64;
    let mut worst: f64 = 0.0;
    for k in 1..=ramp_chunks {
        let a = theta * k as f64 / ramp_chunks as f64;
        md.settings.gravity = DVec3::new(G * a.sin(), 0.0, -G * a.cos());
        md.run(chunk).unwrap();
        worst = worst.max(turned(&md));
    }
    let b = md.bodies().unwrap().bodies[0];
    let (x0, v_start) = (b.pos.x, b.vel.x);
    let hold_chunks = (hold / (chunk as f64 * dt)).round() as u64;
    for _ in 0..hold_chunks {
        md.run(chunk).unwrap();
        worst = worst.max(turned(&md));
    }
    let b = md.bodies().unwrap().bodies[0];
    Tilted {
        v_start,
        v_end: b.vel.x,
        moved: b.pos.x - x0,
        turned: worst,
        hold: hold_chunks as f64 * chunk as f64 * dt,
    }
}

/// A rod of three touching spheres lying along the slope (its axis along
/// x, every sphere on the floor). Statics: the floor's normal forces sum to
/// N = M g cos θ and the friction it can give is at most μ N, while
/// holding the rod takes M g sin θ: it stays while tan θ ≤ μ and slides
/// when tan θ > μ, then at the Coulomb rate a = g (sin θ − μ cos θ) (the
/// three contacts slide together, each capped at μ N_i). Lying along the
/// slope it cannot roll (a roll about y would lift it). μ = 0.5: threshold
/// atan 0.5 = 26.57°, tested at 23.57° and 29.57°.
///
/// Held to: sliding, at least R over the hold and its mean acceleration
/// within 1e-4 of the
/// Coulomb rate (velocity Verlet on a constant force is exact; the normal
/// springs' settling wobble, damped at ζ ≈ 0.45, is long gone after the
/// ramp); sticking, a creep over the 0.1 s hold below 1e-6 R (the spring's
/// whole stretch M g sin θ/(3 k_t) is 4e-5 R) and no turn beyond 1e-4 rad
/// (the friction's moment M g sin θ · r loads the downhill sphere more: the
/// springs tilt the rod by about M g sin θ/(8 k_n r) = 1.5e-6 rad).
/// Planted: the Coulomb cap doubled (the 29.57° rod sticks, fails).
#[test]
fn a_rod_along_the_slope_slides_when_tan_theta_exceeds_mu() {
    let mu: f64 = 0.5;
    let threshold = mu.atan();
    let pos = DVec3::new(0.0, 0.0, R);
    for delta in [-3.0f64, 3.0] {
        let theta = threshold + delta.to_radians();
        let t = tilt(rod(), pos, theta, mu, 0.05, 0.1);
        let a = (t.v_end - t.v_start) / t.hold;
        let coulomb = G * (theta.sin() - mu * theta.cos());
        eprintln!(
            "rod at {:.2}° (threshold {:.2}°): moved {:.3e} R over the hold, a = {a:.6e} \
             (Coulomb {coulomb:.6e}), turned {:.2e} rad",
            theta.to_degrees(),
            threshold.to_degrees(),
            t.moved / R,
            t.turned
        );
        if delta < 0.0 {
            assert!(t.moved.abs() < 1e-6 * R, "sticks: moved {:e} m", t.moved);
            assert!(t.turned < 1e-4, "stays flat: turned {:e} rad", t.turned);
        } else {
            assert!(t.moved > R, "slides: moved {:e} m", t.moved);
            assert!(
                (a / coulomb - 1.0).abs() < 1e-4,
                "slides at {a}, Coulomb {coulomb}"
            );
        }
    }
}

/// A tower of eight touching spheres of radius r: a square base of four
/// at (±r, ±r, 0) and a column of four above its centre at
/// z = √2 r + 2 r j (j = 0..3; the lowest touches all four of the base,
/// √(2r² + 2r²) = 2r). Touching spheres do not overlap, so M = 8 m_s, the
/// centre of mass is the mean of the centres, z̄ = (4√2 + 12) r / 8 above
/// the base's centres, and the inertia is the spheres' own (2/5 m_s r²)
/// plus the parallel axes; the shape is symmetric under x ↦ −x, y ↦ −y and
/// the swap of x and y, so x, y, z are its principal axes.
///
/// Returns the shape and the height h of its centre of mass above the
/// floor when it stands on its base.
fn tower() -> (Shape<D3>, f64) {
    let ms = sphere_mass();
    let mut centers: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(x * R, y * R, 0.0))
        .collect();
    centers.extend((0..4).map(|j| DVec3::new(0.0, 0.0, (2f64.sqrt() + 2.0 * j as f64) * R)));
    let zbar = (4.0 * 2f64.sqrt() + 12.0) * R / 8.0;
    let mut inertia = [0.0; 3];
    for c in &mut centers {
        c.z -= zbar;
        let own = 0.4 * ms * R * R;
        inertia[0] += own + ms * (c.y * c.y + c.z * c.z);
        inertia[1] += own + ms * (c.x * c.x + c.z * c.z);
        inertia[2] += own + ms * (c.x * c.x + c.y * c.y);
    }
    let spheres = centers
        .into_iter()
        .map(|center| SubSphere { center, radius: R })
        .collect();
    let shape = Shape {
        name: "tower".into(),
        spheres,
        mass: 8.0 * ms,
        inertia,
    };
    (shape, R + zbar)
}

/// The tower standing on its base, μ = 1 (sliding would need tan θ > 1,
/// far beyond). Statics: the floor holds it by normal forces at the base
/// spheres' lowest points, x = ±r, and the friction there; about the
/// downhill edge x = +r the weight's moment is M g (h sin θ − r cos θ)
/// (the friction and the normal forces at the edge have no arm), so the
/// uphill contacts must pull once h sin θ > r cos θ, which they cannot: it
/// topples when tan θ > b/h with b = r, h = r + z̄ = (1 + (4√2 + 12)/8) r,
/// atan(1/3.207) = 17.31°. Tested at 14.31° and 20.31°; the normal
/// springs' overlap (M g/(4 k_n) ≈ 2e-5 r) moves the edge and the height
/// by far less than the 3° margin.
///
/// Decided by the largest angle the body turned over the ramp and 0.15 s
/// held: toppled beyond 0.5 rad; standing within 1e-3 rad (the springs'
/// tilt, of order the overlap over r, 2e-5), its creep over the hold
/// within 1e-5 r. Planted: each sub-sphere's own
/// torque (the friction's moment about its centre) left out of the body's,
/// which puts the friction at the centres' height and the threshold at
/// atan(1/(h − r)) = 24.4° (the 20.31° tower stands, fails).
#[test]
fn a_tower_topples_when_its_centre_of_mass_passes_the_edge() {
    let (shape, h) = tower();
    let threshold = (R / h).atan();
    let mu = 1.0;
    let pos = DVec3::new(0.0, 0.0, h);
    for delta in [-3.0f64, 3.0] {
        let theta = threshold + delta.to_radians();
        let t = tilt(shape.clone(), pos, theta, mu, 0.05, 0.15);
        eprintln!(
            "tower at {:.2}° (threshold {:.2}°): turned {:.3e} rad, moved {:.3e} R over the hold",
            theta.to_degrees(),
            threshold.to_degrees(),
            t.turned,
            t.moved / R
        );
        if delta < 0.0 {
            assert!(t.turned < 1e-3, "stands: turned {:e} rad", t.turned);
            assert!(t.moved.abs() < 1e-5 * R, "stays: moved {:e} m", t.moved);
        } else {
            assert!(t.turned > 0.5, "topples: turned {:e} rad", t.turned);
        }
    }
}
