//! Moving walls: poses, surface velocities and modulated plates.

use crate::boundary::tests::{near, near2, near3, plate, vibrated_plate_2d};
use crate::boundary::*;
use crate::dim::{D2, D3};
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

#[test]
fn vibrating_plate() {
    let (a, f) = (1e-3, 20.0);
    let w = plate(0.0);
    for t in [0.0, 0.003, 0.01, 0.0271] {
        let z = a * (TAU * f * t).sin();
        let v = TAU * f * a * (TAU * f * t).cos();
        assert!(near2(w.displacement(t), DVec2::new(0.0, z)));
        let c = w.contact(DVec2::new(3.0, z + 0.4), 0.5, t).unwrap();
        assert!(near(c.overlap, 0.1));
        assert!(near2(c.point, DVec2::new(3.0, z)));
        assert!(near2(c.normal, DVec2::Y));
        assert!(near2(c.velocity, DVec2::new(0.0, v)));
    }
}

#[test]
fn modulated_plate_factors() {
    let (a, f, b, l) = (1e-3, 20.0, 0.5, 20.0);
    let w = plate(b);
    let t = 0.01;
    let (s, co) = ((TAU * f * t).sin(), (TAU * f * t).cos());
    for (x, factor) in [(0.0, 1.0 - b), (l / 2.0, 1.0 + b), (l, 1.0 - b)] {
        let z = a * factor * s;
        let c = w.contact(DVec2::new(x, z + 0.3), 0.5, t).unwrap();
        assert!(near(c.overlap, 0.2), "x = {x}");
        assert!(near2(c.point, DVec2::new(x, z)));
        assert!(near2(
            c.velocity,
            DVec2::new(0.0, TAU * f * a * factor * co)
        ));
    }
    // At x = L/4 the modulation vanishes: the plain amplitude.
    // (the contact point lies a hair off L/4: the plate is tilted there).
    let c = w.contact(DVec2::new(l / 4.0, 0.3), 0.5, t).unwrap();
    let factor = 1.0 - b * (TAU * c.point.x / l).cos();
    assert!(factor != 1.0 && (factor - 1.0).abs() < 1e-4);
    assert!(near(c.velocity.y, TAU * f * a * factor * co));
    // The reference point is at x = 0: displacement with factor 1 − B.
    assert!(near2(w.displacement(t), DVec2::new(0.0, a * (1.0 - b) * s)));
}

#[test]
fn modulated_plate_tilts_its_normal_with_the_surface_slope() {
    // A deep modulation (slope up to A0 B 2π/L = 0.236, 13°) so that the
    // tilt is large; at x = L/4 the surface has no curvature, so the tangent
    // is exact and the overlap must equal r minus the true distance to the
    // curve z0(x) = A0 (1 − B cos 2πx/L) (at sin 2πft = 1), found by sampling.
    let (a0, b, l, f) = (1.5, 0.5, 20.0, 20.0);
    let w = vibrated_plate_2d(DVec2::ZERO, DVec2::Y, DVec2::Y, [a0, b, l, f, 0.0]);
    let t = 0.25 / f;
    let z0 = |x: f64| a0 * (1.0 - b * (TAU * x / l).cos());
    let p = DVec2::new(l / 4.0, z0(l / 4.0) + 0.4);
    let r = 0.5;
    let c = w.contact(p, r, t).unwrap();
    let dist = (0..=200_000)
        .map(|i| {
            let x = l / 4.0 - 1.0 + 2.0 * i as f64 / 200_000.0;
            (p - DVec2::new(x, z0(x))).length()
        })
        .fold(f64::INFINITY, f64::min);
    // The contact point sits δx ≈ slope·0.4 = 0.09 from x = L/4, where the
    // curve leaves its tangent by A0 B k³ δx³/6 ≈ 3e-6.
    assert!(
        (c.overlap - (r - dist)).abs() < 1e-5,
        "{} vs {}",
        c.overlap,
        r - dist
    );
    let slope = a0 * b * TAU / l;
    assert!(near2(c.normal, DVec2::new(-slope, 1.0).normalize()));
    // The plate material moves vertically, with the local amplitude.
    assert_eq!(c.velocity.x, 0.0);
    // The normal leans away from the crest (x = L/2): on the rising plate
    // the grain is pushed toward the trough at x = 0.
    assert!(c.normal.x < 0.0);
}

#[test]
fn modulation_needs_a_plate_across_x() {
    let err = Wall::<D2>::new(
        "side",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::X,
        },
        Motion::Vibrate {
            direction: DVec2::X,
            amplitude: 1.0,
            modulation: 0.5,
            wavelength: 20.0,
            frequency: 20.0,
            phase: 0.0,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("'side'") && err.contains("perpendicular to x"),
        "{err}"
    );
}

#[test]
fn oscillating_conveyor() {
    let amp = DVec3::new(2e-3, 0.0, 1e-3);
    let f = 10.0;
    let w = Wall::<D3>::new(
        "belt",
        Shape::Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        },
        Motion::Oscillate {
            amplitude: amp,
            frequency: f,
            phase: 0.0,
        },
    )
    .unwrap();
    let t = 0.0125; // 2π f t = π/4
    let (s, co) = ((PI / 4.0).sin(), (PI / 4.0).cos());
    assert!(near3(w.displacement(t), amp * s));
    let c = w
        .contact(DVec3::new(7.0, 3.0, amp.z * s + 0.3), 0.5, t)
        .unwrap();
    assert!(near(c.overlap, 0.2));
    // The in-plane part moves the surface along itself: only the velocity sees it.
    assert!(near3(c.point, DVec3::new(7.0, 3.0, amp.z * s)));
    assert!(near3(c.velocity, amp * (TAU * f * co)));
    // A 2D belt with a phase.
    let w = Wall::<D2>::new(
        "belt2",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Oscillate {
            amplitude: DVec2::new(1e-3, 1e-3),
            frequency: 5.0,
            phase: PI / 2.0,
        },
    )
    .unwrap();
    let c = w.contact(DVec2::new(0.0, 1e-3 + 0.1), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.4));
    assert!(c.velocity.length() < 1e-15);
}

#[test]
fn translating_wall() {
    let w = Wall::<D2>::new(
        "piston",
        Shape::Segment {
            a: DVec2::new(0.0, 0.0),
            b: DVec2::new(0.0, 2.0),
        },
        Motion::Translate {
            velocity: DVec2::new(0.5, 0.0),
        },
    )
    .unwrap();
    let c = w.contact(DVec2::new(1.3, 1.0), 0.5, 2.0).unwrap();
    assert!(near(c.overlap, 0.2));
    assert!(near2(c.point, DVec2::new(1.0, 1.0)));
    assert!(near2(c.velocity, DVec2::new(0.5, 0.0)));
    assert!(near2(w.displacement(2.0), DVec2::new(1.0, 0.0)));
}

#[test]
fn rotating_drum_surface_velocity_2d() {
    let (omega, radius) = (3.0, 2.0);
    let w = Wall::<D2>::new(
        "drum",
        Shape::Cylinder {
            point: DVec2::ZERO,
            axis: DVec2::ZERO,
            radius,
            inside: true,
        },
        Motion::Rotate {
            center: DVec2::ZERO,
            omega,
        },
    )
    .unwrap();
    for t in [0.0, 0.37, 12.5] {
        let c = w.contact(DVec2::new(0.0, -1.8), 0.5, t).unwrap();
        assert!(near(c.overlap, 0.3));
        assert!(near2(c.normal, DVec2::Y));
        assert!(near2(c.point, DVec2::new(0.0, -radius)));
        // Ω R, tangential, counter-clockwise for Ω > 0.
        assert!(near2(c.velocity, DVec2::new(omega * radius, 0.0)));
        assert!(w.displacement(t).length() < 1e-12);
    }
}

#[test]
fn rotating_drum_surface_velocity_3d() {
    let center = DVec3::new(1.0, 1.0, 0.0);
    let omega = DVec3::new(0.0, 0.0, -3.0);
    let w = Wall::<D3>::new(
        "drum",
        Shape::Cylinder {
            point: center,
            axis: DVec3::Z,
            radius: 2.0,
            inside: true,
        },
        Motion::Rotate { center, omega },
    )
    .unwrap();
    let c = w.contact(DVec3::new(2.8, 1.0, 4.0), 0.5, 0.8).unwrap();
    assert!(near(c.overlap, 0.3));
    assert!(near3(c.normal, -DVec3::X));
    assert!(near3(c.point, DVec3::new(3.0, 1.0, 4.0)));
    assert!(near3(c.velocity, DVec3::new(0.0, -6.0, 0.0)));
    assert!(near(c.velocity.length(), 3.0 * 2.0));
    assert!(near(c.velocity.dot(c.normal), 0.0));
}

#[test]
fn rotated_segment_quarter_turn() {
    let w = Wall::<D2>::new(
        "paddle",
        Shape::Segment {
            a: DVec2::new(1.0, 0.0),
            b: DVec2::new(3.0, 0.0),
        },
        Motion::Rotate {
            center: DVec2::ZERO,
            omega: PI / 2.0,
        },
    )
    .unwrap();
    // After t = 1 s the segment runs from (0, 1) to (0, 3).
    let c = w.contact(DVec2::new(0.3, 2.0), 0.5, 1.0).unwrap();
    assert!(near(c.overlap, 0.2));
    assert!(near2(c.normal, DVec2::X));
    assert!(near2(c.point, DVec2::new(0.0, 2.0)));
    assert!(near2(c.velocity, DVec2::new(-PI, 0.0)));
    // End cap at the rotated a = (0, 1).
    let c = w.contact(DVec2::new(-0.3, 0.6), 0.6, 1.0).unwrap();
    assert!(near(c.overlap, 0.1));
    assert!(near2(c.normal, DVec2::new(-0.6, -0.8)));
    assert!(near2(c.point, DVec2::new(0.0, 1.0)));
    // Where the segment was, it is no longer.
    assert!(w.contact(DVec2::new(2.0, 0.3), 0.5, 1.0).is_none());
    assert!(w.contact(DVec2::new(2.0, 0.3), 0.5, 0.0).is_some());
    assert!(near2(w.displacement(1.0), DVec2::new(-2.0, 2.0)));
}

#[test]
fn rotated_polygon_quarter_turn_3d() {
    // A square in the x-z plane turned a quarter about z lies in the y-z plane.
    let w = Wall::<D3>::new(
        "flap",
        Shape::Polygon {
            vertices: vec![
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(3.0, 0.0, 2.0),
                DVec3::new(1.0, 0.0, 2.0),
            ],
            seams: vec![],
        },
        Motion::Rotate {
            center: DVec3::ZERO,
            omega: DVec3::new(0.0, 0.0, 0.5),
        },
    )
    .unwrap();
    let t = PI; // angle π/2
    let c = w.contact(DVec3::new(-0.2, 2.0, 1.0), 0.5, t).unwrap();
    assert!(near(c.overlap, 0.3));
    assert!(near3(c.normal, -DVec3::X));
    assert!(near3(c.point, DVec3::new(0.0, 2.0, 1.0)));
    assert!(near3(c.velocity, DVec3::new(-1.0, 0.0, 0.0)));
    assert!(near3(w.displacement(t), DVec3::new(-2.0, 2.0, 0.0)));
}

/// A wall placed once at time t (`Wall::at`) takes its pose and, where the
/// motion says it is uniform, its velocity once for all grains: the
/// velocity must then be the motion's velocity at every contact point, and
/// the pose the one the motion gives at every x (all motions but the
/// modulated vibration). Checked for each motion kind, at grains spread
/// along the wall.
#[test]
fn a_placed_wall_agrees_with_the_motion_at_every_point() {
    let plane = || Shape::Plane {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    };
    let vibrate = |modulation| Motion::Vibrate {
        direction: DVec2::Y,
        amplitude: 1e-3,
        modulation,
        wavelength: 20.0,
        frequency: 20.0,
        phase: 0.3,
    };
    let motions: [Motion<D2>; 6] = [
        Motion::Fixed,
        vibrate(0.0),
        vibrate(0.5),
        Motion::Oscillate {
            amplitude: DVec2::new(2e-3, 1e-3),
            frequency: 15.0,
            phase: 0.1,
        },
        Motion::Translate {
            velocity: DVec2::new(0.5, 0.01),
        },
        Motion::Rotate {
            center: DVec2::new(0.0, 5.0),
            omega: 0.02,
        },
    ];
    for motion in motions {
        let kind = motion.kind();
        let modulated = motion.is_modulated();
        let wall = Wall::new("w", plane(), motion).unwrap();
        for t in [0.0, 0.0137, 0.05] {
            let placed = wall.at(t);
            let mut contacts = 0;
            for x in [-7.3, -1.0, 0.0, 2.5, 9.9] {
                let q = DVec3::new(x, 0.25, 0.0);
                let (here, at_zero) = (wall.motion.pose(t, x), wall.motion.pose(t, 0.0));
                assert!(
                    modulated || here.apply(q) == at_zero.apply(q),
                    "{kind} at t {t}, x {x}"
                );
                let lift = wall.motion.place(DVec2::new(x, 0.0), t).y;
                let Some(c) = placed.contact(DVec2::new(x, lift + 0.3), 0.5) else {
                    continue;
                };
                contacts += 1;
                let v = wall.motion.velocity_at(c.point, t);
                assert!(
                    near2(c.velocity, v),
                    "{kind} at t {t}, x {x}: {c:?} against {v}"
                );
            }
            assert!(contacts >= 4, "{kind} at t {t}: {contacts} contacts");
        }
    }
}
