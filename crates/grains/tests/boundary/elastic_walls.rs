//! Elastic walls: with no damping and no friction, a grain bouncing off a
//! plane, a segment's end cap, a polygon's edge and vertex, a cylinder, or
//! a moving plane (in the plane's frame) leaves with the kinetic energy it
//! came with, at normal and at grazing incidence.
//!
//! Each wall's overlap is a function of the grain's position only (the
//! distance to the nearest point of the shape), so the Hooke force is the
//! gradient of ½ k ξ² and the bounce is elastic; velocity Verlet keeps the
//! energy to O((dt/t_c)²) over a contact entered between two steps: with
//! t_c/dt = 200, 2.5e-5 (measured: 3e-7 head-on, 2e-6 grazing).

use crate::common;

use common::*;
use glam::{DVec2, DVec3};
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::MassScaling;
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Dim, Particles, D2, D3};

const KN: f64 = 1.0e5;
const TOLERANCE: f64 = 2.5e-5;

/// One bounce: a grain of diameter 1 starting at `x0` with velocity `v0`
/// against `wall`, whose surface moves at `frame` (zero for a fixed wall).
/// Runs until the grain is well clear again; returns the final velocity
/// after checking the energy in the wall's frame.
fn bounce<D: Dim>(
    what: &str,
    shape: Shape<D>,
    motion: Motion<D>,
    frame: D::V,
    x0: D::V,
    v0: D::V,
    time: f64,
) -> D::V {
    let law = hooke(KN, 0.0, MassScaling::Reduced);
    let mut g = grain::<D>(0, x0, 1.0);
    g.vel = v0;
    // t_c = π √(m/k): with m = π/6 (a unit sphere), 7.2e-3 s.
    let tc = std::f64::consts::PI * (g.mass / KN).sqrt();
    let mut s = MdSettings::<D>::new(tc / 200.0, law, 0.1);
    s.integrator = Integrator::Verlet;
    let mut p = Particles::new();
    p.push_record(g);
    let wall = Wall::new(what, shape, motion).unwrap();
    let mut md = Md::new(p, open_box(50.0), vec![wall], s).unwrap();
    let e = |v: D::V| 0.5 * D::norm2(v - frame);
    let e0 = e(v0);
    let mut touched = false;
    let steps = (time / md.settings.dt) as u64;
    for _ in 0..steps / 100 {
        md.run(100).unwrap();
        touched |= md.particles.vel[0] != v0;
    }
    let v1 = md.particles.vel[0];
    assert!(touched, "{what}: never touched the wall");
    // Clear of the wall: no force over a further stretch.
    md.run(100).unwrap();
    assert_eq!(md.particles.vel[0], v1, "{what}: still touching");
    let err = (e(v1) - e0).abs() / e0;
    eprintln!("{what}: relative energy change {err:.2e}");
    assert!(
        err < TOLERANCE,
        "{what}: kinetic energy in the wall's frame {e0} -> {} (relative {err:.2e})",
        e(v1)
    );
    v1
}

/// Unit vector in the x–y plane at `deg` degrees from −x towards +y, etc.
fn dir2(deg: f64) -> DVec2 {
    let a = deg.to_radians();
    DVec2::new(a.cos(), a.sin())
}

#[test]
fn plane_2d_normal_and_grazing() {
    let floor = || Shape::Plane {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    };
    // Normal: straight down from 0.05 above contact; grazing: 85° from the
    // normal, so the normal speed is 0.087 m/s.
    for (what, v0) in [
        ("plane normal", DVec2::new(0.0, -1.0)),
        ("plane grazing", dir2(-5.0)),
    ] {
        let v1 = bounce::<D2>(
            what,
            floor(),
            Motion::Fixed,
            DVec2::ZERO,
            DVec2::new(0.0, 0.55),
            v0,
            0.05 / -v0.y * 2.5,
        );
        assert!(v1.y > 0.0 && (v1.x - v0.x).abs() < 1e-12, "{what}: {v1}");
    }
}

#[test]
fn segment_end_cap_normal_and_grazing() {
    let seg = || Shape::Segment {
        a: DVec2::new(-3.0, 0.0),
        b: DVec2::ZERO,
    };
    // Head-on into the end b along the segment's line; then with an impact
    // parameter of 0.45 (contact normal 64° from the motion) and 0.49.
    for (what, y0) in [
        ("cap normal", 0.0),
        ("cap grazing", 0.45),
        ("cap nearly missing", 0.49),
    ] {
        let v1 = bounce::<D2>(
            what,
            seg(),
            Motion::Fixed,
            DVec2::ZERO,
            DVec2::new(0.6, y0),
            DVec2::new(-1.0, 0.0),
            0.6,
        );
        if y0 == 0.0 {
            assert!(v1.x > 0.0, "{what}: {v1}");
        } else {
            assert!(v1.y > 0.0, "{what}: {v1}");
        }
    }
}

#[test]
fn cylinder_2d_inside_normal_and_grazing() {
    let drum = || Shape::Cylinder {
        point: DVec2::ZERO,
        axis: DVec2::ZERO,
        radius: 3.0,
        inside: true,
    };
    // From the centre along x: hits at x = 2.5 head-on. Along a chord at
    // height 2.45: the contact normal is 78° from the motion.
    // The grazing grain meets the wall again after a chord of 1.04 m.
    for (what, y0, time) in [("drum normal", 0.0, 4.0), ("drum grazing", 2.45, 1.0)] {
        let v1 = bounce::<D2>(
            what,
            drum(),
            Motion::Fixed,
            DVec2::ZERO,
            DVec2::new(0.0, y0),
            DVec2::X,
            time,
        );
        assert!(v1.x < 0.0 || v1.y < 0.0, "{what}: {v1}");
    }
}

#[test]
fn moving_plane_keeps_energy_in_its_frame() {
    // The floor rises at 0.3 m/s and slides at 0.7 m/s; in its frame the
    // bounce is elastic (in the lab the grain gains 2 × 0.3 m/s upwards).
    let wall_v = DVec2::new(0.7, 0.3);
    for (what, v0) in [
        ("moving normal", DVec2::new(0.0, -1.0)),
        ("moving grazing", DVec2::new(2.0, -0.2)),
    ] {
        let v1 = bounce::<D2>(
            what,
            Shape::Plane {
                point: DVec2::ZERO,
                normal: DVec2::Y,
            },
            Motion::Translate { velocity: wall_v },
            wall_v,
            DVec2::new(0.0, 0.6),
            v0,
            0.5,
        );
        let want_vy = 2.0 * wall_v.y - v0.y;
        assert!(
            (v1.y - want_vy).abs() < 1e-3 * want_vy,
            "{what}: {v1}, vy should be {want_vy}"
        );
    }
}

fn square() -> Shape<D3> {
    Shape::Polygon {
        vertices: vec![
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ],
        seams: Vec::new(),
    }
}

#[test]
fn polygon_edge_normal_and_grazing() {
    // Into the edge x = 1 within the polygon's plane; then from above the
    // plane with an impact parameter of 0.45 (the edge's rounded side).
    for (what, z0) in [("edge normal", 0.0), ("edge grazing", 0.45)] {
        let v1 = bounce::<D3>(
            what,
            square(),
            Motion::Fixed,
            DVec3::ZERO,
            DVec3::new(1.6, 0.2, z0),
            -DVec3::X,
            0.6,
        );
        assert!(
            if z0 == 0.0 { v1.x > 0.0 } else { v1.z > 0.0 },
            "{what}: {v1}"
        );
    }
}

#[test]
fn polygon_vertex_normal_and_grazing() {
    let diag = DVec3::new(1.0, 1.0, 0.0).normalize();
    for (what, z0) in [("vertex normal", 0.0), ("vertex grazing", 0.45)] {
        let x0 = DVec3::new(1.0, 1.0, z0) + diag * 0.6;
        let v1 = bounce::<D3>(what, square(), Motion::Fixed, DVec3::ZERO, x0, -diag, 0.6);
        assert!(
            if z0 == 0.0 {
                v1.dot(diag) > 0.0
            } else {
                v1.z > 0.0
            },
            "{what}: {v1}"
        );
    }
}

#[test]
fn cylinder_3d_inside_normal_and_grazing() {
    let pipe = || Shape::Cylinder {
        point: DVec3::ZERO,
        axis: DVec3::Z,
        radius: 3.0,
        inside: true,
    };
    // Across the pipe, head-on and along a chord 2.45 off the axis, with
    // some motion along the axis as well.
    for (what, y0, time) in [("pipe normal", 0.0, 4.0), ("pipe grazing", 2.45, 1.0)] {
        let v0 = DVec3::new(1.0, 0.0, 0.3);
        let v1 = bounce::<D3>(
            what,
            pipe(),
            Motion::Fixed,
            DVec3::ZERO,
            DVec3::new(0.0, y0, 0.0),
            v0,
            time,
        );
        assert!(
            (v1.x < 0.0 || v1.y < 0.0) && (v1.z - v0.z).abs() < 1e-12,
            "{what}: {v1}"
        );
    }
}
