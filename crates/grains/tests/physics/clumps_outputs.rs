//! What a run with rigid clumps writes of its bodies: the frames' `body`
//! and `orientation` point arrays and the per-body table bodies.csv,
//! checked against the geometry of the sub-spheres in the same frame and
//! against the dimer's inertia in closed form.

use super::clumps::{big_box, floor, hooke, rod, settings, spec, sphere_mass, turn, R};
use crate::common;

use common::runs::read_csv;
use glam::DVec3;
use grains::md::Md;
use grains::output::Outputs;
use grains::scenario::schema::OutputSpec;
use grains::{ParticleRecord, Particles, D3};
use std::collections::BTreeMap;

/// The rotation of a unit quaternion (w, x, y, z) applied to `v`, written
/// out here (v + 2w (u × v) + 2 u × (u × v), u the vector part) rather than
/// taken from the engine.
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let u = [x, y, z];
    let t = cross(u, v);
    let tt = cross(u, t);
    std::array::from_fn(|a| v[a] + 2.0 * w * t[a] + 2.0 * tt[a])
}

/// Three spinning rods (three touching spheres of radius R at −2R, 0, 2R
/// along the rod's own x) and two free spheres, dropped on the floor:
/// the run's outputs at step 0 and after 200 steps, through the files a
/// scenario run writes (`Outputs`), in `dir`.
fn rods_written(dir: &std::path::Path) -> u64 {
    let ms = sphere_mass();
    let mut p = Particles::<D3>::new();
    for k in 0..2u64 {
        let x = DVec3::new(-0.01 + 0.02 * k as f64, 0.0, 0.003);
        p.push_record(ParticleRecord::new(100 + k, x, R, ms, 0.4 * ms * R * R));
    }
    let mut s = settings(hooke(1e3, 5000.0), 2e-6);
    s.gravity = DVec3::new(0.0, 0.0, -9.81);
    let mut md = Md::new(p, big_box(), floor(), s).unwrap();
    let specs = (0..3)
        .map(|k| {
            let x = DVec3::new(-0.006 + 0.006 * k as f64, 0.0, 0.0025 + 0.001 * k as f64);
            let q = turn(
                DVec3::new(0.3, k as f64, 1.0).normalize(),
                0.7 * k as f64 + 0.2,
            );
            spec(x, q, DVec3::ZERO, DVec3::new(k as f64 + 1.0, 20.0, -10.0))
        })
        .collect();
    md.add_bodies(vec![rod()], specs).unwrap();
    let spec = OutputSpec {
        picture: false,
        ..Default::default()
    };
    let mut out = Outputs::create(dir, &spec).unwrap();
    out.record_md(&md).unwrap();
    md.run(200).unwrap();
    out.record_md(&md).unwrap();
    md.step
}

/// The frames and bodies.csv of [`rods_written`]. bodies.csv holds one row
/// per rod and output step, numbered 1..=3 with the shape's name. In the
/// last frame each rod's sub-spheres carry its number (the free spheres 0)
/// and the table's orientation q (to the bit: both are written in shortest
/// round-trip form); its middle sphere sits at the table's centre of mass
/// (equal touching spheres: the centre of mass is the middle one's centre)
/// and q turns the rod's x onto the line through its end spheres, 4R apart;
/// the table's L is R I Rᵀ ω with the rod's closed-form moments
/// (I_axis = 3·(2/5) m_s R², I_perp = I_axis + 2 m_s (2R)²), to 1e-12
/// relative, the rounding of the three written columns.
#[test]
fn frames_and_bodies_csv_carry_each_bodys_pose_and_spin() {
    let dir =
        std::env::temp_dir().join(format!("grains-test-clump-outputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let step = rods_written(&dir) as f64;

    let entries = grains::io::read_series(&dir).unwrap();
    assert_eq!(entries.len(), 2);
    let text = std::fs::read_to_string(dir.join("bodies.csv")).unwrap();
    let header = text.lines().next().unwrap();
    assert_eq!(
        header,
        "step,time,id,shape,x,y,z,qw,qx,qy,qz,vx,vy,vz,Lx,Ly,Lz,wx,wy,wz"
    );
    assert!(text
        .lines()
        .skip(1)
        .all(|l| l.split(',').nth(3) == Some("rod")));
    let rows = read_csv(&dir.join("bodies.csv"));
    assert_eq!(rows.len(), 6, "a row per body and output step");
    let last = grains::io::read_frame(&entries[1].path).unwrap();
    assert_eq!(last.step as f64, step);
    let mine: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] == step).collect();
    let ids: Vec<u64> = mine.iter().map(|r| r[2] as u64).collect();
    assert_eq!(ids, [1, 2, 3]);

    let body = last.body.as_ref().expect("frames carry body");
    let orientation = last.orientation.as_ref().expect("frames carry orientation");
    let mut members: BTreeMap<u64, Vec<(u64, usize)>> = BTreeMap::new();
    for (i, &b) in body.iter().enumerate() {
        members.entry(b).or_default().push((last.id[i], i));
    }
    let free: Vec<u64> = members[&0].iter().map(|m| m.0).collect();
    assert_eq!(free, [100, 101]);
    for &(_, i) in &members[&0] {
        assert_eq!(orientation[i], [1.0, 0.0, 0.0, 0.0]);
    }
    let ms = sphere_mass();
    let i_axis = 3.0 * 0.4 * ms * R * R;
    let i_perp = i_axis + 2.0 * ms * 4.0 * R * R;
    let mut turning = 0.0f64;
    for row in mine {
        let id = row[2] as u64;
        let q = [row[7], row[8], row[9], row[10]];
        // The rod's spheres in id order: its shape's order, −2R, 0, 2R.
        let mut spheres = members[&id].clone();
        spheres.sort();
        assert_eq!(spheres.len(), 3);
        for &(_, i) in &spheres {
            assert_eq!(orientation[i], q, "body {id}: its sub-spheres' orientation");
        }
        let [a, m, b] = [0, 1, 2].map(|k| last.pos[spheres[k].1]);
        for c in 0..3 {
            assert!(
                (m[c] - row[4 + c]).abs() < 1e-15,
                "body {id}: centre of mass"
            );
        }
        let axis = rotate(q, [1.0, 0.0, 0.0]);
        for c in 0..3 {
            let d = (b[c] - a[c]) / (4.0 * R);
            assert!((axis[c] - d).abs() < 1e-9, "body {id}: axis {axis:?}");
        }
        // L = R I Rᵀ ω, with Rᵀ the turn by the conjugate.
        let w = [row[17], row[18], row[19]];
        let wb = rotate([q[0], -q[1], -q[2], -q[3]], w);
        let l = rotate(q, [i_axis * wb[0], i_perp * wb[1], i_perp * wb[2]]);
        let scale = (row[14].powi(2) + row[15].powi(2) + row[16].powi(2)).sqrt();
        turning = turning.max(scale);
        for c in 0..3 {
            assert!(
                (l[c] - row[14 + c]).abs() <= 1e-12 * scale,
                "body {id}: L {:?} against I ω {l:?}",
                &row[14..17]
            );
        }
    }
    assert!(turning > 0.0, "the rods spin");
    std::fs::remove_dir_all(&dir).unwrap();
}
