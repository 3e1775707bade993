//! Seed 002's parameter readings as options: the flat (1992) plate beside
//! the curved one, and elastic walls beside a dissipative bulk, checked
//! against their closed forms; bad values refused with the key named.

use glam::DVec2;
use grains::boundary::{Motion, PlateSurface, Shape, Wall};
use grains::contact::{ContactLaw, MassScaling};
use grains::md::{Md, MdSettings};
use grains::scenario::{build_md, load_default};
use grains::{Domain, MassModel, ParticleRecord, Particles, D2};
use std::f64::consts::{PI, TAU};

const A0: f64 = 1.5e-3;
const B: f64 = 0.5;
const L: f64 = 0.02;
const F: f64 = 70.0;

fn plate(surface: PlateSurface) -> Wall<D2> {
    Wall::new(
        "plate",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Vibrate {
            direction: DVec2::Y,
            amplitude: A0,
            modulation: B,
            wavelength: L,
            frequency: F,
            phase: 0.0,
        },
    )
    .unwrap()
    .with_surface(surface)
}

/// At x = L/4 (steepest modulation) and ωt = π/4 the curve z0 = A(x) sin ωt
/// has slope σ = A0 B k sin ωt = 0.167: the curved plate's normal leans by
/// atan σ = 9.5°, the flat one's stays vertical; both sit at z0 and move at
/// A(x) ω cos ωt straight up.
#[test]
fn flat_plate_pushes_straight_up_where_the_curved_one_leans() {
    let (x, t, r) = (0.25 * L, 1.0 / (8.0 * F), 0.5e-3);
    let (k, w) = (TAU / L, TAU * F);
    let ax = A0 * (1.0 - B * (k * x).cos());
    let z0 = ax * (w * t).sin();
    let slope = A0 * B * k * (k * x).sin() * (w * t).sin();
    let p = DVec2::new(x, z0 + 0.9 * r);
    let flat = plate(PlateSurface::Flat).contact(p, r, t).unwrap();
    let curved = plate(PlateSurface::Curved).contact(p, r, t).unwrap();
    let eps = 1e-12;
    assert_eq!(flat.normal, DVec2::Y);
    assert!((flat.overlap - 0.1 * r).abs() < eps * r, "{}", flat.overlap);
    assert!((flat.point - DVec2::new(x, z0)).length() < eps * r);
    let lean = (-curved.normal.x).atan2(curved.normal.y);
    assert!(
        (lean - slope.atan()).abs() < 1e-12,
        "{lean} vs {}",
        slope.atan()
    );
    // The curved plate's distance is the vertical one times cos(lean).
    let s = 0.9 * r / (1.0 + slope * slope).sqrt();
    assert!((curved.overlap - (r - s)).abs() < eps * r);
    // Each moves at A(x) ω cos ωt straight up, x its contact point's (the
    // curved plate's lies r σ/√(1 + σ²) aside).
    for c in [flat, curved] {
        let v = A0 * (1.0 - B * (k * c.point.x).cos()) * w * (w * t).cos();
        assert!((c.velocity - DVec2::new(0.0, v)).length() < 1e-12 * v);
    }
    let aside = slope * s / (1.0 + slope * slope).sqrt();
    assert!((curved.point.x - (x + aside)).abs() < 1e-12 * r);
}

/// A ball (no gravity) thrown at a fixed wall at `v0`; its rebound speed.
/// Under seed scaling the contact is ẍ + γ ẋ + Y x = 0 (the wall an equal
/// partner of diameter d0).
fn rebound(gamma_n: f64, elastic: bool) -> f64 {
    let (kn, d, v0) = (5.0e7, 1.0e-3, 0.1);
    let law = ContactLaw {
        kn,
        beta: 1.0,
        gamma_n,
        gamma_t: 400.0,
        kt: 0.0,
        mu: f64::INFINITY,
        scaling: MassScaling::Seed,
        rotation: false,
    };
    let m = MassModel::Sphere.mass(7850.0, d);
    let mut ball = ParticleRecord::new(1, DVec2::new(0.0, 0.5 * d + 1e-6), 0.5 * d, m, 0.0);
    ball.vel = DVec2::new(0.0, -v0);
    let mut p = Particles::new();
    p.push_record(ball);
    let wall = Wall::new(
        "floor",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Fixed,
    )
    .unwrap()
    .with_elastic(elastic);
    let dom = Domain::new(
        DVec2::new(-0.01, -0.01),
        DVec2::new(0.01, 0.05),
        [true, false, false],
    );
    let dt = PI / kn.sqrt() / 200.0;
    let mut md: Md<D2> = Md::new(p, dom, vec![wall], MdSettings::new(dt, law, 2.0e-4)).unwrap();
    // Well past the contact (t_c ≈ 0.44 ms) and the 1 µm approach.
    while md.time < 2.0e-3 {
        md.step().unwrap();
    }
    md.particles.vel[0].y / v0
}

/// ẍ + γẋ + Yx = 0 returns a grain at e = exp(−γ π / (2 ω_d)),
/// ω_d = √(Y − γ²/4): 0.986 at γ = 200 s⁻¹, Y = 5e7 s⁻². An elastic wall
/// returns it at e = 1 whatever γ (Gear-5 at t_c/200 keeps the energy to
/// far better than the 1e-4 allowed).
#[test]
fn elastic_wall_returns_the_grain_at_its_impact_speed() {
    let gamma = 2000.0;
    let wd = (5.0e7 - gamma * gamma / 4.0_f64).sqrt();
    let e = (-gamma * PI / (2.0 * wd)).exp();
    let damped = rebound(gamma, false);
    assert!((damped - e).abs() < 1e-3, "damped wall: {damped} vs {e}");
    let elastic = rebound(gamma, true);
    assert!((elastic - 1.0).abs() < 1e-4, "elastic wall: {elastic}");
    assert!(e < 0.9, "the check needs a clearly damped contact: {e}");
}

#[test]
fn unknown_elastic_wall_is_refused_with_the_walls_named() {
    let l = load_default(&["contact.elastic_walls=[\"left\"]".into()]).unwrap();
    let e = build_md::<D2>(&l).err().expect("refused").to_string();
    assert!(
        e.contains("contact.elastic_walls") && e.contains("\"left\"") && e.contains("\"plate\""),
        "{e}"
    );
}

#[test]
fn unknown_plate_surface_is_refused_with_the_choices() {
    let e = load_default(&["walls.0.motion.surface=\"wavy\"".into()])
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("wavy") && e.contains("curved") && e.contains("flat"),
        "{e}"
    );
}

/// `walls.0.motion.surface` reaches the plate: in the shipped Fig. 2
/// scenario the flat reading meets a grain at x = L/4 with a vertical
/// normal, the curved one with a leaning normal.
#[test]
fn the_surface_key_reaches_the_plate() {
    let (x, t, r) = (0.25 * L, 1.0 / (8.0 * F), 0.5e-3);
    let z0 = A0 * (TAU * F * t).sin();
    for (s, vertical) in [("flat", true), ("curved", false)] {
        let l = load_default(&[format!("walls.0.motion.surface={s}")]).unwrap();
        let (md, _) = build_md::<D2>(&l).unwrap();
        let c = md.walls[0]
            .contact(DVec2::new(x, z0 + 0.9 * r), r, t)
            .unwrap();
        assert_eq!(c.normal == DVec2::Y, vertical, "{s}: {:?}", c.normal);
    }
}
