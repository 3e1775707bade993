//! 2D mesh walls (polylines) against the analytic walls they stand for: a
//! straight run of many segments is a line, an L is two lines, and a convex
//! corner pushes once.

use crate::common;

use common::*;
use glam::{DVec2, DVec3};
use grains::boundary::{Mesh, MeshPlacement, Motion, Shape, Wall};
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Particles, D2};
use std::sync::Arc;

fn polyline_wall(name: &str, points: Vec<[f64; 2]>, place: &MeshPlacement) -> Wall<D2> {
    let mesh = Mesh::from_polylines(name, &[points], place).unwrap();
    Wall::new(name, Shape::Mesh(Arc::new(mesh)), Motion::Fixed).unwrap()
}

fn line(name: &str, point: DVec2, normal: DVec2) -> Wall<D2> {
    Wall::new(name, Shape::Plane { point, normal }, Motion::Fixed).unwrap()
}

fn md(pos: DVec2, vel: DVec2, omega: f64, walls: Vec<Wall<D2>>, mu: f64, g: DVec2) -> Md<D2> {
    let mut s = MdSettings::<D2>::new(2e-5, wall_law::<D2>(mu), 0.1);
    s.integrator = Integrator::Verlet;
    s.gravity = g;
    let mut gr = grain::<D2>(0, pos, 1.0);
    gr.vel = vel;
    gr.omega = omega;
    let mut p = Particles::new();
    p.push_record(gr);
    Md::new(p, open_box(30.0), walls, s).unwrap()
}

/// The largest relative difference of two one-grain runs' position,
/// velocity and spin (relative to at least 1e-3, so rounding noise on a
/// quantity near zero does not count).
fn gap(a: &Md<D2>, b: &Md<D2>) -> f64 {
    let (pa, pb) = (&a.particles, &b.particles);
    let rel = |x: DVec2, y: DVec2| (x - y).length() / x.length().max(y.length()).max(1e-3);
    let spin = (pa.omega[0] - pb.omega[0]).abs() / pa.omega[0].abs().max(1e-3);
    rel(pa.pos[0], pb.pos[0])
        .max(rel(pa.vel[0], pb.vel[0]))
        .max(spin)
}

/// 120 collinear segments of uneven length along y = 0, x from −20 to 20.
fn floor_points() -> Vec<[f64; 2]> {
    (0..=120)
        .map(|k| {
            let x = -20.0
                + k as f64 / 3.0
                + if k % 120 == 0 {
                    0.0
                } else {
                    0.07 * (k as f64).sin()
                };
            [x, 0.0]
        })
        .collect()
}

#[test]
fn a_straight_polyline_of_many_segments_is_a_line_for_a_rolling_disk() {
    let g = DVec2::new(0.0, -9.81);
    for mu in [0.0, 0.5] {
        let floor = polyline_wall("floor", floor_points(), &MeshPlacement::default());
        let (x0, v0) = (DVec2::new(-3.1, 0.52), DVec2::new(6.0, -0.8));
        let mut a = md(x0, v0, 3.0, vec![floor], mu, g);
        let mut b = md(x0, v0, 3.0, vec![line("y0", DVec2::ZERO, DVec2::Y)], mu, g);
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            a.run(1000).unwrap();
            b.run(1000).unwrap();
            worst = worst.max(gap(&a, &b));
        }
        let travel = (a.particles.pos[0] - x0).length();
        // Segments are a third of a diameter long: twelve joints at least.
        assert!(travel > 4.0, "mu {mu}: travelled only {travel}");
        assert!(
            worst < 1e-9,
            "mu {mu}: polyline and line differ by {worst:e}"
        );
        assert_eq!(a.stats.contacts, 1, "mu {mu}");
        if mu > 0.0 {
            // Rolling without slipping: v_x = −ω r.
            let (v, w) = (a.particles.vel[0], a.particles.omega[0]);
            assert!((v.x + 0.5 * w).abs() < 1e-3 * v.length(), "v {v}, ω {w}");
        }
    }
}

#[test]
fn a_placed_polyline_is_the_line_it_was_turned_and_moved_to() {
    // The floor scaled by 2, turned by 30° and moved to (1, 2) is the line
    // through (1, 2) with normal (−sin 30°, cos 30°); gravity along −normal.
    let place = MeshPlacement {
        scale: 2.0,
        rotate_deg: [0.0, 0.0, 30.0],
        translate: [1.0, 2.0, 0.0],
    };
    let (s, c) = 30f64.to_radians().sin_cos();
    let (n, t) = (DVec2::new(-s, c), DVec2::new(c, s));
    let g = -9.81 * n + 2.0 * t;
    let x0 = DVec2::new(1.0, 2.0) + 0.52 * n - 3.0 * t;
    let v0 = 4.0 * t - 0.8 * n;
    let floor = polyline_wall("floor", floor_points(), &place);
    let mut a = md(x0, v0, 0.0, vec![floor], 0.5, g);
    let mut b = md(
        x0,
        v0,
        0.0,
        vec![line("l", DVec2::new(1.0, 2.0), n)],
        0.5,
        g,
    );
    for _ in 0..50 {
        a.run(1000).unwrap();
        b.run(1000).unwrap();
        // The turned points are collinear to rounding only: 1e-9.
        assert!(gap(&a, &b) < 1e-9, "differ by {:e}", gap(&a, &b));
    }
    // Landed and rolling, as on the line.
    assert_eq!(a.stats.contacts, 1);
    assert_eq!(b.stats.contacts, 1);
}

#[test]
fn a_disk_in_the_corner_of_an_l_feels_two_lines_and_loads_the_wall() {
    let g = DVec2::new(-4.0, -9.0);
    let corner = polyline_wall(
        "corner",
        vec![[0.0, 4.0], [0.0, 0.0], [4.0, 0.0]],
        &MeshPlacement::default(),
    );
    let x0 = DVec2::new(0.4999, 0.4999);
    let walls = vec![
        line("x0", DVec2::ZERO, DVec2::X),
        line("y0", DVec2::ZERO, DVec2::Y),
    ];
    let mut a = md(x0, DVec2::ZERO, 0.0, vec![corner], 0.5, g);
    let mut b = md(x0, DVec2::ZERO, 0.0, walls, 0.5, g);
    for _ in 0..20 {
        a.run(1000).unwrap();
        b.run(1000).unwrap();
        assert!(gap(&a, &b) < 1e-9, "differ by {:e}", gap(&a, &b));
    }
    assert_eq!(a.stats.contacts, 2);
    // At rest the wall carries the disk's weight.
    let m = a.particles.mass[0];
    let f = a.mesh_loads()[0].force;
    let w = DVec3::new(g.x * m, g.y * m, 0.0);
    assert!((f - w).length() < 1e-6 * w.length(), "{f} vs {w}");
}

#[test]
fn a_disk_on_a_convex_corner_is_pushed_once() {
    // A roof ∧ with its apex at the origin; the disk rests on the apex
    // (by symmetry the contact normal stays vertical). One push: k_n ξ =
    // m g, so the overlap is m g / k_n (two segment walls meeting there
    // would push twice and halve it).
    let roof = polyline_wall(
        "roof",
        vec![[-3.0, -1.0], [0.0, 0.0], [3.0, -1.0]],
        &MeshPlacement::default(),
    );
    let g = DVec2::new(0.0, -9.81);
    let mut a = md(DVec2::new(0.0, 0.5), DVec2::ZERO, 0.0, vec![roof], 0.5, g);
    a.run(40_000).unwrap();
    let m = a.particles.mass[0];
    let overlap = 0.5 - a.particles.pos[0].y;
    let want = m * 9.81 / 1.0e6;
    assert_eq!(a.stats.contacts, 1);
    assert_eq!(a.particles.pos[0].x, 0.0);
    assert!(a.particles.vel[0].length() < 1e-9, "{}", a.particles.vel[0]);
    assert!((overlap - want).abs() < 1e-6 * want, "{overlap} vs {want}");
}
