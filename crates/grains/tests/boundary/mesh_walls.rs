//! Mesh walls against the analytic walls they stand for: a flat sheet of
//! many triangles is a plane, a mesh box's corner is two planes, and
//! grazing impacts on a mesh never gain energy; a moving mesh drags as
//! the moving plane does, translating or turning.

use crate::common;

use common::*;
use glam::DVec3;
use grains::boundary::{Mesh, MeshPlacement, Motion, Shape, Wall};
use grains::contact::ContactLaw;
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{ParticleRecord, Particles, D3};
use std::sync::Arc;

type Tri = [[f64; 3]; 3];

/// An n × n grid of squares over [lo, hi]² (x, y) at z = 0, each cut in
/// two along alternating diagonals.
fn sheet(n: usize, lo: f64, hi: f64) -> Vec<Tri> {
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

fn mesh_wall(name: &str, tris: &[Tri], place: &MeshPlacement, motion: Motion<D3>) -> Wall<D3> {
    let mesh = Mesh::new(name, tris, place).unwrap();
    Wall::new(name, Shape::Mesh(Arc::new(mesh)), motion).unwrap()
}

fn plane(name: &str, point: DVec3, normal: DVec3) -> Wall<D3> {
    Wall::new(name, Shape::Plane { point, normal }, Motion::Fixed).unwrap()
}

fn md(grains: Vec<ParticleRecord<D3>>, walls: Vec<Wall<D3>>, law: ContactLaw, g: DVec3) -> Md<D3> {
    let mut s = MdSettings::<D3>::new(2e-5, law, 0.1);
    s.integrator = Integrator::Verlet;
    s.gravity = g;
    let mut p = Particles::new();
    for gr in grains {
        p.push_record(gr);
    }
    Md::new(p, open_box(30.0), walls, s).unwrap()
}

/// The largest difference between two runs' positions, velocities and
/// spins, relative to the larger of each (and to at least 1e-3, so that a
/// spin left at rounding noise, 1e-14, is not compared with its like).
fn gap(a: &Md<D3>, b: &Md<D3>) -> f64 {
    let (pa, pb) = (&a.particles, &b.particles);
    let rel = |x: DVec3, y: DVec3| (x - y).length() / x.length().max(y.length()).max(1e-3);
    (0..pa.len())
        .map(|i| {
            rel(pa.pos[i], pb.pos[i])
                .max(rel(pa.vel[i], pb.vel[i]))
                .max(rel(pa.omega[i], pb.omega[i]))
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_flat_mesh_of_many_triangles_is_a_plane_for_a_rolling_sphere() {
    // Triangles a quarter of the diameter wide; the sphere lands at an
    // angle, bounces, slides and (with friction) rolls over some forty of
    // their edges along a line that cuts the grid obliquely.
    let tris = sheet(160, -20.0, 20.0);
    for mu in [0.0, 0.5] {
        let mut g = grain::<D3>(0, DVec3::new(-3.1, -1.3, 0.52), 1.0);
        g.vel = DVec3::new(6.0, 2.2, -0.8);
        g.omega = DVec3::new(0.0, 0.0, 3.0);
        let gravity = DVec3::new(0.0, 0.0, -9.81);
        let flat = mesh_wall("sheet", &tris, &MeshPlacement::default(), Motion::Fixed);
        let mut a = md(vec![g.clone()], vec![flat], wall_law::<D3>(mu), gravity);
        let mut b = md(
            vec![g],
            vec![plane("floor", DVec3::ZERO, DVec3::Z)],
            wall_law::<D3>(mu),
            gravity,
        );
        let x0 = a.particles.pos[0];
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            a.run(1000).unwrap();
            b.run(1000).unwrap();
            worst = worst.max(gap(&a, &b));
        }
        let travel = (a.particles.pos[0] - x0).length();
        // Over 16 columns and rows of squares, 30 edges and more.
        assert!(travel > 16.0 * 0.25, "mu {mu}: travelled only {travel}");
        // Same arithmetic but for the order of a few sums: 1e-9 leaves
        // room for rounding over 50 000 steps.
        assert!(worst < 1e-9, "mu {mu}: mesh and plane differ by {worst:e}");
        // Still touching at the end (it rolls, it does not fly).
        assert!(
            a.stats.contacts == 1,
            "mu {mu}: {} contacts",
            a.stats.contacts
        );
        if mu > 0.0 {
            // Rolling without slipping: v = ω × r at the contact.
            let (v, w) = (a.particles.vel[0], a.particles.omega[0]);
            let slip = v + w.cross(DVec3::new(0.0, 0.0, -0.5));
            assert!(slip.truncate().length() < 1e-3 * v.length(), "slip {slip}");
        }
    }
}

/// The twelve triangles of the cube [0, l]³ (grains inside).
fn cube(l: f64) -> Vec<Tri> {
    let c = |i: usize| {
        [
            (i & 1) as f64 * l,
            ((i >> 1) & 1) as f64 * l,
            ((i >> 2) & 1) as f64 * l,
        ]
    };
    // Each face by its four corners in order around it.
    let faces = [
        [0, 1, 3, 2],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 3, 7, 5],
    ];
    faces
        .iter()
        .flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]])
        .collect()
}

#[test]
fn a_grain_in_a_concave_corner_of_a_mesh_box_feels_two_plane_walls() {
    // Gravity pushes the grain into the edge x = 0, z = 0 of the box;
    // the mesh's two faces there must give what two planes give, and at
    // rest the box carries the grain's weight.
    // Released touching both faces (friction would hold it on the floor
    // short of the side face otherwise).
    let g0 = grain::<D3>(0, DVec3::new(0.4999, 2.0, 0.4999), 1.0);
    let gravity = DVec3::new(-4.0, 0.0, -9.0);
    let boxed = mesh_wall("box", &cube(4.0), &MeshPlacement::default(), Motion::Fixed);
    let walls = vec![
        plane("x0", DVec3::ZERO, DVec3::X),
        plane("z0", DVec3::ZERO, DVec3::Z),
    ];
    let mut a = md(vec![g0.clone()], vec![boxed], wall_law::<D3>(0.5), gravity);
    let mut b = md(vec![g0], walls, wall_law::<D3>(0.5), gravity);
    for _ in 0..20 {
        a.run(1000).unwrap();
        b.run(1000).unwrap();
        assert!(gap(&a, &b) < 1e-9, "differ by {:e}", gap(&a, &b));
    }
    assert_eq!(a.stats.contacts, 2);
    // At rest: the walls hold the weight m g, so the grains push m g on
    // the box; its torque about the grain's contact-free centre... about
    // the box's centroid (2, 2, 2): Σ (q − c) × F with q the two contact
    // points.
    let m = a.particles.mass[0];
    let loads = a.mesh_loads();
    assert_eq!(loads.len(), 1);
    let f = loads[0].force;
    assert!(
        (f - gravity * m).length() < 1e-6 * (gravity * m).length(),
        "{f}"
    );
    let p = a.particles.pos[0];
    let (qx, qz) = (DVec3::new(0.0, p.y, p.z), DVec3::new(p.x, p.y, 0.0));
    let c = DVec3::splat(2.0);
    assert!((loads[0].point - c).length() < 1e-12);
    // Each face's share: the normal force balances gravity's component.
    let want = (qx - c).cross(DVec3::new(gravity.x * m, 0.0, 0.0))
        + (qz - c).cross(DVec3::new(0.0, 0.0, gravity.z * m));
    assert!(
        (loads[0].torque - want).length() < 1e-5 * want.length(),
        "{} vs {want}",
        loads[0].torque
    );
}

#[test]
fn grazing_impacts_with_friction_never_gain_energy() {
    // A spinning sphere meets a tilted, shifted sheet of small triangles
    // (many edges under one contact) at angles of incidence 0 to 85°, with
    // μ = 0.5: friction and the spring's cap can only take energy away,
    // and the mesh must give what the plane it lies in gives.
    let place = MeshPlacement {
        scale: 1.0,
        rotate_deg: [20.0, -35.0, 10.0],
        translate: [0.3, -0.2, 0.1],
    };
    let tris = sheet(100, -10.0, 10.0);
    let origin = place.apply([0.0, 0.0, 0.0]);
    let normal = place.apply([0.0, 0.0, 1.0]) - origin;
    let along = place.apply([1.0, 0.0, 0.0]) - origin;
    // Restitution about 0.9: what is left to gain or lose is friction's.
    let mut law = wall_law::<D3>(0.5);
    law.gamma_n = 60.0;
    for deg in [0.0, 30.0, 60.0, 75.0, 80.0, 85.0] {
        let theta = f64::to_radians(deg);
        for spin in [0.0, 20.0, -20.0] {
            let start = origin + normal * 0.505 - along * 0.5;
            let mut g = grain::<D3>(0, start, 1.0);
            g.vel = (along * theta.sin() - normal * theta.cos()) * 4.0;
            g.omega = normal.cross(along) * spin;
            let sheet = mesh_wall("tilted", &tris, &place, Motion::Fixed);
            let flat = Wall::new(
                "p",
                Shape::Plane {
                    point: origin,
                    normal,
                },
                Motion::Fixed,
            );
            let mut m = md(vec![g.clone()], vec![sheet], law.clone(), DVec3::ZERO);
            let mut p = md(vec![g], vec![flat.unwrap()], law.clone(), DVec3::ZERO);
            let energy =
                |m: &Md<D3>| m.particles.kinetic_energy() + m.particles.rotational_energy();
            let e0 = energy(&m);
            let mut touched = false;
            // Stretches of 5 steps: from 8 on, `run` wakes the thread
            // pool's workers, which costs more than one grain's steps.
            for _ in 0..1200 {
                m.run(5).unwrap();
                p.run(5).unwrap();
                touched |= m.stats.contacts > 0;
                // Velocity Verlet's energy wobbles by (ω dt)²/8 ~ 1e-4 of
                // what the springs hold during a contact.
                let e = energy(&m);
                assert!(e <= e0 * (1.0 + 1e-3), "{deg}°, spin {spin}: {e} > {e0}");
            }
            assert!(touched, "{deg}°: never touched");
            assert_eq!(m.stats.contacts, 0, "{deg}°: still touching");
            let e = energy(&m);
            assert!(e < e0, "{deg}°, spin {spin}: gained energy {e} > {e0}");
            assert!(
                gap(&m, &p) < 1e-9,
                "{deg}°: mesh and plane differ by {:e}",
                gap(&m, &p)
            );
        }
    }
}

#[test]
fn a_moving_mesh_pushes_like_the_moving_plane_it_stands_for() {
    // A floor sheet translating sideways under a resting grain drags it
    // as a translating plane does.
    let tris = sheet(80, -20.0, 20.0);
    let motion = || Motion::Translate {
        velocity: DVec3::new(0.7, -0.2, 0.0),
    };
    let mesh = mesh_wall("belt", &tris, &MeshPlacement::default(), motion());
    let flat = Wall::new(
        "belt",
        Shape::Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        },
        motion(),
    )
    .unwrap();
    let g = grain::<D3>(0, DVec3::new(0.0, 0.0, 0.4999), 1.0);
    let gravity = DVec3::new(0.0, 0.0, -9.81);
    let mut a = md(vec![g.clone()], vec![mesh], wall_law::<D3>(0.5), gravity);
    let mut b = md(vec![g], vec![flat], wall_law::<D3>(0.5), gravity);
    for _ in 0..10 {
        a.run(1000).unwrap();
        b.run(1000).unwrap();
    }
    assert!(gap(&a, &b) < 1e-9, "{:e}", gap(&a, &b));
    assert!(
        a.particles.vel[0].x > 0.1,
        "dragged: {}",
        a.particles.vel[0]
    );
}

/// A turntable: the floor sheet, or the plane it stands for, turning at
/// Ω = 1 rad/s about the vertical axis through the origin (its surface
/// moves with ω × (q − c)), a ball (d = 1, at rest) set down 3 d from the
/// axis, sliding friction μ = 0.5; under `law` (a Hooke law or
/// Hertz–Mindlin, given as settings).
fn turntable(mesh: bool, settings: &MdSettings<D3>) -> Md<D3> {
    let motion = Motion::Rotate {
        center: DVec3::ZERO,
        omega: DVec3::new(0.0, 0.0, 1.0),
    };
    let wall = if mesh {
        mesh_wall(
            "table",
            &sheet(80, -20.0, 20.0),
            &MeshPlacement::default(),
            motion,
        )
    } else {
        let plane = Shape::Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        };
        Wall::new("table", plane, motion).unwrap()
    };
    let g = grain::<D3>(0, DVec3::new(3.0, 0.0, 0.4999), 1.0);
    let mut p = Particles::new();
    p.push_record(g);
    Md::new(p, open_box(30.0), vec![wall], settings.clone()).unwrap()
}

/// The turntable under a Hooke law with friction and under Hertz–Mindlin:
/// the turning mesh drags the ball as the turning plane does (positions,
/// velocities and spins within 1e-9 relative over 3 s, as the translating
/// belt above: the same contact found another way; measured 0), and,
/// once the ball rolls without slipping, its centre circles at 2Ω/7 (a
/// uniform ball on a turntable: Ω I/(I + m R²) with I = (2/5) m R²;
/// Weltner 1979, Am. J. Phys. 47, 984). The rate is measured from the
/// turn of the ball's velocity between 1 s and 3 s, to 1e-5 (the
/// tangential spring's give and the rolling ball's small normal
/// oscillations; measured 4e-8 under Hooke, 1.2e-7 under Hertz–Mindlin),
/// the contact point slipping at under 1e-3 m/s (measured 9e-6). A mesh
/// whose surface moved with −ω (planted) fails.
#[test]
fn a_turning_mesh_drags_a_ball_as_the_turning_plane_does() {
    use grains::contact::hertz_mindlin::HertzMindlin;
    use grains::contact::material::Material;
    let gravity = DVec3::new(0.0, 0.0, -9.81);
    let mut hooke = MdSettings::<D3>::new(2e-5, wall_law::<D3>(0.5), 0.1);
    hooke.integrator = Integrator::Verlet;
    hooke.gravity = gravity;
    let material = |name: &str, e: f64| Material {
        name: name.into(),
        density: 6.0 / std::f64::consts::PI,
        youngs_modulus: e,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: 0.5,
        rolling_friction: 0.0,
        surface_energy: 0.0,
    };
    let mats = [material("ball", 1e7), material("table", 1e9)];
    let law = HertzMindlin::new(&mats, &[], vec![0], vec![1], true);
    let mut hertz = MdSettings::<D3>::with_materials(2e-5, law, 0.1);
    hertz.gravity = gravity;
    for (what, settings) in [("Hooke", hooke), ("Hertz-Mindlin", hertz)] {
        let mut a = turntable(true, &settings);
        let mut b = turntable(false, &settings);
        for md in [&mut a, &mut b] {
            md.run(50_000).unwrap();
        }
        let v1 = a.particles.vel[0];
        let (t1, slip1) = (a.time, slip(&a));
        for md in [&mut a, &mut b] {
            md.run(100_000).unwrap();
        }
        let v2 = a.particles.vel[0];
        assert!(
            gap(&a, &b) < 1e-9,
            "{what}: mesh and plane {:e} apart",
            gap(&a, &b)
        );
        // Rolling, not sliding, over the whole interval.
        assert!(slip1 < 1e-3 && slip(&a) < 1e-3, "{what}: slipping");
        let turned = (v2.y.atan2(v2.x) - v1.y.atan2(v1.x)).rem_euclid(std::f64::consts::TAU);
        let rate = turned / (a.time - t1);
        let want = 2.0 / 7.0;
        assert!(
            (rate / want - 1.0).abs() < 1e-5,
            "{what}: the ball circles at {rate} rad/s, not 2Ω/7 = {want}"
        );
        assert!(
            a.particles.pos[0].z > 0.49 && v1.length() > 0.1,
            "{what}: {v1}"
        );
    }
}

/// The slip speed of the ball over the turntable (Ω = 1 about z): its
/// contact point's velocity v + ω × (−R ẑ) less the table's ẑ × q there.
fn slip(md: &Md<D3>) -> f64 {
    let p = &md.particles;
    let (q, v, w, r) = (p.pos[0], p.vel[0], p.omega[0], p.radius[0]);
    let contact = DVec3::new(q.x, q.y, 0.0);
    let point = v + w.cross(DVec3::new(0.0, 0.0, -r));
    let table = DVec3::Z.cross(contact);
    (point - table).length()
}
