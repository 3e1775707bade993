//! Coulomb friction on an incline, and walls behaving like a grain of
//! diameter d0 at the contact point.

use crate::common;

use common::*;
use glam::{DVec2, DVec3};
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::{ContactLaw, MassScaling};
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Particles, D2, D3};

/// A grain resting on a plane tilted by θ (gravity turned instead of the
/// plane). Returns its displacement along the slope at `t`/2 and at `t`, and
/// the mean acceleration over the second half.
fn incline(theta: f64, mu: f64, t: f64) -> (f64, f64, f64) {
    let g = 9.81;
    let law = ContactLaw {
        kt: 2.0 / 7.0 * 1.0e6,
        gamma_t: 250.0,
        mu,
        ..hooke(1.0e6, 500.0, MassScaling::Reduced)
    };
    let r = 0.5;
    let mut s = MdSettings::<D2>::new(2e-5, law, 0.1);
    s.integrator = Integrator::Verlet;
    s.gravity = DVec2::new(g * theta.sin(), -g * theta.cos());
    let mut p = Particles::new();
    let mut gr = grain::<D2>(0, DVec2::new(0.0, r), 2.0 * r);
    gr.pos.y -= gr.mass * g * theta.cos() / 1.0e6; // start at the static overlap
    p.push_record(gr);
    let floor = Wall::new(
        "incline",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Fixed,
    )
    .unwrap();
    let mut md = Md::new(p, open_box(1.0e3), vec![floor], s).unwrap();
    let steps = (t / md.settings.dt) as u64;
    md.run(steps / 2).unwrap();
    let (x1, v1, t1) = (md.particles.pos[0].x, md.particles.vel[0].x, md.time);
    md.run(steps - steps / 2).unwrap();
    let (x2, v2, t2) = (md.particles.pos[0].x, md.particles.vel[0].x, md.time);
    (x1, x2, (v2 - v1) / (t2 - t1))
}

#[test]
fn grain_sticks_below_the_friction_angle() {
    let mu: f64 = 0.5;
    let theta = (0.9 * mu).atan();
    let (x_half, x_end, a) = incline(theta, mu, 0.5);
    // Released with an unstretched spring, the grain slips a little while the
    // spring loads (the overshoot exceeds the cap), then holds: it moves by a
    // few spring stretches m g sin θ / k_t and then not at all.
    let m = grains::MassModel::Sphere.mass(1.0, 1.0);
    let stretch = m * 9.81 * theta.sin() / (2.0 / 7.0 * 1.0e6);
    assert!(
        x_end.abs() < 10.0 * stretch,
        "moved {x_end}, spring stretch {stretch}"
    );
    assert!(
        (x_end - x_half).abs() < 1e-3 * stretch,
        "still creeping: {x_half} -> {x_end}"
    );
    assert!(a.abs() < 1e-6, "accelerates {a}");
}

#[test]
fn grain_slides_above_the_friction_angle_at_the_coulomb_rate() {
    let mu = 0.3;
    for theta_deg in [25.0f64, 35.0] {
        let theta = theta_deg.to_radians();
        let (_, _, a) = incline(theta, mu, 0.5);
        let expected = 9.81 * (theta.sin() - mu * theta.cos());
        assert!(
            ((a - expected) / expected).abs() < 1e-3,
            "θ = {theta_deg}: a = {a}, expected {expected}"
        );
    }
}

/// Force and torque on a grain touching either a plane wall moving with
/// `wall_vel`, or a frozen grain of diameter d0 placed so that it touches
/// the plane's surface at the same point and moves the same way.
fn wall_versus_grain(scaling: MassScaling, wall_vel: DVec3) -> [(DVec3, DVec3); 2] {
    let d0 = 1.0;
    let law = ContactLaw {
        kn: 1.0e5,
        beta: 1.0,
        gamma_n: 80.0,
        gamma_t: 40.0,
        kt: 3.0e4,
        mu: 0.4,
        scaling,
        rotation: true,
    };
    let mut g = grain::<D3>(0, DVec3::new(0.3, -0.2, 0.49), 0.8);
    g.pos.z = 0.4 - 0.01; // overlap 0.01 with the plane z = 0
    g.vel = DVec3::new(0.3, -0.1, -0.2);
    g.omega = DVec3::new(1.0, 2.0, -0.5);
    let settings = MdSettings::<D3>::new(1e-5, law, 0.05);
    let mut out = [(DVec3::ZERO, DVec3::ZERO); 2];
    // Wall.
    let mut p = Particles::new();
    p.push_record(g.clone());
    let wall = Wall::new(
        "plate",
        Shape::Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        },
        Motion::Translate { velocity: wall_vel },
    )
    .unwrap();
    let md = Md::new(p, open_box(5.0), vec![wall], settings.clone()).unwrap();
    out[0] = (md.particles.force[0], md.particles.torque[0]);
    // Frozen grain of diameter d0 whose top touches the plane below the grain.
    let mut p = Particles::new();
    p.push_record(g.clone());
    let mut f = grain::<D3>(1, DVec3::new(g.pos.x, g.pos.y, -0.5 * d0), d0);
    f.frozen = true;
    f.vel = wall_vel;
    p.push_record(f);
    let md = Md::new(p, open_box(5.0), vec![], settings).unwrap();
    let i = md.particles.id.iter().position(|&id| id == 0).unwrap();
    out[1] = (md.particles.force[i], md.particles.torque[i]);
    out
}

#[test]
fn wall_contact_equals_contact_with_a_frozen_grain_of_diameter_d0() {
    for scaling in [MassScaling::Seed, MassScaling::Reduced] {
        for vel in [DVec3::ZERO, DVec3::new(0.5, 0.2, 0.7)] {
            let [(fw, tw), (fg, tg)] = wall_versus_grain(scaling, vel);
            assert!(
                (fw - fg).length() < 1e-9 * fw.length(),
                "{scaling:?}: {fw} vs {fg}"
            );
            assert!(
                (tw - tg).length() < 1e-9 * tw.length().max(1e-12),
                "{scaling:?}: {tw} vs {tg}"
            );
        }
        // The wall's velocity enters the dissipation: a plate rising at the
        // grain's own normal speed removes the normal damping force.
        let [(still, _), _] = wall_versus_grain(scaling, DVec3::ZERO);
        let [(comoving, _), _] = wall_versus_grain(scaling, DVec3::new(0.0, 0.0, -0.2));
        assert!(
            comoving.z < still.z,
            "{scaling:?}: damping ignored the wall velocity"
        );
    }
}

/// A grain bouncing on a floor that comes last among many walls, the others
/// planes far below it: the floor's force must arrive as when it is alone,
/// bit for bit, with 10 walls or 70 (the wall pass marks the grains some
/// wall may touch before it runs the contact code on them).
#[test]
fn far_walls_change_nothing_with_few_or_many_walls() {
    let plane = |name: String, y: f64| {
        Wall::new(
            name,
            Shape::Plane {
                point: DVec2::new(0.0, y),
                normal: DVec2::Y,
            },
            Motion::Fixed,
        )
        .unwrap()
    };
    let run = |far: usize| {
        let mut s = MdSettings::<D2>::new(2e-5, hooke(1.0e6, 5.0, MassScaling::Reduced), 0.1);
        s.integrator = Integrator::Verlet;
        s.gravity = DVec2::new(0.0, -9.81);
        let mut p = Particles::new();
        p.push_record(grain::<D2>(0, DVec2::new(0.0, 0.501), 1.0));
        let mut walls: Vec<_> = (0..far)
            .map(|w| plane(format!("far{w}"), -100.0 - w as f64))
            .collect();
        walls.push(plane("floor".into(), 0.0));
        let mut md = Md::new(p, open_box(1.0e3), walls, s).unwrap();
        let mut contacts = 0;
        for _ in 0..400 {
            md.run(10).unwrap();
            contacts += md.stats.contacts;
        }
        (md.particles.pos[0], md.particles.vel[0], contacts)
    };
    let alone = run(0);
    assert!(alone.2 > 0, "the grain never reached the floor");
    assert_eq!(run(9), alone);
    assert_eq!(run(69), alone);
}
