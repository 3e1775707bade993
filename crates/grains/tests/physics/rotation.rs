//! Rotation against closed forms: rolling without slipping down an
//! incline, angular momentum in a frictional gas, and the order of
//! Gear-5's spin corrector.

use crate::common;

use common::*;
use glam::{DVec2, DVec3};
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::{ContactLaw, MassScaling};
use grains::integrate::{gear5, Integrator};
use grains::md::{Md, MdSettings};
use grains::{Dim, MassModel, ParticleRecord, Particles, D2, D3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// A grain of diameter 1 and density 1 on a plane tilted by θ (gravity
/// turned instead), with friction strong enough to roll it: its mean
/// acceleration down the slope over the second half of `t` seconds.
fn rolling<D: Dim>(model: MassModel, theta: f64, t: f64) -> f64 {
    let g = 9.81;
    let kn = 1.0e6;
    let law = ContactLaw {
        kt: 2.0 / 7.0 * kn,
        gamma_t: 250.0,
        mu: 1.0,
        rotation: true,
        ..hooke(kn, 500.0, MassScaling::Reduced)
    };
    let r = 0.5;
    let m = model.mass(1.0, 2.0 * r);
    let mut gr = ParticleRecord::<D>::new(0, D::unit(D::vertical()) * r, r, m, model.inertia(m, r));
    // Start at the static overlap, at rest.
    D::set(&mut gr.pos, D::vertical(), r - m * g * theta.cos() / kn);
    let mut s = MdSettings::<D>::new(2e-5, law, 0.1);
    s.integrator = Integrator::Verlet;
    s.gravity = D::unit(0) * (g * theta.sin()) - D::unit(D::vertical()) * (g * theta.cos());
    let mut p = Particles::new();
    p.push_record(gr);
    let floor = Wall::new(
        "incline",
        Shape::Plane {
            point: D::zero(),
            normal: D::unit(D::vertical()),
        },
        Motion::Fixed,
    )
    .unwrap();
    let mut md = Md::new(p, open_box(1.0e3), vec![floor], s).unwrap();
    let steps = (t / md.settings.dt) as u64;
    md.run(steps / 2).unwrap();
    let (v1, t1) = (D::get(md.particles.vel[0], 0), md.time);
    md.run(steps - steps / 2).unwrap();
    let (v2, t2) = (D::get(md.particles.vel[0], 0), md.time);
    // Rolling, not slipping: the contact point is at rest, v = ω r.
    let w = D::ang_to_xyz(md.particles.omega[0]);
    let spin = w[0].abs().max(w[1].abs()).max(w[2].abs());
    assert!(
        (spin * r - v2).abs() < 1e-3 * v2,
        "{}: slips, v = {v2}, ω r = {}",
        D::NAME,
        spin * r
    );
    (v2 - v1) / (t2 - t1)
}

#[test]
fn sphere_and_disk_roll_down_an_incline_at_the_closed_form_rate() {
    // a = g sin θ / (1 + I / m r²): 5/7 g sin θ for a sphere (I = 2/5 m r²),
    // 2/3 g sin θ for a disk (I = 1/2 m r²). The spring's start-up
    // oscillation is damped (γ_t) long before the second half; what is left
    // is the lever arm r against r − δ (δ/r ≈ 1e-5) and round-off
    // (measured: 1e-12).
    let theta = 20f64.to_radians();
    let g_sin = 9.81 * theta.sin();
    let sphere = rolling::<D3>(MassModel::Sphere, theta, 0.4);
    assert!(
        (sphere / (5.0 / 7.0 * g_sin) - 1.0).abs() < 1e-5,
        "sphere: {sphere}, expected {}",
        5.0 / 7.0 * g_sin
    );
    let disk = rolling::<D2>(MassModel::Disk, theta, 0.4);
    eprintln!(
        "rolling: sphere {:.2e}, disk {:.2e} relative error",
        sphere / (5.0 / 7.0 * g_sin) - 1.0,
        disk / (2.0 / 3.0 * g_sin) - 1.0
    );
    assert!(
        (disk / (2.0 / 3.0 * g_sin) - 1.0).abs() < 1e-5,
        "disk: {disk}, expected {}",
        2.0 / 3.0 * g_sin
    );
}

/// Total angular momentum about the origin, orbital plus spin.
fn angular_momentum<D: Dim>(md: &Md<D>) -> D::A {
    let p = &md.particles;
    (0..p.len()).fold(D::A::default(), |l, i| {
        l + D::torque(p.pos[i], p.vel[i] * p.mass[i]) + p.omega[i] * p.inertia[i]
    })
}

fn ang_norm<D: Dim>(a: D::A) -> f64 {
    D::ang_dot(a, a).sqrt()
}

/// A cloud of polydisperse grains in open space, falling in on itself
/// (velocities towards the centre plus a random part), without spin.
fn cloud<D: Dim>(n: usize, radius: f64, seed: u64) -> Vec<ParticleRecord<D>> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut out: Vec<ParticleRecord<D>> = Vec::new();
    while out.len() < n {
        let d = rng.gen_range(0.7..1.3);
        let mut x = D::zero();
        for a in 0..D::D {
            D::set(&mut x, a, rng.gen_range(-radius..radius));
        }
        if D::norm(x) > radius || out.iter().any(|q| D::norm(q.pos - x) < q.radius + 0.5 * d) {
            continue;
        }
        let mut g = grain::<D>(out.len() as u64, x, d);
        g.vel = x * -0.6;
        for a in 0..D::D {
            let v = D::get(g.vel, a) + rng.gen_range(-0.5..0.5);
            D::set(&mut g.vel, a, v);
        }
        out.push(g);
    }
    out
}

fn angular_momentum_in_frictional_gas<D: Dim>() {
    let kn = 1.0e7;
    let law = ContactLaw {
        kt: 2.0 / 7.0 * kn,
        gamma_t: 0.0,
        mu: 0.5,
        rotation: true,
        ..hooke(kn, 100.0, MassScaling::Reduced)
    };
    let mut md = engine(
        cloud::<D>(60, 4.0, 7),
        open_box(100.0),
        MdSettings::new(2.0e-5, law, 0.1),
    );
    let l0 = angular_momentum(&md);
    let p = &md.particles;
    // Scale of the angular momenta involved: Σ m |x| |v|.
    let scale: f64 = (0..p.len())
        .map(|i| p.mass[i] * D::norm(p.pos[i]) * D::norm(p.vel[i]))
        .sum();
    let spin0: f64 = (0..p.len()).map(|i| ang_norm::<D>(p.omega[i])).sum();
    assert_eq!(spin0, 0.0);
    md.run(100_000).unwrap();
    let p = &md.particles;
    // Friction acted: the grains spin, with a share of the kinetic energy.
    let rot: f64 = (0..p.len())
        .map(|i| 0.5 * p.inertia[i] * D::ang_dot(p.omega[i], p.omega[i]))
        .sum();
    assert!(
        rot > 1e-3 * p.kinetic_energy(),
        "{}: no frictional collisions? rotational {rot}, translational {}",
        D::NAME,
        p.kinetic_energy()
    );
    // Contact forces are equal and opposite and their torques act with lever
    // arms r_i and r_j (LAMMPS's convention), not the distances r_i − δ/2 to
    // the contact point: each contact leaves a torque δ n × F_t, so the
    // total drifts by a fraction of order δ/d of the tangential angular
    // impulse. Here δ/d ≲ 5e-4 (kn = 1e7, speeds ≈ 2 m/s, m ≈ 0.5 kg), and
    // the tangential impulses are below the scale Σ m|x||v|; a sign or
    // factor error in any torque would move L by a sizeable part of it.
    // Measured: 3e-6 (3D) and 3e-7 (2D) of the scale.
    let l1 = angular_momentum(&md);
    let drift = ang_norm::<D>(l1 - l0);
    eprintln!(
        "{}: L drift / scale {:.2e}, rotational / translational energy {:.2e}",
        D::NAME,
        drift / scale,
        rot / p.kinetic_energy()
    );
    assert!(
        drift < 5e-5 * scale,
        "{}: angular momentum {:?} -> {:?} (drift {drift:.3e}, scale {scale:.3e})",
        D::NAME,
        l0,
        l1
    );
}

#[test]
fn angular_momentum_is_conserved_in_a_frictional_gas_3d() {
    angular_momentum_in_frictional_gas::<D3>();
}

#[test]
fn angular_momentum_is_conserved_in_a_frictional_gas_2d() {
    angular_momentum_in_frictional_gas::<D2>();
}

/// Gear-5 on y' = ẑ × y (a vector turning at 1 rad/s) for one turn, with y
/// the velocity (a force −m ẑ × v... as a velocity-dependent force) or the
/// spin (a torque I ẑ × ω): the error of y after one turn.
fn gear_turn_error(dt: f64, spin: bool) -> f64 {
    let mut p = Particles::<D3>::new();
    let mut g = ParticleRecord::new(0, DVec3::ZERO, 0.5, 2.0, 0.3);
    let y0 = DVec3::new(1.0, 0.0, 0.0);
    if spin {
        g.omega = y0;
    } else {
        g.vel = y0;
    }
    p.push_record(g);
    let steps = (2.0 * std::f64::consts::PI / dt).round() as usize;
    let dt = 2.0 * std::f64::consts::PI / steps as f64;
    let rate = |p: &mut Particles<D3>| {
        if spin {
            p.torque[0] = DVec3::Z.cross(p.omega[0]) * p.inertia[0];
        } else {
            p.force[0] = DVec3::Z.cross(p.vel[0]) * p.mass[0];
        }
    };
    rate(&mut p);
    gear5::initialize(&mut p, dt);
    for _ in 0..steps {
        Integrator::Gear5.predict(&mut p, dt, spin, None);
        rate(&mut p);
        Integrator::Gear5.correct(&mut p, dt, spin);
    }
    let y = if spin { p.omega[0] } else { p.vel[0] };
    (y - y0).length()
}

#[test]
fn gear5_spin_corrector_has_the_order_of_its_translation_corrector() {
    // The same equation integrated once as a velocity and once as a spin:
    // the errors must fall with dt at the same rate (the spin corrector is
    // a first-order Gear scheme of its own, with its own coefficients, so a
    // wrong one would show as a lower order or no convergence at all).
    let order = |spin: bool| {
        let (e1, e2) = (gear_turn_error(0.02, spin), gear_turn_error(0.01, spin));
        assert!(e1 > 0.0 && e2 > 0.0 && e1 < 1e-2, "spin {spin}: {e1}, {e2}");
        (e1 / e2).log2()
    };
    let (translation, spin) = (order(false), order(true));
    eprintln!("Gear-5 orders: translation {translation:.3}, spin {spin:.3}");
    assert!(translation > 1.5, "translation order {translation}");
    assert!(
        (spin - translation).abs() < 0.3,
        "spin order {spin}, translation order {translation}"
    );
    let _ = DVec2::ZERO;
}
