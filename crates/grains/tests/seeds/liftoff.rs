//! Seed 002 §3 (onset of fluidization), its simplest case: a single ball on
//! a plate vibrating as A sin(ωt + φ0) first leaves the plate at the phase
//! where the plate's downward acceleration exceeds g, sin φ = 1/Γ with
//! Γ = A ω² / g, and never when Γ < 1.

use glam::DVec2;
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::{ContactLaw, MassScaling};
use grains::md::{Md, MdSettings};
use grains::{Domain, MassModel, ParticleRecord, Particles, D2};
use std::f64::consts::{FRAC_PI_2, TAU};

const G: f64 = 9.81;
const F: f64 = 20.0;
const KN: f64 = 5.0e7;

/// The ball on the plate, the plate at its lowest point (φ = −π/2, at rest,
/// accelerating upward at A ω²) and the ball pressed in by the matching
/// static overlap, so that nothing rings at the start.
fn ball_on_plate(gamma: f64) -> Md<D2> {
    let w = TAU * F;
    let amp = gamma * G / (w * w);
    let law = ContactLaw {
        kn: KN,
        beta: 1.0,
        gamma_n: 200.0,
        gamma_t: 400.0,
        kt: 0.0,
        mu: f64::INFINITY,
        scaling: MassScaling::Seed,
        rotation: false,
    };
    let d = 1.0e-3;
    let m = MassModel::Sphere.mass(7850.0, d);
    let overlap = (G + amp * w * w) / KN;
    let y0 = -amp + 0.5 * d - overlap;
    let ball = ParticleRecord::new(1, DVec2::new(0.0, y0), 0.5 * d, m, 0.1 * m * d * d);
    let mut p = Particles::new();
    p.push_record(ball);
    let plate = Wall::new(
        "plate",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Vibrate {
            direction: DVec2::Y,
            amplitude: amp,
            modulation: 0.0,
            wavelength: 1.0,
            frequency: F,
            phase: -FRAC_PI_2,
        },
    )
    .unwrap();
    let dom = Domain::new(
        DVec2::new(-0.01, -0.01),
        DVec2::new(0.01, 0.05),
        [true, false, false],
    );
    // t_c = π / √kn under seed scaling (a wall is an equal partner); t_c / 50.
    let dt = std::f64::consts::PI / KN.sqrt() / 50.0;
    let mut s = MdSettings::new(dt, law, 2.0e-4);
    s.gravity = DVec2::new(0.0, -G);
    Md::new(p, dom, vec![plate], s).unwrap()
}

/// The time the plate stops pushing the ball: the net force on it is gravity
/// alone (or less), or the contact is gone. `None` within `cycles` cycles.
fn lift_off(md: &mut Md<D2>, cycles: f64) -> Option<f64> {
    let steps = (cycles / (F * md.settings.dt)) as u64;
    for _ in 0..steps {
        md.step().unwrap();
        let p = &md.particles;
        let pushed = p.force[0].y + p.mass[0] * G > 0.0;
        let touching = md.walls[0]
            .contact(p.pos[0], p.radius[0], md.time)
            .is_some();
        if !(pushed && touching) {
            return Some(md.time);
        }
    }
    None
}

#[test]
fn ball_leaves_the_plate_where_its_downward_acceleration_exceeds_g() {
    for gamma in [1.2, 2.0, 3.5] {
        let mut md = ball_on_plate(gamma);
        let dt = md.settings.dt;
        let t = lift_off(&mut md, 1.0).expect("the ball leaves within a cycle");
        // φ = ωt − π/2 from the plate's upward zero crossing.
        let w = TAU * F;
        let phase = w * t - FRAC_PI_2;
        let expect = (1.0 / gamma).asin();
        let tol = 3.0 * w * dt;
        assert!(
            (phase - expect).abs() < tol,
            "Γ = {gamma}: left at φ = {phase:.5} rad, closed form {expect:.5} rad (tolerance {tol:.5} rad = 3 steps)"
        );
    }
}

#[test]
fn ball_stays_on_the_plate_below_gamma_one() {
    for gamma in [0.5, 0.9] {
        let mut md = ball_on_plate(gamma);
        assert_eq!(lift_off(&mut md, 3.0), None, "Γ = {gamma}");
    }
}
