//! Tests of `Wall` and `PlacedWall` (this module's `mod.rs`), and the
//! helpers the tests beside each wall file share. The tests of each shape's
//! contact and of each motion are beside their files.

use super::*;
use crate::dim::{D2, D3};
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

pub(super) const EPS: f64 = 1e-12;

pub(super) fn near(a: f64, b: f64) -> bool {
    (a - b).abs() < EPS * (1.0 + b.abs())
}
pub(super) fn near2(a: DVec2, b: DVec2) -> bool {
    (a - b).length() < EPS * (1.0 + b.length())
}
pub(super) fn near3(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < EPS * (1.0 + b.length())
}

pub(super) fn fixed2(shape: Shape<D2>) -> Wall<D2> {
    Wall::new("w", shape, Motion::Fixed).unwrap()
}
pub(super) fn fixed3(shape: Shape<D3>) -> Wall<D3> {
    Wall::new("w", shape, Motion::Fixed).unwrap()
}

pub(super) fn plate(modulation: f64) -> Wall<D2> {
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

/// A plate through `point` facing `normal` (±y), vibrated along
/// `direction` with `[A0, B, L, f, phase]`.
pub(super) fn vibrated_plate_2d(
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
