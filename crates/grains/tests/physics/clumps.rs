//! Rigid clumps through the whole engine: free rotation against Euler's
//! equations, a dimer's bounce on a frictionless plane against the closed
//! form of an impulsive collision, the same bits on any thread count and
//! across a checkpoint.
//!
//! The shapes are made by hand from closed forms: a dimer of two equal
//! touching spheres of mass m_s and radius r, centres at ±r along its axis,
//! has M = 2 m_s, I_axis = 2·(2/5) m_s r² and
//! I_perp = 2·((2/5) m_s r² + m_s r²) (parallel axes).

use glam::DVec3;
use grains::boundary::{Motion, Shape as WallShape, Wall};
use grains::codec::{Dec, Enc};
use grains::contact::law::ContactLaw;
use grains::contact::mass_scaling::MassScaling;
use grains::domain::Domain;
use grains::md::codec::{decode_md, encode_md};
use grains::md::{Md, MdSettings};
use grains::rigid::no_squish;
use grains::rigid::{BodySpec, Shape, SubSphere};
use grains::{ParticleRecord, Particles, D3};
use std::f64::consts::PI;

pub(super) const R: f64 = 1e-3;
pub(super) const RHO: f64 = 2500.0;

pub(super) fn sphere_mass() -> f64 {
    RHO * 4.0 / 3.0 * PI * R.powi(3)
}

/// The dimer along body axis `axis` (0: x, 2: z).
fn dimer(axis: usize) -> Shape<D3> {
    let ms = sphere_mass();
    let (along, perp) = (
        2.0 * 0.4 * ms * R * R,
        2.0 * (0.4 * ms * R * R + ms * R * R),
    );
    let mut inertia = [perp; 3];
    inertia[axis] = along;
    let c = DVec3::from_array(std::array::from_fn(|a| if a == axis { R } else { 0.0 }));
    Shape {
        name: "dimer".into(),
        spheres: vec![
            SubSphere {
                center: c,
                radius: R,
            },
            SubSphere {
                center: -c,
                radius: R,
            },
        ],
        mass: 2.0 * ms,
        inertia,
    }
}

/// A linear spring–dashpot without friction: k (N/m), damping γ_n (1/s)
/// times the damping mass.
pub(super) fn hooke(kn: f64, gamma_n: f64) -> ContactLaw {
    ContactLaw {
        kn,
        beta: 1.0,
        gamma_n,
        gamma_t: 0.0,
        kt: 0.0,
        mu: 0.0,
        scaling: MassScaling::Reduced,
        rotation: true,
    }
}

pub(super) fn settings(law: ContactLaw, dt: f64) -> MdSettings<D3> {
    let mut s = MdSettings::<D3>::new(dt, law, 0.2 * R);
    s.integrator = grains::integrate::Integrator::Verlet;
    s
}

pub(super) fn floor() -> Vec<Wall<D3>> {
    let plane = WallShape::Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    vec![Wall::new("floor", plane, Motion::Fixed).unwrap()]
}

pub(super) fn big_box() -> Domain<D3> {
    Domain::new(DVec3::splat(-0.1), DVec3::splat(0.1), [false; 3])
}

pub(super) fn spec(pos: DVec3, orientation: [f64; 4], vel: DVec3, omega: DVec3) -> BodySpec<D3> {
    BodySpec {
        shape: 0,
        kind: 1,
        pos,
        orientation,
        vel,
        omega,
    }
}

/// Quaternion of a turn by `angle` about the unit `axis`.
pub(super) fn turn(axis: DVec3, angle: f64) -> [f64; 4] {
    let (s, c) = (0.5 * angle).sin_cos();
    [c, s * axis.x, s * axis.y, s * axis.z]
}

/// A lone symmetric top (the dimer along z: I1 = I2 = I_perp, I3 =
/// I_axis) in free rotation through the engine: in the body frame ω_perp
/// turns about the axis at Ω = (I3 − I1)/I1 · ω3 (Euler's equations;
/// Landau & Lifshitz, Mechanics §33). After two precession periods at 2000
/// steps per period the phase is held to 1e-4 rad (the splitting's phase
/// error is O((ω dt)²) per unit time: about 2e-5 rad here); ω3 stays to
/// 1e-6 and the energy to 1e-8 (the splitting's bounded O((ω dt)²)
/// wobble, (ω dt)² = 2e-5 here, times a small constant), |L| to 1e-8. The sub-spheres sit at X ± R e3 and move
/// at v + ω × r. Planted: I1 and I3 swapped in the body's shape (the phase
/// runs the other way, fails).
#[test]
fn dimer_precesses_at_the_euler_rate_through_the_engine() {
    let shape = dimer(2);
    let [i1, _, i3] = shape.inertia;
    let (w1, w3) = (30.0, 200.0);
    let big_omega = (i3 - i1) / i1 * w3;
    let period = 2.0 * PI / big_omega.abs();
    let dt = period / 2000.0;
    let q0 = turn(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.7);
    let r0 = no_squish::matrix(q0);
    let omega = r0 * DVec3::new(w1, 0.0, w3);
    let law = hooke(1e3, 0.0);
    let mut md = Md::new(Particles::new(), big_box(), Vec::new(), settings(law, dt)).unwrap();
    let body = spec(DVec3::ZERO, q0, DVec3::new(0.01, 0.0, 0.0), omega);
    md.add_bodies(vec![shape.clone()], vec![body]).unwrap();
    assert_eq!(md.particles.len(), 2);
    let rot0 = md.rotational_energy();
    let want_e = 0.5 * (i1 * w1 * w1 + i3 * w3 * w3);
    assert!((rot0 / want_e - 1.0).abs() < 1e-12, "½ L·ω of the spin");
    let l0 = md.bodies().unwrap().bodies[0].ang_mom.length();
    let mut worst: f64 = 0.0;
    for s in 1..=4000 {
        md.step().unwrap();
        let b = md.bodies().unwrap();
        let body = b.bodies[0];
        let w = no_squish::matrix(body.quat).transpose() * b.omega(0);
        let d = (w.y.atan2(w.x) - big_omega * s as f64 * dt).rem_euclid(2.0 * PI);
        worst = worst.max(d.min(2.0 * PI - d));
        assert!((w.z / w3 - 1.0).abs() < 1e-6, "ω3 stays: {}", w.z);
    }
    let b = md.bodies().unwrap();
    let body = b.bodies[0];
    eprintln!("precession: worst phase error {worst:e} rad over two periods");
    assert!(worst < 1e-4, "phase error {worst:e} rad");
    let de = md.rotational_energy() / rot0 - 1.0;
    let dl = body.ang_mom.length() / l0 - 1.0;
    eprintln!("precession: ΔE/E {de:e}, Δ|L|/|L| {dl:e} after 4000 steps");
    assert!(de.abs() < 1e-8 && dl.abs() < 1e-8);
    // The sub-spheres where and as fast as the body says.
    let r = no_squish::matrix(body.quat);
    let w = b.omega(0);
    for (k, sign) in [(0usize, 1.0), (1, -1.0)] {
        let arm = r * DVec3::new(0.0, 0.0, sign * R);
        let i = md
            .particles
            .id
            .iter()
            .position(|&id| id == 1 + k as u64)
            .unwrap();
        assert!((md.particles.pos[i] - (body.pos + arm)).length() < 1e-15);
        let v = body.vel + w.cross(arm);
        assert!((md.particles.vel[i] - v).length() < 1e-12 * v.length());
        assert_eq!(md.particles.omega[i], w);
    }
}

/// What a dimer leaves the floor with: (velocity, spin) of its body.
fn bounce(tilt: f64, v0: f64, kn: f64, gamma_n: f64) -> (DVec3, DVec3, f64) {
    let shape = dimer(0);
    let m = shape.mass;
    let m_eff = m / 2.0; // two contacts in parallel, or one at a lever
    let t_c = PI / (kn / m_eff).sqrt();
    let dt = t_c / 2000.0;
    let mut md = Md::new(
        Particles::new(),
        big_box(),
        floor(),
        settings(hooke(kn, gamma_n), dt),
    )
    .unwrap();
    // Its lowest point 1e-3 R above the floor.
    let q = turn(DVec3::Y, tilt);
    let z = R * tilt.sin() + R + 1e-3 * R;
    let body = spec(
        DVec3::new(0.0, 0.0, z),
        q,
        DVec3::new(0.0, 0.0, -v0),
        DVec3::ZERO,
    );
    md.add_bodies(vec![shape], vec![body]).unwrap();
    let mut touched = false;
    for _ in 0..(200.0 * t_c / dt) as u64 {
        md.step().unwrap();
        touched |= md.stats.contacts > 0;
        if touched && md.stats.contacts == 0 {
            break;
        }
    }
    assert!(touched && md.stats.contacts == 0, "it bounced off");
    let b = md.bodies().unwrap();
    (b.bodies[0].vel, b.omega(0), t_c)
}

/// The restitution of a linear spring–dashpot on effective mass m_eff
/// with damping coefficient c: e = exp(−π ζ / √(1 − ζ²)), ζ = c / (2√(k
/// m_eff)) (the damped oscillator's half period).
fn restitution(kn: f64, c: f64, m_eff: f64) -> f64 {
    let zeta = c / (2.0 * (kn * m_eff).sqrt());
    (-PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
}

/// Dropped flat on a frictionless floor, the dimer bounces without
/// turning: both contacts alike, their torques about the centre of mass
/// cancel (the spin stays 0 to round-off). Each contact damps with the
/// body's mass M (the damping mass of a sub-sphere is its body's, as LAMMPS
/// takes it): two contacts k, γM in parallel on mass M give
/// e = exp(−πζ/√(1−ζ²)), ζ = 2γM / (2√(2kM)); at dt = t_c/2000 velocity
/// Verlet's error on e is below 1e-4, held to 1e-3. Planted: the sub-sphere's
/// own mass (M/2) as damping mass, e moves by 10 % (fails).
#[test]
fn a_flat_dimer_bounces_without_turning() {
    let (kn, gamma_n, v0) = (1e4, 2000.0, 0.1);
    let m = dimer(0).mass;
    let (v, w, _) = bounce(0.0, v0, kn, gamma_n);
    let e = restitution(2.0 * kn, 2.0 * gamma_n * m, m);
    eprintln!(
        "flat dimer: v_z = {:.6e} (e v0 = {:.6e}), |ω| = {:e}",
        v.z,
        e * v0,
        w.length()
    );
    assert!(w.length() < 1e-9, "no spin: {w}");
    assert!(
        (v.z / (e * v0) - 1.0).abs() < 1e-3,
        "e {} against {e}",
        v.z / v0
    );
    assert!(v.x.abs() < 1e-12 && v.y.abs() < 1e-12);
}

/// Dropped tilted by α about y, the dimer touches with its lower sphere
/// only: lever arm ρ from the centre of mass to the contact point, normal
/// n = z. The impulse of a collision of restitution e is
/// J = −(1+e) v_n / (1/M + (ρ×n)²/I), so v' = v + J n / M and
/// ω' = I⁻¹ (ρ × J n), with (ρ×n)² = R² cos²α and I = I_perp. The contact
/// damps with c = γM on the effective mass m_eff = 1/(1/M + (ρ×n)²/I),
/// which sets e. The soft contact lasts t_c, during which the body turns by
/// Δθ ≈ ω' t_c/2 and the lever arm changes by tan α · Δθ relative: the
/// tolerance is 4 tan α Δθ (here about 1e-3) plus Verlet's 1e-4. Planted:
/// the lever arm's sign flipped in the torque sum (ω' reversed, fails).
#[test]
fn a_tilted_dimer_leaves_with_the_spin_of_its_impulse() {
    let (kn, gamma_n, v0, tilt) = (1e6, 2e4, 0.1, PI / 6.0);
    let shape = dimer(0);
    let (m, i_perp) = (shape.mass, shape.inertia[1]);
    let arm = R * tilt.cos();
    let m_eff = 1.0 / (1.0 / m + arm * arm / i_perp);
    let e = restitution(kn, gamma_n * m, m_eff);
    let j = (1.0 + e) * v0 * m_eff;
    let want_v = -v0 + j / m;
    // ρ = (R cos α, 0, −R sin α − R) from the centre to the lower sphere's
    // contact (turning by +α about y lowers the sphere at +R on the body's x).
    let rho = DVec3::new(R * tilt.cos(), 0.0, -R * tilt.sin() - R);
    let want_w = rho.cross(DVec3::new(0.0, 0.0, j)) / i_perp;
    let (v, w, _) = bounce(tilt, v0, kn, gamma_n);
    let t_c = PI / (kn / m_eff).sqrt();
    let turned = want_w.length() * t_c / 2.0;
    let tol = 4.0 * tilt.tan() * turned + 1e-4;
    eprintln!(
        "tilted dimer: e = {e:.5}, v_z {:.6e} want {want_v:.6e}, ω_y {:.6e} want {:.6e}, \
         Δθ {turned:.2e}, tol {tol:.1e}",
        v.z, w.y, want_w.y
    );
    assert!(
        (v.z / want_v - 1.0).abs() < tol,
        "v_z {} against {want_v}",
        v.z
    );
    assert!(
        (w.y / want_w.y - 1.0).abs() < tol,
        "ω_y {} against {}",
        w.y,
        want_w.y
    );
    assert!(w.x.abs() < 1e-9 * w.y.abs() && w.z.abs() < 1e-9 * w.y.abs());
}

/// Dimers and spheres poured on a floor with friction and gravity: the
/// engine and its state after `steps` steps on `threads` threads, with a
/// checkpoint's round trip through the bytes at `resume` if given.
fn pile(threads: usize, steps: u64, resume: Option<u64>) -> (Vec<u8>, Md<D3>) {
    let build = || {
        let ms = sphere_mass();
        let mut p = Particles::<D3>::new();
        for k in 0..6u64 {
            let x = DVec3::new(-0.008 + 0.003 * k as f64, 0.0005 * k as f64, 0.007);
            let mut g = ParticleRecord::new(100 + k, x, R, ms, 0.4 * ms * R * R);
            g.vel = DVec3::new(0.0, 0.0, -0.5);
            p.push_record(g);
        }
        let mut law = hooke(1e3, 5000.0);
        law.kt = 2.0 / 7.0 * 1e3;
        law.mu = 0.5;
        let mut s = settings(law, 2e-6);
        // Fifty g, so that the pile settles within the test's 12 ms.
        s.gravity = DVec3::new(0.0, 0.0, -490.0);
        let mut md = Md::new(p, big_box(), floor(), s).unwrap();
        let bodies = (0..8)
            .map(|k| {
                let x = DVec3::new(
                    -0.012 + 0.0045 * k as f64,
                    0.0002 * k as f64,
                    0.0021 + 0.0006 * (k % 3) as f64,
                );
                let q = turn(DVec3::new(1.0, k as f64, 0.5).normalize(), 0.3 * k as f64);
                spec(
                    x,
                    q,
                    DVec3::new(0.0, 0.0, -0.5),
                    DVec3::new(5.0, -3.0, k as f64),
                )
            })
            .collect();
        md.add_bodies(vec![dimer(0)], bodies).unwrap();
        md
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut md = build();
        if let Some(at) = resume {
            md.run(at).unwrap();
            let mut e = Enc::default();
            encode_md(&mut e, &md.export_state().unwrap());
            let state = decode_md::<D3>(&mut Dec::new(&e.buf)).unwrap();
            md = build();
            md.import_state(state).unwrap();
            md.run(steps - at).unwrap();
        } else {
            md.run(steps).unwrap();
        }
        let mut e = Enc::default();
        encode_md(&mut e, &md.export_state().unwrap());
        (e.buf, md)
    })
}

/// The same bits on one and two threads, and through a checkpoint taken
/// mid-run (the state's bytes, the bodies' section included, compared
/// whole). The pile must have touched: contacts between bodies, spheres
/// and the floor, and the pair list must hold no pair within a body.
/// Planted: the bodies' section left out of the state (the resumed run
/// differs, fails).
#[test]
fn clumps_give_the_same_bits_on_any_threads_and_through_a_checkpoint() {
    let steps = 6000;
    let (one, md) = pile(1, steps, None);
    let (two, _) = pile(2, steps, None);
    let (resumed, _) = pile(1, steps, Some(2500));
    let e = md.kinetic_energy() + md.rotational_energy();
    eprintln!(
        "pile: {} contacts, kinetic energy {e:e} J",
        md.stats.contacts
    );
    assert!(one == two, "1 and 2 threads differ");
    assert!(one == resumed, "the resumed run differs");
    assert!(
        md.stats.contacts > 8,
        "the pile touches: {}",
        md.stats.contacts
    );
    let ties = md.grain_bodies().unwrap();
    let list = md.export_state().unwrap().list;
    for [i, j] in list.pairs {
        let (a, b) = (ties[i as usize], ties[j as usize]);
        assert!(a.is_none() || a != b, "a pair within body {a:?}");
    }
}

/// Gear-5 with clumps is refused by name.
#[test]
fn gear5_with_clumps_is_refused_by_name() {
    let mut s = settings(hooke(1e3, 0.0), 1e-6);
    s.integrator = grains::integrate::Integrator::Gear5;
    let mut md = Md::new(Particles::new(), big_box(), Vec::new(), s).unwrap();
    let body = spec(DVec3::ZERO, [1.0, 0.0, 0.0, 0.0], DVec3::ZERO, DVec3::ZERO);
    let err = md.add_bodies(vec![dimer(0)], vec![body]).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("run.integrator") && msg.contains("verlet"),
        "{msg}"
    );
}

/// A symmetric top (I1 = I2 ≠ I3) in free rotation: in the body frame
/// ω_perp turns about the symmetry axis at Ω = (I3 − I1)/I1 · ω3 (Euler's
/// equations; Landau & Lifshitz, Mechanics §33), ω3 constant: the body
/// store's integrator alone. Over one precession period in 4000 steps the
/// phase must match within 1e-4 rad (the splitting's error is O((ω dt)²)
/// per unit time); ω3 stays within 1e-6 (the splitting's O((ω dt)²)
/// wobble, 7e-6 here times a small constant). Planted I1/I3 swap in the
/// rotation: the phase runs backwards (fails).
#[test]
fn the_rotation_integrator_precesses_a_symmetric_top_at_the_euler_rate() {
    let inertia: [f64; 3] = [1.0, 1.0, 1.6];
    let (w3, w1): (f64, f64) = (2.0, 0.3);
    let big_omega = (inertia[2] - inertia[0]) / inertia[0] * w3;
    let period = 2.0 * PI / big_omega.abs();
    let steps = 4000;
    let dt = period / steps as f64;
    let mut q = turn(DVec3::new(0.1, -0.2, 0.3).normalize(), 0.9);
    let r = no_squish::matrix(q);
    let mut l = r * DVec3::new(inertia[0] * w1, 0.0, inertia[2] * w3);
    let mut worst: f64 = 0.0;
    for s in 1..=steps {
        no_squish::free_rotation(&mut q, &mut l, inertia, dt);
        let w = no_squish::matrix(q).transpose() * no_squish::omega(q, l, inertia);
        let phase = w.y.atan2(w.x);
        let want = big_omega * s as f64 * dt;
        let d = (phase - want).rem_euclid(2.0 * PI);
        worst = worst.max(d.min(2.0 * PI - d));
        assert!((w.z / w3 - 1.0).abs() < 1e-6, "ω3 stays: {}", w.z);
    }
    eprintln!("rotation integrator: worst phase error {worst:e} rad over a period");
    assert!(worst < 1e-4, "phase error {worst:e} rad");
}

/// The tennis-racket (Dzhanibekov) flip: spun near its intermediate
/// axis, an asymmetric body turns that axis over again and again, while
/// the energy and |L| are kept: over 10⁶ steps both within 1e-8
/// relative (NO_SQUISH is symplectic: no drift, only a bounded
/// oscillation of order (ω dt)²).
#[test]
fn intermediate_axis_flips_while_energy_and_momentum_stay() {
    let inertia = [1.0, 2.0, 3.0];
    let mut q = [1.0, 0.0, 0.0, 0.0];
    let w = DVec3::new(1e-3, 1.0, 1e-3);
    let mut l = DVec3::new(w.x * inertia[0], w.y * inertia[1], w.z * inertia[2]);
    let (e0, l0) = (no_squish::rotational_energy(q, l, inertia), l.length());
    let dt = 1e-4;
    let (mut flips, mut last_sign) = (0, 1.0);
    let (mut de, mut dl): (f64, f64) = (0.0, 0.0);
    for s in 0..1_000_000 {
        no_squish::free_rotation(&mut q, &mut l, inertia, dt);
        if s % 100 == 0 {
            let axis = no_squish::matrix(q).col(1);
            let sign = axis.dot(l).signum();
            if sign != last_sign {
                flips += 1;
                last_sign = sign;
            }
            de = de.max((no_squish::rotational_energy(q, l, inertia) / e0 - 1.0).abs());
            dl = dl.max((l.length() / l0 - 1.0).abs());
        }
    }
    eprintln!("tennis racket: {flips} flips, |ΔE/E| ≤ {de:e}, |Δ|L|/|L|| ≤ {dl:e}");
    assert!(flips >= 2, "the intermediate axis flips ({flips})");
    assert!(de < 1e-8 && dl < 1e-8, "ΔE {de:e}, Δ|L| {dl:e}");
}

/// The tilted bounce in 2D: a dimer of two touching disks (mass m_d = ρπR²
/// each, unit thickness; I_z = 2 (½ m_d R² + m_d R²)) turned by α about z
/// falls on the line y = 0 and leaves with the impulse's closed form, as
/// in 3D: the body turns about z only, and its energy is ½MV² + ½ I_z ω².
#[test]
fn a_tilted_disk_dimer_leaves_with_the_spin_of_its_impulse() {
    use glam::DVec2;
    use grains::D2;
    // A disk of unit thickness is 700 times heavier than the sphere: a
    // stiffer contact for the same contact time and damping ratio.
    let (kn, gamma_n, v0, tilt) = (1e9, 2.4e4, 0.1, PI / 6.0);
    let md_mass = RHO * PI * R * R;
    let (m, i_z) = (2.0 * md_mass, 3.0 * md_mass * R * R);
    let c = DVec2::new(R, 0.0);
    let shape = Shape::<D2> {
        name: "disk dimer".into(),
        spheres: vec![
            SubSphere {
                center: c,
                radius: R,
            },
            SubSphere {
                center: -c,
                radius: R,
            },
        ],
        mass: m,
        inertia: [0.0, 0.0, i_z],
    };
    let arm = R * tilt.cos();
    let m_eff = 1.0 / (1.0 / m + arm * arm / i_z);
    let e = restitution(kn, gamma_n * m, m_eff);
    let j = (1.0 + e) * v0 * m_eff;
    let want_v = -v0 + j / m;
    // Turned by +α about z, the sphere at −R on the body's x is the lower:
    // ρ = (−R cos α, −R sin α − R), torque ρ × J ŷ = −R cos α J.
    let want_w = -R * tilt.cos() * j / i_z;
    let t_c = PI / (kn / m_eff).sqrt();
    let dt = t_c / 2000.0;
    let line = WallShape::Plane {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    };
    let walls = vec![Wall::new("line", line, Motion::Fixed).unwrap()];
    let mut s = MdSettings::<D2>::new(dt, hooke(kn, gamma_n), 0.2 * R);
    s.integrator = grains::integrate::Integrator::Verlet;
    let domain = Domain::new(DVec2::splat(-0.1), DVec2::splat(0.1), [false; 3]);
    let mut md = Md::new(Particles::new(), domain, walls, s).unwrap();
    let body = BodySpec::<D2> {
        shape: 0,
        kind: 1,
        pos: DVec2::new(0.0, R * tilt.sin() + R + 1e-3 * R),
        orientation: turn(DVec3::Z, tilt),
        vel: DVec2::new(0.0, -v0),
        omega: 0.0,
    };
    md.add_bodies(vec![shape], vec![body]).unwrap();
    let mut touched = false;
    for _ in 0..(200.0 * t_c / dt) as u64 {
        md.step().unwrap();
        touched |= md.stats.contacts > 0;
        if touched && md.stats.contacts == 0 {
            break;
        }
    }
    assert!(touched && md.stats.contacts == 0, "it bounced off");
    let b = md.bodies().unwrap();
    let (v, w) = (b.bodies[0].vel, b.omega(0));
    let turned = want_w.abs() * t_c / 2.0;
    let tol = 4.0 * tilt.tan() * turned + 1e-4;
    eprintln!(
        "2D tilted dimer: v_y {:.6e} want {want_v:.6e}, ω_z {:.6e} want {want_w:.6e}, tol {tol:.1e}",
        v.y, w.z
    );
    assert!((v.y / want_v - 1.0).abs() < tol);
    assert!((w.z / want_w - 1.0).abs() < tol);
    assert!(w.x == 0.0 && w.y == 0.0 && v.z == 0.0);
    let energy = 0.5 * m * v.length_squared() + 0.5 * i_z * w.z * w.z;
    let got = md.kinetic_energy() + md.rotational_energy();
    assert!((got / energy - 1.0).abs() < 1e-12, "{got} against {energy}");
}

/// A rod of three touching spheres along body x (centres at −2R, 0, 2R):
/// M = 3 m_s, I_axis = 3 · (2/5) m_s R², I_perp = 3 · (2/5) m_s R² +
/// 2 m_s (2R)² (parallel axes).
pub(super) fn rod() -> Shape<D3> {
    let ms = sphere_mass();
    let along = 3.0 * 0.4 * ms * R * R;
    let perp = along + 2.0 * ms * 4.0 * R * R;
    let spheres = [-2.0, 0.0, 2.0]
        .iter()
        .map(|&s| SubSphere {
            center: DVec3::new(s * R, 0.0, 0.0),
            radius: R,
        })
        .collect();
    Shape {
        name: "rod".into(),
        spheres,
        mass: 3.0 * ms,
        inertia: [along, perp, perp],
    }
}

/// The dump of a few steps of two free spheres and, with `bodies`, three
/// rods dropped on the floor, with the VTK frame of the same step.
fn dump_of_a_small_run(bodies: bool) -> (String, String) {
    let ms = sphere_mass();
    let mut p = Particles::<D3>::new();
    for k in 0..2u64 {
        let x = DVec3::new(-0.01 + 0.02 * k as f64, 0.0, 0.003);
        p.push_record(ParticleRecord::new(100 + k, x, R, ms, 0.4 * ms * R * R));
    }
    let mut s = settings(hooke(1e3, 5000.0), 2e-6);
    s.gravity = DVec3::new(0.0, 0.0, -9.81);
    let mut md = Md::new(p, big_box(), floor(), s).unwrap();
    if bodies {
        let specs = (0..3)
            .map(|k| {
                let x = DVec3::new(-0.006 + 0.006 * k as f64, 0.0, 0.0015 + 0.001 * k as f64);
                let q = turn(DVec3::new(0.3, k as f64, 1.0).normalize(), 0.7 * k as f64);
                spec(x, q, DVec3::ZERO, DVec3::new(k as f64, 2.0, -1.0))
            })
            .collect();
        md.add_bodies(vec![rod()], specs).unwrap();
    }
    md.run(200).unwrap();
    let frame = md.frame();
    let mut buf = Vec::new();
    grains::io::write_snapshot(&mut buf, &frame).unwrap();
    (
        String::from_utf8(buf).unwrap(),
        grains::io::vtp_string(&frame),
    )
}

/// With bodies the dump ends each row with a `mol` column (OVITO's
/// molecule id): 0 for the two free spheres, and each rod's three
/// sub-spheres share one id, their centres 2R apart in a line (end to end
/// 4R, to round-off of the written digits) as the rod's shape puts them.
/// The VTK frame carries the same ids as a `body` point array. A run
/// without bodies keeps the dump's columns and the frame's arrays as they
/// were. Planted: the body numbered from 0 (free spheres then share
/// body 1's id, fails).
#[test]
fn dumps_group_each_clumps_spheres_by_mol() {
    let (dump, vtp) = dump_of_a_small_run(true);
    let mut lines = dump.lines().skip_while(|l| !l.starts_with("ITEM: ATOMS"));
    let header = lines.next().unwrap();
    assert_eq!(header, "ITEM: ATOMS id type radius x y z vx vy vz mol");
    let mut groups: std::collections::BTreeMap<u64, Vec<(u64, DVec3)>> = Default::default();
    for l in lines {
        let t: Vec<&str> = l.split(' ').collect();
        assert_eq!(t.len(), 10, "row {l}");
        let x = DVec3::new(
            t[3].parse().unwrap(),
            t[4].parse().unwrap(),
            t[5].parse().unwrap(),
        );
        groups
            .entry(t[9].parse().unwrap())
            .or_default()
            .push((t[0].parse().unwrap(), x));
    }
    assert_eq!(groups.keys().copied().collect::<Vec<_>>(), [0, 1, 2, 3]);
    let mut free: Vec<u64> = groups[&0].iter().map(|g| g.0).collect();
    free.sort();
    assert_eq!(free, [100, 101]);
    for b in 1..=3 {
        let g = &groups[&b];
        assert_eq!(g.len(), 3, "body {b}: {g:?}");
        let mut d: Vec<f64> = [(0, 1), (0, 2), (1, 2)]
            .iter()
            .map(|&(i, j)| g[i].1.distance(g[j].1))
            .collect();
        d.sort_by(f64::total_cmp);
        for (got, want) in d.iter().zip([2.0 * R, 2.0 * R, 4.0 * R]) {
            assert!((got - want).abs() < 1e-9 * R, "body {b}: {d:?}");
        }
    }
    assert!(vtp.contains("Name=\"body\""));

    let (dump, vtp) = dump_of_a_small_run(false);
    assert!(dump.contains("ITEM: ATOMS id type radius x y z vx vy vz\n"));
    assert!(!dump.contains("mol"));
    assert!(!vtp.contains("Name=\"body\""));
}
