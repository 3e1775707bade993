//! Wall contacts with numbers, in 2D and 3D.

use super::*;
use crate::dim::{D2, D3};
use glam::{DQuat, DVec2, DVec3};
use std::f64::consts::{FRAC_1_SQRT_2, PI, TAU};

const EPS: f64 = 1e-12;

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() < EPS * (1.0 + b.abs())
}
fn near2(a: DVec2, b: DVec2) -> bool {
    (a - b).length() < EPS * (1.0 + b.length())
}
fn near3(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < EPS * (1.0 + b.length())
}

fn fixed2(shape: Shape<D2>) -> Wall<D2> {
    Wall::new("w", shape, Motion::Fixed).unwrap()
}
fn fixed3(shape: Shape<D3>) -> Wall<D3> {
    Wall::new("w", shape, Motion::Fixed).unwrap()
}

#[test]
fn plane_2d_arbitrary_orientation() {
    let w = fixed2(Shape::Plane {
        point: DVec2::new(1.0, 0.0),
        normal: DVec2::new(1.0, 1.0),
    });
    let c = w.contact(DVec2::new(2.0, 0.5), 1.2, 0.0).unwrap();
    assert!(near(c.overlap, 1.2 - 1.5 / 2f64.sqrt()));
    assert!(near2(c.normal, DVec2::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2)));
    assert!(near2(c.point, DVec2::new(1.25, -0.25)));
    assert_eq!(c.velocity, DVec2::ZERO);
    assert!(w.contact(DVec2::new(2.0, 0.5), 1.0, 0.0).is_none());
}

#[test]
fn plane_3d_arbitrary_orientation() {
    let w = fixed3(Shape::Plane {
        point: DVec3::new(0.0, 0.0, 1.0),
        normal: DVec3::new(1.0, 2.0, 2.0),
    });
    let c = w.contact(DVec3::new(1.0, 1.0, 2.0), 2.0, 0.0).unwrap();
    assert!(near(c.overlap, 1.0 / 3.0));
    assert!(near3(c.normal, DVec3::new(1.0, 2.0, 2.0) / 3.0));
    assert!(near3(c.point, DVec3::new(4.0, -1.0, 8.0) / 9.0));
    // Behind the plane (centre crossed by 0.5 < r): pushed back along n.
    let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    let p = DVec3::new(0.0, 0.0, 1.0) - n * 0.5;
    let c = w.contact(p, 2.0, 0.0).unwrap();
    assert!(near(c.overlap, 2.5));
    assert!(near3(c.normal, n));
    // Deeply behind (more than r): lost, no contact.
    assert!(w
        .contact(DVec3::new(0.0, 0.0, 1.0) - n * 2.5, 2.0, 0.0)
        .is_none());
}

#[test]
fn exactly_touching_is_no_contact() {
    let w = fixed2(Shape::Plane {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    });
    assert!(w.contact(DVec2::new(0.3, 0.5), 0.5, 0.0).is_none());
    assert!(near(
        w.contact(DVec2::new(0.3, 0.25), 0.5, 0.0).unwrap().overlap,
        0.25
    ));
    let o = fixed3(Shape::Obstacle {
        center: DVec3::ZERO,
        diameter: 1.0,
    });
    assert!(o.contact(DVec3::new(0.0, 0.75, 0.0), 0.25, 0.0).is_none());
    let s = fixed2(Shape::Segment {
        a: DVec2::ZERO,
        b: DVec2::X,
    });
    assert!(s.contact(DVec2::new(0.5, -0.5), 0.5, 0.0).is_none());
}

#[test]
fn segment_interior_and_end_caps() {
    let w = fixed2(Shape::Segment {
        a: DVec2::new(0.0, 0.0),
        b: DVec2::new(4.0, 0.0),
    });
    let c = w.contact(DVec2::new(1.0, 0.3), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.2));
    assert!(near2(c.normal, DVec2::Y));
    assert!(near2(c.point, DVec2::new(1.0, 0.0)));
    // Two-sided: from below the normal points down.
    let c = w.contact(DVec2::new(2.0, -0.1), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.4));
    assert!(near2(c.normal, -DVec2::Y));
    // End cap at b.
    let c = w.contact(DVec2::new(4.3, 0.4), 0.6, 0.0).unwrap();
    assert!(near(c.overlap, 0.1));
    assert!(near2(c.normal, DVec2::new(0.6, 0.8)));
    assert!(near2(c.point, DVec2::new(4.0, 0.0)));
    // End cap at a.
    let c = w.contact(DVec2::new(-0.3, -0.4), 0.6, 0.0).unwrap();
    assert!(near(c.overlap, 0.1));
    assert!(near2(c.normal, DVec2::new(-0.6, -0.8)));
    assert!(near2(c.point, DVec2::ZERO));
    // Beyond the cap: nothing.
    assert!(w.contact(DVec2::new(4.5, 0.1), 0.4, 0.0).is_none());
    // Centre on the segment: pushed along the left normal.
    let c = w.contact(DVec2::new(2.0, 0.0), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.5));
    assert!(near2(c.normal, DVec2::Y));
}

#[test]
fn polygon_interior_edge_and_vertex() {
    let w = fixed3(Shape::Polygon {
        vertices: vec![
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(2.0, 2.0, 1.0),
            DVec3::new(0.0, 2.0, 1.0),
        ],
        seams: vec![],
    });
    // Interior, both sides.
    let c = w.contact(DVec3::new(1.0, 1.0, 1.3), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.2));
    assert!(near3(c.normal, DVec3::Z));
    assert!(near3(c.point, DVec3::new(1.0, 1.0, 1.0)));
    let c = w.contact(DVec3::new(0.5, 1.5, 0.8), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.3));
    assert!(near3(c.normal, -DVec3::Z));
    assert!(near3(c.point, DVec3::new(0.5, 1.5, 1.0)));
    // Edge region (beyond x = 2).
    let c = w.contact(DVec3::new(2.3, 1.0, 1.4), 0.6, 0.0).unwrap();
    assert!(near(c.overlap, 0.1));
    assert!(near3(c.normal, DVec3::new(0.6, 0.0, 0.8)));
    assert!(near3(c.point, DVec3::new(2.0, 1.0, 1.0)));
    // Vertex region (beyond the corner (2, 2)).
    let c = w.contact(DVec3::new(2.2, 2.2, 1.1), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.2));
    assert!(near3(c.normal, DVec3::new(2.0, 2.0, 1.0) / 3.0));
    assert!(near3(c.point, DVec3::new(2.0, 2.0, 1.0)));
    // Beside the polygon, in its plane, out of reach.
    assert!(w.contact(DVec3::new(3.0, 1.0, 1.0), 0.5, 0.0).is_none());
    assert!(w.contact(DVec3::new(1.0, 1.0, 1.5), 0.5, 0.0).is_none());
}

#[test]
fn tilted_polygon() {
    // A triangle rotated about an arbitrary axis: the interior normal is the
    // rotated z, the distance the rotated height.
    let q = DQuat::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 0.7);
    let o = DVec3::new(0.3, -1.0, 2.0);
    let tri = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(3.0, 0.0, 0.0),
        DVec3::new(0.0, 3.0, 0.0),
    ];
    let w = fixed3(Shape::Polygon {
        vertices: tri.iter().map(|v| o + q * *v).collect(),
        seams: vec![],
    });
    let c = w
        .contact(o + q * DVec3::new(1.0, 1.0, 0.35), 0.5, 0.0)
        .unwrap();
    assert!(near(c.overlap, 0.15));
    assert!(near3(c.normal, q * DVec3::Z));
    assert!(near3(c.point, o + q * DVec3::new(1.0, 1.0, 0.0)));
    // Near the hypotenuse x + y = 3, outside it, in the plane.
    let c = w
        .contact(o + q * DVec3::new(1.7, 1.7, 0.0), 0.5, 0.0)
        .unwrap();
    assert!(near(c.overlap, 0.5 - 0.4 / 2f64.sqrt()));
    assert!(near3(
        c.normal,
        q * DVec3::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.0)
    ));
}

#[test]
fn cylinder_2d_inside_and_outside() {
    let drum = fixed2(Shape::Cylinder {
        point: DVec2::new(1.0, 1.0),
        axis: DVec2::ZERO,
        radius: 3.0,
        inside: true,
    });
    let c = drum.contact(DVec2::new(3.8, 1.0), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.3));
    assert!(near2(c.normal, -DVec2::X));
    assert!(near2(c.point, DVec2::new(4.0, 1.0)));
    assert!(drum.contact(DVec2::new(1.0, 1.0), 0.5, 0.0).is_none());
    let post = fixed2(Shape::Cylinder {
        point: DVec2::new(1.0, 1.0),
        axis: DVec2::ZERO,
        radius: 1.0,
        inside: false,
    });
    let c = post.contact(DVec2::new(1.0, 2.3), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.2));
    assert!(near2(c.normal, DVec2::Y));
    assert!(near2(c.point, DVec2::new(1.0, 2.0)));
    assert!(post.contact(DVec2::new(1.0, 2.5), 0.5, 0.0).is_none());
}

#[test]
fn cylinder_3d_arbitrary_axis() {
    let axis = DVec3::new(1.0, 1.0, 0.0);
    let along = axis.normalize() * 5.0;
    let pipe = fixed3(Shape::Cylinder {
        point: DVec3::ZERO,
        axis,
        radius: 2.0,
        inside: true,
    });
    let c = pipe
        .contact(along + DVec3::new(0.0, 0.0, 1.8), 0.5, 0.0)
        .unwrap();
    assert!(near(c.overlap, 0.3));
    assert!(near3(c.normal, -DVec3::Z));
    assert!(near3(c.point, along + DVec3::new(0.0, 0.0, 2.0)));
    // Radial direction not along a coordinate axis.
    let radial = DVec3::new(1.0, -1.0, 0.0).normalize();
    let c = pipe.contact(along + radial * 1.9, 0.25, 0.0).unwrap();
    assert!(near(c.overlap, 0.15));
    assert!(near3(c.normal, -radial));
    let post = fixed3(Shape::Cylinder {
        point: DVec3::ZERO,
        axis,
        radius: 1.0,
        inside: false,
    });
    let c = post
        .contact(along + DVec3::new(0.0, 0.0, 1.2), 0.5, 0.0)
        .unwrap();
    assert!(near(c.overlap, 0.3));
    assert!(near3(c.normal, DVec3::Z));
    assert!(near3(c.point, along + DVec3::Z));
}

#[test]
fn obstacle_2d_and_3d() {
    let w = fixed2(Shape::Obstacle {
        center: DVec2::new(5.0, 1.0),
        diameter: 1.0,
    });
    let c = w.contact(DVec2::new(5.6, 1.8), 0.6, 0.0).unwrap();
    assert!(near(c.overlap, 0.1));
    assert!(near2(c.normal, DVec2::new(0.6, 0.8)));
    assert!(near2(c.point, DVec2::new(5.3, 1.4)));
    let w = fixed3(Shape::Obstacle {
        center: DVec3::new(1.0, 2.0, 3.0),
        diameter: 2.0,
    });
    let c = w.contact(DVec3::new(1.0, 3.2, 4.6), 1.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.5));
    assert!(near3(c.normal, DVec3::new(0.0, 0.6, 0.8)));
    assert!(near3(c.point, DVec3::new(1.0, 2.6, 3.8)));
}

fn plate(modulation: f64) -> Wall<D2> {
    Wall::new(
        "bottom",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Vibrate {
            direction: DVec2::new(0.0, 2.0),
            amplitude: 1e-3,
            modulation,
            wavelength: 20.0,
            frequency: 20.0,
            phase: 0.0,
        },
    )
    .unwrap()
}

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

/// A plate through `point` facing `normal` (±y), vibrated along
/// `direction` with `[A0, B, L, f, phase]`.
fn vibrated_plate_2d(
    point: DVec2,
    normal: DVec2,
    direction: DVec2,
    [a0, b, l, f, phase]: [f64; 5],
) -> Wall<D2> {
    let motion = Motion::Vibrate {
        direction,
        amplitude: a0,
        modulation: b,
        wavelength: l,
        frequency: f,
        phase,
    };
    Wall::new("plate", Shape::Plane { point, normal }, motion).unwrap()
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

#[test]
fn remove_at_turns_the_wall_off() {
    let w = Wall::<D2>::new(
        "side",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::X,
        },
        Motion::Fixed,
    )
    .unwrap()
    .with_remove_at(1.5)
    .unwrap();
    let p = DVec2::new(0.2, 3.0);
    assert!(w.is_active(1.4999));
    assert!(w.contact(p, 0.5, 1.0).is_some());
    assert!(!w.is_active(1.5));
    assert!(w.contact(p, 0.5, 1.5).is_none());
    assert!(w.contact(p, 0.5, 100.0).is_none());
    assert!(fixed2(Shape::Plane {
        point: DVec2::ZERO,
        normal: DVec2::X
    })
    .is_active(1e30));
}

#[test]
fn constructor_normalizes() {
    let w = fixed2(Shape::Plane {
        point: DVec2::ZERO,
        normal: DVec2::new(0.0, 2.0),
    });
    assert_eq!(
        w.shape,
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y
        }
    );
    let w = fixed3(Shape::Cylinder {
        point: DVec3::ZERO,
        axis: DVec3::new(0.0, 0.0, -4.0),
        radius: 1.0,
        inside: true,
    });
    match w.shape {
        Shape::Cylinder { axis, .. } => assert_eq!(axis, -DVec3::Z),
        _ => unreachable!(),
    }
}

fn err<D: Dim>(shape: Shape<D>, motion: Motion<D>) -> String {
    Wall::new("left", shape, motion).unwrap_err().to_string()
}

#[test]
fn constructor_errors() {
    let plane2 = || Shape::<D2>::Plane {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    };
    let e = err(
        Shape::<D2>::Plane {
            point: DVec2::ZERO,
            normal: DVec2::ZERO,
        },
        Motion::Fixed,
    );
    assert!(
        e.contains("wall 'left'") && e.contains("plane normal"),
        "{e}"
    );
    let e = err(
        Shape::<D3>::Segment {
            a: DVec3::ZERO,
            b: DVec3::X,
        },
        Motion::Fixed,
    );
    assert!(e.contains("'left'") && e.contains("2D"), "{e}");
    let e = err(
        Shape::<D2>::Segment {
            a: DVec2::X,
            b: DVec2::X,
        },
        Motion::Fixed,
    );
    assert!(e.contains("zero length"), "{e}");
    let e = err(
        Shape::<D2>::Polygon {
            vertices: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            seams: vec![],
        },
        Motion::Fixed,
    );
    assert!(e.contains("3D"), "{e}");
    let e = err(
        Shape::<D3>::Polygon {
            vertices: vec![DVec3::ZERO, DVec3::X],
            seams: vec![],
        },
        Motion::Fixed,
    );
    assert!(e.contains("at least 3"), "{e}");
    let e = err(
        Shape::<D3>::Polygon {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::new(0.2, 0.2, 0.0), DVec3::Y],
            seams: vec![],
        },
        Motion::Fixed,
    );
    assert!(e.contains("convex"), "{e}");
    let e = err(
        Shape::<D3>::Polygon {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.5), DVec3::Y],
            seams: vec![],
        },
        Motion::Fixed,
    );
    assert!(e.contains("coplanar"), "{e}");
    let e = err(
        Shape::<D3>::Polygon {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            seams: vec![3],
        },
        Motion::Fixed,
    );
    assert!(e.contains("seam 3 is not an edge"), "{e}");
    let e = err(
        Shape::<D2>::Cylinder {
            point: DVec2::ZERO,
            axis: DVec2::ZERO,
            radius: -1.0,
            inside: true,
        },
        Motion::Fixed,
    );
    assert!(e.contains("cylinder radius"), "{e}");
    let e = err(
        Shape::<D3>::Cylinder {
            point: DVec3::ZERO,
            axis: DVec3::ZERO,
            radius: 1.0,
            inside: true,
        },
        Motion::Fixed,
    );
    assert!(e.contains("cylinder axis"), "{e}");
    let e = err(
        Shape::<D3>::Obstacle {
            center: DVec3::ZERO,
            diameter: 0.0,
        },
        Motion::Fixed,
    );
    assert!(e.contains("obstacle diameter"), "{e}");
    let e = err(
        Shape::<D2>::Plane {
            point: DVec2::new(f64::NAN, 0.0),
            normal: DVec2::Y,
        },
        Motion::Fixed,
    );
    assert!(e.contains("not finite"), "{e}");
    let e = err(
        plane2(),
        Motion::Vibrate {
            direction: DVec2::Y,
            amplitude: 1e-3,
            modulation: 0.0,
            wavelength: 0.0,
            frequency: -1.0,
            phase: 0.0,
        },
    );
    assert!(e.contains("'left'") && e.contains("frequency"), "{e}");
    let e = err(
        plane2(),
        Motion::Vibrate {
            direction: DVec2::ZERO,
            amplitude: 1e-3,
            modulation: 0.0,
            wavelength: 0.0,
            frequency: 1.0,
            phase: 0.0,
        },
    );
    assert!(e.contains("direction"), "{e}");
    let e = err(
        plane2(),
        Motion::Vibrate {
            direction: DVec2::Y,
            amplitude: 1e-3,
            modulation: 0.5,
            wavelength: 0.0,
            frequency: 1.0,
            phase: 0.0,
        },
    );
    assert!(e.contains("wavelength"), "{e}");
    let e = err(
        plane2(),
        Motion::Oscillate {
            amplitude: DVec2::X,
            frequency: f64::INFINITY,
            phase: 0.0,
        },
    );
    assert!(e.contains("frequency"), "{e}");
    let e = Wall::<D2>::new("x", plane2(), Motion::Fixed)
        .unwrap()
        .with_remove_at(f64::NAN)
        .unwrap_err()
        .to_string();
    assert!(e.contains("removal time"), "{e}");
}

#[test]
fn serde_round_trip() {
    let w = plate(0.5).with_remove_at(2.0).unwrap();
    let s = serde_json::to_string(&w).unwrap();
    assert!(s.contains("\"type\":\"vibrate\""), "{s}");
    let back: Wall<D2> = serde_json::from_str(&s).unwrap();
    assert_eq!(back, w);
    let d = Wall::<D3>::new(
        "drum",
        Shape::Cylinder {
            point: DVec3::ZERO,
            axis: DVec3::Y,
            radius: 1.0,
            inside: true,
        },
        Motion::Rotate {
            center: DVec3::ZERO,
            omega: DVec3::new(0.0, 2.0, 0.0),
        },
    )
    .unwrap();
    let back: Wall<D3> = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_eq!(back, d);
}

/// Two coplanar squares that share an edge marked as a seam on both act as
/// one rectangle: a sphere anywhere across the seam (and exactly on it) feels
/// the single-face overlap once, never an edge contact.
#[test]
fn polygon_seam_pushes_once() {
    let sq = |x0: f64, seams: Vec<usize>| {
        fixed3(Shape::Polygon {
            vertices: vec![
                DVec3::new(x0, 0.0, 0.0),
                DVec3::new(x0 + 1.0, 0.0, 0.0),
                DVec3::new(x0 + 1.0, 1.0, 0.0),
                DVec3::new(x0, 1.0, 0.0),
            ],
            seams,
        })
    };
    // Edge 1 of the left square (x = 1, going +y) meets edge 3 of the right
    // one (x = 1, going −y).
    let (left, right) = (sq(0.0, vec![1]), sq(1.0, vec![3]));
    for x in [0.7, 0.95, 1.0 - 1e-12, 1.0, 1.0 + 1e-12, 1.05, 1.3] {
        let p = DVec3::new(x, 0.5, 0.3);
        let touches: Vec<_> = [&left, &right]
            .iter()
            .filter_map(|w| w.contact(p, 0.5, 0.0))
            .collect();
        assert_eq!(touches.len(), 1, "x = {x}: {} contacts", touches.len());
        assert!(near(touches[0].overlap, 0.2), "x = {x}");
        assert!(near3(touches[0].normal, DVec3::Z), "x = {x}");
    }
    // Without seams both squares push a sphere near the shared edge.
    let (l, r) = (sq(0.0, vec![]), sq(1.0, vec![]));
    let p = DVec3::new(1.05, 0.5, 0.3);
    assert!(l.contact(p, 0.5, 0.0).is_some() && r.contact(p, 0.5, 0.0).is_some());
    // A real edge (not a seam) still acts: beyond x = 2 the right square's rim.
    let c = right.contact(DVec3::new(2.2, 0.5, 0.3), 0.5, 0.0).unwrap();
    assert!(c.overlap > 0.0 && c.normal.x > 0.0);
    // A rim collinear with a seam (an orifice beside a joint): x = 1 is a seam
    // for y < 1 and a real edge for 1 < y < 2.
    let piece = fixed3(Shape::Polygon {
        vertices: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ],
        seams: vec![1],
    });
    let c = piece.contact(DVec3::new(1.2, 1.5, 0.1), 0.5, 0.0).unwrap();
    assert!(near(c.overlap, 0.5 - 0.05_f64.sqrt()) && c.normal.x > 0.0);
    assert!(piece.contact(DVec3::new(1.2, 0.5, 0.1), 0.5, 0.0).is_none());
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

/// A translated plane rejects far grains with its own distance test before
/// the general path (`PlacedWall`): at the edges of contact (exactly r in
/// front: none; exactly r behind: still in contact) it must answer as
/// `flat::plane` does on the grain carried back into the wall's frame.
#[test]
fn a_moving_plane_answers_at_the_edges_as_the_plane_contact() {
    let wall: Wall<D3> = Wall::new(
        "floor",
        Shape::Plane {
            point: DVec3::new(0.3, -0.2, 1.0),
            normal: DVec3::new(0.0, 0.6, 0.8),
        },
        Motion::Translate {
            velocity: DVec3::new(0.1, 0.2, -0.3),
        },
    )
    .unwrap();
    let (n, r) = (DVec3::new(0.0, 0.6, 0.8), 0.5);
    for t in [0.0, 0.7, 2.9] {
        let shift = DVec3::new(0.1, 0.2, -0.3) * t;
        let on_plane = DVec3::new(0.3, -0.2, 1.0) + shift + DVec3::new(4.0, 0.8, -0.6);
        for s in [
            r,
            r * (1.0 - 1e-15),
            0.2,
            0.0,
            -r,
            -r * (1.0 + 1e-15),
            3.0,
            -3.0,
        ] {
            let p = on_plane + n * s;
            let expected = flat::plane(p - shift, DVec3::new(0.3, -0.2, 1.0), n, r);
            let got = wall.at(t).contact(p, r);
            assert_eq!(
                got.map(|c| c.overlap),
                expected.map(|c| c.overlap),
                "t {t}, s {s}"
            );
        }
    }
}

/// Over a grid of grain positions in front of a modulated plate and of
/// times, the quick test turns down only grains the exact contact misses
/// too (and then `contact` says no contact); it turns some down. Heights
/// `h` along the normal up to 18 % past the bound.
fn check_quick_test(w: &Wall<D2>, bound: f64, r: f64) {
    let Shape::Plane { point, normal } = w.shape else {
        panic!("a plate");
    };
    let Motion::Vibrate {
        frequency: f,
        wavelength: l,
        ..
    } = w.motion
    else {
        panic!("vibrated");
    };
    let (mut turned_down, mut touching) = (0, 0);
    for it in 0..100 {
        let t = it as f64 / (100.0 * f);
        let placed = w.at(t);
        let test = lifted_of(&placed);
        for ix in 0..100 {
            let x = l * ix as f64 / 100.0;
            for ih in 0..60 {
                let h = bound * 1.2 * ih as f64 / 60.0;
                let p = DVec2::new(x, point.y) + normal * h;
                let slope = w.motion.modulation_slope(x, t).unwrap();
                let exact = w.modulated_contact(p, r, t, slope);
                touching += exact.is_some() as usize;
                if test.misses(to3::<D2>(p), r) {
                    turned_down += 1;
                    assert!(
                        exact.is_none(),
                        "x {x}, h {h}, t {t}: touching but turned down"
                    );
                    assert!(placed.contact(p, r).is_none());
                } else {
                    assert_eq!(placed.contact(p, r).is_some(), exact.is_some());
                }
            }
        }
    }
    assert!(touching > 0 && turned_down > 0, "{touching} {turned_down}");
}

/// The quick test of a modulated plate is safe (see [`check_quick_test`])
/// for plates facing up and down, driven along and against the normal,
/// with negative amplitudes and modulations, and tight where the plate is
/// highest.
#[test]
fn modulated_plate_quick_test_is_safe_and_tight() {
    // A deep modulation (tilt up to 13°) driven along a direction at 30° to
    // the normal, so that both bounds are scaled by |d · n|.
    let (a0, b, l, f) = (1.5, 0.5, 20.0, 20.0);
    let slanted = DVec2::new(0.5, 0.75f64.sqrt());
    let along = slanted.y;
    let lift = a0 * (1.0 + b) * along;
    let root = (1.0 + (a0 * b * TAU / l * along).powi(2)).sqrt();
    let r = 0.5;
    let floor = DVec2::new(0.0, -2.0);
    for (normal, direction, a, m) in [
        (DVec2::Y, slanted, a0, b),
        (DVec2::Y, -slanted, -a0, b),
        (DVec2::Y, slanted, a0, -b),
        (-DVec2::Y, slanted, a0, b),
        (-DVec2::Y, -slanted, -a0, -b),
    ] {
        let w = vibrated_plate_2d(floor, normal, direction, [a, m, l, f, 0.3]);
        check_quick_test(&w, lift + r * root, r);
    }
    // Where and when the floor is highest (x = L/2, sine 1) it is flat: a
    // grain a millionth of r short of touching it is kept.
    let w = vibrated_plate_2d(floor, DVec2::Y, slanted, [a0, b, l, f, 0.3]);
    let t = (PI / 2.0 - 0.3) / (TAU * f);
    let top = DVec2::new(l / 2.0, -2.0 + lift + r * (1.0 - 1e-6));
    assert!(w.contact(top, r, t).is_some());
    // Just past the bound: turned down whatever x and t.
    let far = DVec2::new(3.0, -2.0 + (lift + r * root) * 1.001);
    assert!(lifted_of(&w.at(0.0)).misses(to3::<D2>(far), r));
    // A plate that is not modulated keeps its own (exact) test.
    let plain = vibrated_plate_2d(DVec2::ZERO, DVec2::Y, DVec2::Y, [a0, 0.0, l, f, 0.0]);
    assert!(matches!(plain.at(0.1).quick, Some(QuickTest::Plane(_))));
}

/// Finite shapes (a triangle in 3D, a segment and a disk in 2D), fixed,
/// shaken and turning: the bounding-box test turns down only grains the
/// shape's own test misses too, turns down most far grains, and keeps a
/// grain just inside its reach.
#[test]
fn finite_walls_reach_box_is_safe() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
    let triangle = Shape::<D3>::Polygon {
        vertices: vec![
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.5, 1.2),
            DVec3::new(0.5, 2.0, 0.8),
        ],
        seams: vec![],
    };
    let motions3 = motions3();
    let mut turned_down = 0;
    for motion in motions3 {
        let w = Wall::new("triangle", triangle.clone(), motion).unwrap();
        for _ in 0..20_000 {
            let t = rng.gen_range(0.0..2.0);
            let p = DVec3::new(
                rng.gen_range(-1.5..3.5),
                rng.gen_range(-1.5..3.5),
                rng.gen_range(-0.5..2.5),
            );
            let r = rng.gen_range(0.05..0.6);
            turned_down += check_reach(&w, p, r, t) as usize;
        }
    }
    let shapes2 = [
        Shape::<D2>::Segment {
            a: DVec2::new(0.0, 0.0),
            b: DVec2::new(2.0, 1.0),
        },
        Shape::<D2>::Obstacle {
            center: DVec2::new(1.0, 1.0),
            diameter: 1.5,
        },
    ];
    for shape in shapes2 {
        for motion in [
            Motion::Fixed,
            Motion::Rotate {
                center: DVec2::ZERO,
                omega: 0.7,
            },
        ] {
            let w = Wall::new("finite", shape.clone(), motion).unwrap();
            for _ in 0..20_000 {
                let t = rng.gen_range(0.0..2.0);
                let p = DVec2::new(rng.gen_range(-1.5..3.5), rng.gen_range(-1.5..3.5));
                let r = rng.gen_range(0.05..0.6);
                turned_down += check_reach(&w, p, r, t) as usize;
            }
        }
    }
    // About 115 000 lie beyond their reach; a box that turned down only
    // one side's grains would stop near 85 000.
    assert!(
        turned_down > 100_000,
        "only {turned_down} of 140000 turned down"
    );
    // Just inside the reach on the low side: kept, and touching (a sphere
    // and a disk, whose nearest point there is on the box's face).
    let sphere = Wall::new(
        "sphere",
        Shape::<D3>::Obstacle {
            center: DVec3::new(1.0, 1.0, 1.0),
            diameter: 1.5,
        },
        Motion::Fixed,
    )
    .unwrap();
    let p = DVec3::new(1.0 - 0.75 - 0.5 * (1.0 - 1e-6), 1.0, 1.0);
    assert!(!check_reach(&sphere, p, 0.5, 0.0) && sphere.contact(p, 0.5, 0.0).is_some());
    let disk = Wall::new(
        "disk",
        Shape::<D2>::Obstacle {
            center: DVec2::new(1.0, 1.0),
            diameter: 1.5,
        },
        Motion::Fixed,
    )
    .unwrap();
    let p = DVec2::new(1.0, 1.0 - 0.75 - 0.5 * (1.0 - 1e-6));
    assert!(!check_reach(&disk, p, 0.5, 0.0) && disk.contact(p, 0.5, 0.0).is_some());
    // A grain a millionth of r inside its reach of the triangle's corner
    // along x is kept (and touches, the corner being the nearest point).
    let w = Wall::new("triangle", triangle, Motion::Fixed).unwrap();
    let p = DVec3::new(2.0 + 0.5 * (1.0 - 1e-6), 0.5, 1.2);
    assert!(!reach_of(&w.at(0.0)).misses(p, 0.5));
    assert!(w.contact(p, 0.5, 0.0).is_some());
}

/// Whether `w`'s bounding box turns the grain down at `t`; if it does, the
/// shape's own test must find no contact either.
fn check_reach<D: Dim>(w: &Wall<D>, p: D::V, r: f64, t: f64) -> bool {
    let placed = w.at(t);
    let pose = placed.pose.expect("a finite wall has one pose");
    let local = pose.invert(to3::<D>(p));
    let exact = w.shape.touch(local, r);
    let missed = reach_of(&placed).misses(local, r);
    let mut near = [false];
    placed.mark_near(&[p], &[r], &mut near);
    assert_eq!(near[0], !missed, "mark_near and contact disagree");
    if missed {
        assert!(
            exact.is_none(),
            "{p:?}, r {r}, t {t}: touching but turned down"
        );
    }
    assert_eq!(placed.contact(p, r).is_some(), exact.is_some());
    missed
}

/// A polygon whose vertices stray from one plane by less than validation
/// allows: `touch` meets it projected onto the plane of its first vertex,
/// a little outside the box of the vertices alone. A grain touching it
/// there is kept.
#[test]
fn reach_box_holds_a_slightly_warped_polygon() {
    let (delta, theta) = (0.99e-9, 1e-6);
    let vertices = vec![
        DVec3::new(-1.0, 0.0, delta),
        DVec3::new(0.0, -1.0, -theta - delta),
        DVec3::new(1.0, 0.0, delta),
        DVec3::new(0.0, 1.0, theta - delta),
    ];
    let normal = flat::polygon_normal(4, |i| vertices[i]);
    let shape = Shape::<D3>::Polygon {
        vertices,
        seams: vec![],
    };
    let w = Wall::new("warped", shape, Motion::Fixed).unwrap();
    let r = 0.1;
    let q = DVec3::new(0.0, 1.0 - 1e-6, theta * (1.0 - 1e-6) + delta);
    let p = q + normal * (r - 5e-10);
    assert!(w.shape.touch(p, r).is_some(), "the example touches");
    assert!(!check_reach(&w, p, r, 0.0));
}

/// The quick test of a modulated plate.
fn lifted_of<D: Dim>(w: &PlacedWall<D>) -> LiftedTest {
    match w.quick {
        Some(QuickTest::Lifted(t)) => t,
        other => panic!("a modulated plate has the lifted test, not {other:?}"),
    }
}

/// The bounding box of a finite shape.
fn reach_of<D: Dim>(w: &PlacedWall<D>) -> ReachBox {
    match w.quick {
        Some(QuickTest::Reach(b)) => b,
        other => panic!("a finite shape has its box, not {other:?}"),
    }
}

/// A placed cylinder's quick test is its exact test in the wall's frame:
/// the wall pass marks exactly the grains that touch it, for drums and
/// posts, fixed, shaken and turning, in 2D and 3D. Grains are thrown
/// around the surface, within a radius of it, so that many touch.
#[test]
fn cylinder_quick_test_marks_exactly_the_touching_grains() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
    let (radius, n, times) = (2.0, 4000, [0.0, 0.4, 1.7]);
    // Polar coordinates about the axis (through the origin), grain radius.
    let mut polar = || {
        (
            rng.gen_range(0.0..TAU),
            rng.gen_range(1.0..3.0),
            rng.gen_range(0.05..0.5),
            rng.gen_range(-3.0..3.0),
        )
    };
    let grains2: Vec<(DVec2, f64)> = (0..n)
        .map(|_| {
            let (angle, rho, r, _) = polar();
            (DVec2::new(rho * angle.cos(), rho * angle.sin()), r)
        })
        .collect();
    let axis = DVec3::new(0.3, -0.2, 1.0).normalize();
    let across = geom::perpendicular(axis);
    let other = axis.cross(across);
    let grains3: Vec<(DVec3, f64)> = (0..n)
        .map(|_| {
            let (angle, rho, r, h) = polar();
            let p = axis * h + (across * angle.cos() + other * angle.sin()) * rho;
            (p, r)
        })
        .collect();
    let motions2 = [
        Motion::Fixed,
        Motion::Oscillate {
            amplitude: DVec2::new(0.3, 0.2),
            frequency: 2.0,
            phase: 0.1,
        },
        Motion::Rotate {
            center: DVec2::new(0.5, -0.2),
            omega: 3.0,
        },
    ];
    let motions3 = motions3();
    for inside in [true, false] {
        for motion in &motions2 {
            let shape = Shape::Cylinder {
                point: DVec2::ZERO,
                axis: DVec2::ZERO,
                radius,
                inside,
            };
            let w = Wall::<D2>::new("ring", shape, motion.clone()).unwrap();
            let touching: usize = times.iter().map(|&t| marks_match(&w, &grains2, t)).sum();
            assert!(touching > n / 5, "{touching} of {} touch", 3 * n);
        }
        for motion in &motions3 {
            let shape = Shape::Cylinder {
                point: DVec3::ZERO,
                axis,
                radius,
                inside,
            };
            let w = Wall::<D3>::new("tube", shape, motion.clone()).unwrap();
            let touching: usize = times.iter().map(|&t| marks_match(&w, &grains3, t)).sum();
            assert!(touching > n / 5, "{touching} of {} touch", 3 * n);
        }
    }
}

/// Checks that the wall pass's marks at `t` are exactly the grains that
/// `contact` finds touching; returns how many touch.
fn marks_match<D: Dim>(w: &Wall<D>, grains: &[(D::V, f64)], t: f64) -> usize {
    let placed = w.at(t);
    assert!(
        matches!(placed.quick, Some(QuickTest::Cylinder(_))),
        "a cylinder with one pose has its quick test"
    );
    let pos: Vec<D::V> = grains.iter().map(|g| g.0).collect();
    let radius: Vec<f64> = grains.iter().map(|g| g.1).collect();
    let mut near = vec![false; grains.len()];
    placed.mark_near(&pos, &radius, &mut near);
    let mut touching = 0;
    for (k, &(p, r)) in grains.iter().enumerate() {
        let exact = w.contact(p, r, t).is_some();
        assert_eq!(near[k], exact, "grain {k} at {p:?}, r {r}, t {t}");
        touching += exact as usize;
    }
    touching
}

/// A fixed, a shaken and a turning motion in 3D, for the quick tests.
fn motions3() -> [Motion<D3>; 3] {
    [
        Motion::Fixed,
        Motion::Oscillate {
            amplitude: DVec3::new(0.3, 0.0, 0.2),
            frequency: 2.0,
            phase: 0.1,
        },
        Motion::Rotate {
            center: DVec3::new(1.0, 1.0, 0.0),
            omega: DVec3::new(0.0, 0.3, 1.0),
        },
    ]
}
