//! Bodies placed from a scenario: no sub-sphere of one body overlaps a
//! sub-sphere of another, a grain or a wall; a mixture's counts are the
//! fractions' shares of the count to within one body; the same seed gives
//! the same bodies.

use grains::dim::Dim;
use grains::rigid::shape::{placed, quat};
use grains::rigid::BodySpec;
use grains::scenario::clumps::Clumps;
use grains::scenario::{build_md_parts, load_str};
use grains::{D2, D3};
use std::path::PathBuf;

pub const BASE: &str = r#"name = "clumps"
dimension = "3d"
seed = 4
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.012, 0.012, 0.03]
[particles]
placement = "random"
count = 150
shape = "rod"
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-6
duration = 1.0e-4
[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
[[walls]]
name = "can"
shape = { type = "cylinder", point = [0.006, 0.006, 0.0], radius = 0.006 }
[[shapes]]
name = "rod"
units = "d0"
spheres = [{ center = [-0.8, 0.0, 0.0], radius = 0.5 }, { center = [0.0, 0.0, 0.0], radius = 0.5 }, { center = [0.8, 0.0, 0.0], radius = 0.5 }]
[[shapes]]
name = "dimer"
units = "d0"
spheres = [{ center = [0.0, 0.0, 0.0], radius = 0.5 }, { center = [0.0, 0.0, 1.0], radius = 0.5 }]
[[shapes]]
name = "tetra"
units = "d0"
spheres = [{ center = [0.3, 0.3, 0.3], radius = 0.5 }, { center = [0.3, -0.3, -0.3], radius = 0.5 }, { center = [-0.3, 0.3, -0.3], radius = 0.5 }, { center = [-0.3, -0.3, 0.3], radius = 0.5 }]
"#;

pub fn parts<D: Dim>(text: &str, sets: &[&str]) -> grains::Result<(grains::md::Md<D>, Clumps<D>)> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let loaded = load_str(text, "clumps.toml", PathBuf::from("."), &sets)?;
    let (md, _, clumps) = build_md_parts::<D>(&loaded, &mut |_| {})?;
    Ok((md, clumps))
}

/// Every sub-sphere in space with its body's index.
fn spheres<D: Dim>(c: &Clumps<D>) -> Vec<(D::V, f64, usize)> {
    let mut out = Vec::new();
    for (k, b) in c.bodies.iter().enumerate() {
        for s in &c.shapes[b.shape].spheres {
            out.push((
                placed::<D>(b.pos, quat(b.orientation), s.center),
                s.radius,
                k,
            ));
        }
    }
    out
}

/// The deepest overlap between sub-spheres of different bodies, of a
/// sub-sphere with a grain, and with a wall (m; ≤ 0 is none).
fn deepest<D: Dim>(md: &grains::md::Md<D>, c: &Clumps<D>) -> (f64, f64, f64) {
    let all = spheres(c);
    let mut bodies = f64::NEG_INFINITY;
    for (i, a) in all.iter().enumerate() {
        for b in &all[i + 1..] {
            if a.2 != b.2 {
                bodies = bodies.max(a.1 + b.1 - D::norm(a.0 - b.0));
            }
        }
    }
    let p = &md.particles;
    let mut grains = f64::NEG_INFINITY;
    let mut walls = f64::NEG_INFINITY;
    for a in &all {
        for j in 0..p.n_owned() {
            grains = grains.max(a.1 + p.radius[j] - D::norm(a.0 - p.pos[j]));
        }
        for w in &md.walls {
            if let Some(wc) = w.contact(a.0, a.1, 0.0) {
                walls = walls.max(wc.overlap);
            }
        }
    }
    (bodies, grains, walls)
}

#[test]
fn random_bodies_overlap_nothing() {
    let extra =
        format!("{BASE}[[particles.add]]\nposition = [0.006, 0.006, 0.015]\ndiameter = 0.003\n");
    let (md, c) = parts::<D3>(&extra, &[]).unwrap();
    assert_eq!(c.bodies.len(), 150);
    assert_eq!(md.particles.n_owned(), 1, "the added sphere");
    let (b, g, w) = deepest(&md, &c);
    assert!(b <= 0.0 && g <= 0.0 && w <= 0.0, "{b} {g} {w}");
    for body in &c.bodies {
        assert!((quat(body.orientation).length() - 1.0).abs() < 1e-12);
    }
    let (_, again) = parts::<D3>(&extra, &[]).unwrap();
    assert_eq!(c.bodies, again.bodies, "the same seed, the same bodies");
}

#[test]
fn lattice_bodies_overlap_nothing() {
    let text = BASE.replace(
        "placement = \"random\"\ncount = 150\nshape = \"rod\"\n",
        "placement = \"lattice\"\ncount = 40\nshape = \"tetra\"\n\
         region = { lo = [0.002, 0.002, 0.0005], hi = [0.010, 0.010, 0.03] }\n",
    );
    let (md, c) = parts::<D3>(&text, &[]).unwrap();
    assert_eq!(c.bodies.len(), 40);
    let (b, _, w) = deepest(&md, &c);
    assert!(b <= 0.0 && w <= 0.0, "{b} {w}");
}

#[test]
fn a_mixture_has_the_fractions_counts() {
    let text = BASE.replace(
        "shape = \"rod\"\n",
        "shapes = [{ name = \"rod\", fraction = 0.5 }, { name = \"dimer\", fraction = 0.3 }, { name = \"tetra\", fraction = 0.2 }]\n",
    );
    for count in [150, 101, 7] {
        let (md, c) = parts::<D3>(&text, &[&format!("particles.count={count}")]).unwrap();
        let of = |i: usize| {
            c.bodies
                .iter()
                .filter(|b: &&BodySpec<D3>| b.shape == i)
                .count()
        };
        let n = [of(0), of(1), of(2)];
        assert_eq!(n.iter().sum::<usize>(), count);
        for (k, f) in [0.5, 0.3, 0.2].iter().enumerate() {
            assert!(
                (n[k] as f64 - f * count as f64).abs() < 1.0,
                "count {count}: {n:?}"
            );
        }
        let (b, _, w) = deepest(&md, &c);
        assert!(b <= 0.0 && w <= 0.0, "{b} {w}");
        // Shuffled, not in runs of one shape.
        if count == 150 {
            assert!(c.bodies.windows(2).any(|w| w[0].shape > w[1].shape));
        }
    }
}

#[test]
fn two_dimensional_clumps_of_disks() {
    let text = r#"name = "c2"
dimension = "2d"
[domain]
lo = [0.0, 0.0]
hi = [0.02, 0.04]
[particles]
placement = "random"
count = 100
shape = "tri"
mass_model = "disk"
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-6
duration = 1.0e-4
[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
[[shapes]]
name = "tri"
units = "d0"
spheres = [{ center = [0.0, 0.0], radius = 0.5 }, { center = [0.9, 0.0], radius = 0.5 }, { center = [0.45, 0.75, 0.0], radius = 0.5 }]
"#;
    let (md, c) = parts::<D2>(text, &[]).unwrap();
    assert_eq!(c.bodies.len(), 100);
    let (b, _, w) = deepest(&md, &c);
    assert!(b <= 0.0 && w <= 0.0, "{b} {w}");
    for body in &c.bodies {
        let q = body.orientation;
        assert!(q[1] == 0.0 && q[2] == 0.0, "a 2d turn is about z: {q:?}");
    }
}

#[test]
fn added_bodies_take_their_orientation_and_spin() {
    let text = format!(
        "{BASE}[[particles.add]]\nshape = \"dimer\"\nposition = [0.006, 0.006, 0.02]\n\
         orientation = [0.7071067811865476, 0.7071067811865476, 0.0, 0.0]\nomega = [0.0, 0.0, 3.0]\n\
         velocity = [0.0, 0.0, -1.0]\n"
    );
    let text = text.replace(
        "placement = \"random\"\ncount = 150\nshape = \"rod\"\n",
        "placement = \"none\"\n",
    );
    let (_, c) = parts::<D3>(&text, &[]).unwrap();
    assert_eq!(c.bodies.len(), 1);
    let added = c.bodies.last().unwrap();
    assert_eq!(added.shape, 1);
    assert_eq!(added.omega.z, 3.0);
    assert_eq!(added.vel.z, -1.0);
    // The dimer written along z, turned 90° about x: its spheres lie along −y.
    let shape = &c.shapes[1];
    let ends: Vec<_> = shape
        .spheres
        .iter()
        .map(|s| placed::<D3>(added.pos, quat(added.orientation), s.center))
        .collect();
    let axis = (ends[1] - ends[0]).normalize();
    assert!((axis.y.abs() - 1.0).abs() < 1e-12, "{axis}");
    let mid = (ends[0] + ends[1]) / 2.0;
    assert!(
        (mid - added.pos).length() < 1e-15,
        "the position is the centre of mass"
    );
}
