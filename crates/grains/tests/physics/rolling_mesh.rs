//! epsd rolling resistance on a mesh floor against the plane it stands
//! for and against the closed form of a ball rolling at the torque cap.
//!
//! A ball rolling without slipping on a floor, held back by a rolling
//! torque at its cap M = μ_r R* |F_n| (R* = R against a wall, |F_n| = m g):
//! (m + I/R²) a = −M/R, so with I = (2/5) m R² it decelerates at
//! a = −(5/7) μ_r g, whatever the spring's stiffness, until the spring
//! holds it. On a flat mesh the rolling spring is kept per (grain, wall,
//! patch) as the tangential one is; the ball must stop where it stops on
//! the plane.

use super::jkr::forget_rolling_springs;
use super::rolling::ball_on;
use glam::DVec3;
use grains::boundary::{Mesh, MeshPlacement, Motion, Shape, Wall};
use grains::contact::rolling::RollingModel;
use grains::md::Md;
use grains::D3;
use std::sync::Arc;

const R: f64 = 0.01;
const G: f64 = 9.81;

/// An n × n grid of squares over [lo, hi]² (x, y) at z = 0, each cut in
/// two along alternating diagonals: one flat patch of 2 n² triangles.
fn sheet(n: usize, lo: f64, hi: f64) -> Vec<[[f64; 3]; 3]> {
    let h = (hi - lo) / n as f64;
    let at = |i: usize| lo + i as f64 * h;
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b) = ([at(i), at(j), 0.0], [at(i + 1), at(j), 0.0]);
            let (c, d) = ([at(i + 1), at(j + 1), 0.0], [at(i), at(j + 1), 0.0]);
            if (i + j) % 2 == 0 {
                out.extend([[a, b, c], [a, c, d]]);
            } else {
                out.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    out
}

/// The floor z = 0 as a plane or as a sheet of triangles 2 mm wide.
fn floor(mesh: bool) -> Wall<D3> {
    if mesh {
        let tris = sheet(50, -0.05, 0.05);
        let m = Mesh::new("sheet", &tris, &MeshPlacement::default()).unwrap();
        Wall::new("sheet", Shape::Mesh(Arc::new(m)), Motion::Fixed).unwrap()
    } else {
        let plane = Shape::Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        };
        Wall::new("plane", plane, Motion::Fixed).unwrap()
    }
}

/// What one ball does, rolling at 0.1 m/s at 20° to the x axis (across
/// the triangles' edges) on `floor` with epsd, μ_r = 0.1: its speed at
/// 0.02 s and 0.10 s (while it rolls at the cap) and where it stops.
struct Rolled {
    v1: f64,
    v2: f64,
    stop: DVec3,
    stop_time: f64,
}

fn roll(mesh: bool) -> (Rolled, Md<D3>) {
    let v0 = 0.1;
    let dir = DVec3::new(20f64.to_radians().cos(), 20f64.to_radians().sin(), 0.0);
    let g = DVec3::new(0.0, 0.0, -G);
    let at = DVec3::new(1.3e-3, 0.7e-3, 0.0);
    let mut md = ball_on(floor(mesh), RollingModel::Epsd, 0.1, g, [at, dir * v0]);
    let speed = |md: &Md<D3>| md.particles.vel[0].dot(dir);
    md.run(1_000).unwrap();
    let v1 = speed(&md);
    md.run(4_000).unwrap();
    let v2 = speed(&md);
    while speed(&md) > 0.0 && md.time < 0.5 {
        md.step().unwrap();
    }
    let rolled = Rolled {
        v1,
        v2,
        stop: md.particles.pos[0],
        stop_time: md.time,
    };
    (rolled, md)
}

/// On the plane and on the mesh the ball decelerates at (5/7) μ_r g to
/// 1e-6 while the spring slides at its cap, and stops at the same place
/// on both (to 1e-9 of the distance: the same arithmetic, the mesh's
/// contact found through its triangles); its spring then holds it.
#[test]
fn epsd_stops_a_ball_on_a_mesh_floor_where_it_stops_on_the_plane() {
    let (plane, _) = roll(false);
    let (mesh, mut md) = roll(true);
    let want = 5.0 / 7.0 * 0.1 * G;
    for (name, r) in [("plane", &plane), ("mesh", &mesh)] {
        let a = (r.v1 - r.v2) / (4_000.0 * 2e-5);
        let rel = (a - want).abs() / want;
        println!(
            "{name}: deceleration {a:.9} m/s² (closed form {want:.9}, off {rel:.1e}), \
             stopped at {:?} after {:.4} s",
            r.stop, r.stop_time
        );
        assert!(rel < 1e-6, "{name}: deceleration {a} against {want}");
        assert!(r.stop_time < 0.5, "{name}: never stopped");
    }
    let start = DVec3::new(1.3e-3, 0.7e-3, 0.0);
    let travel = (plane.stop - start).truncate().length();
    let gap = (mesh.stop - plane.stop).length();
    // Rolling at the cap all the way: s = v₀² / (2 a) = 7 v₀² / (10 μ_r
    // g), 7.1 mm, over some eight triangle edges of the mesh. The spring's
    // build-up at the start (below the cap) and its give at the stop add
    // a little.
    let closed = 0.1 * 0.1 / (2.0 * want);
    println!(
        "travel {travel:.6e} m (closed form {closed:.6e}, off {:.2e}), mesh − plane {gap:.1e} m",
        (travel - closed) / closed
    );
    assert!((travel - closed).abs() < 0.05 * closed, "travel {travel}");
    assert!(gap < 1e-9 * travel, "mesh and plane stop {gap:e} m apart");
    assert!((plane.stop_time - mesh.stop_time).abs() < 1.5 * 2e-5);
    // Held: after the stop the spring keeps the ball within its give.
    let held = md.particles.pos[0];
    md.run(10_000).unwrap();
    let crept = (md.particles.pos[0] - held).length();
    assert!(crept < 0.05 * R, "crept {crept:e} m after the stop");
}

/// A mesh wall's rolling springs travel in a checkpoint (a tagged section
/// of the MD state): a ball held by epsd on the mesh floor tilted to
/// tan θ = 0.05 (below μ_r = 0.1: the spring holds it, short of its cap),
/// saved after 2000 steps and restored into a fresh engine, continues bit
/// for bit; without its rolling spring it would take another path.
#[test]
fn mesh_rolling_springs_resume_bit_for_bit() {
    let theta = 0.05f64.atan();
    let g = DVec3::new(G * theta.sin(), 0.0, -G * theta.cos());
    let at = DVec3::new(1.3e-3, 0.7e-3, 0.0);
    let fresh = || ball_on(floor(true), RollingModel::Epsd, 0.1, g, [at, DVec3::ZERO]);
    let mut md = fresh();
    md.run(2_000).unwrap();
    assert_eq!(md.export_state().unwrap().mesh_rolling.len(), 1);
    let bytes = grains::md::contract::encode(&md).unwrap();
    let mut resumed = fresh();
    grains::md::contract::restore(&mut resumed, &bytes).unwrap();
    md.run(2_000).unwrap();
    resumed.run(2_000).unwrap();
    let bits = |m: &Md<D3>| {
        let p = &m.particles;
        [p.pos[0], p.vel[0], p.omega[0]].map(|v| v.to_array().map(f64::to_bits))
    };
    assert_eq!(bits(&md), bits(&resumed));
    let mut forgetful = fresh();
    grains::md::contract::restore(&mut forgetful, &bytes).unwrap();
    forget_rolling_springs(&mut forgetful);
    forgetful.run(2_000).unwrap();
    assert_ne!(bits(&md), bits(&forgetful));
}
