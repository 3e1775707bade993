//! The clump scenarios on the engine (with `Md::add_bodies`): built with
//! their bodies, the engine holds the bodies and orientations placed, and
//! after a stretch of steps every body is still rigid (its sub-spheres
//! keep their distances to 1e-9 of a diameter) and every grain finite.

use grains::dim::Dim;
use grains::scenario::{build_md, build_md_parts, load_file};
use grains::{D2, D3};
use std::path::PathBuf;

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenarios/{name}.toml"))
}

fn runs<D: Dim>(name: &str, steps: u64) {
    let loaded = load_file(&path(name), &[]).unwrap();
    let (_, _, placed) = build_md_parts::<D>(&loaded, &mut |_| {}).unwrap();
    let (mut md, _) = build_md::<D>(&loaded).unwrap_or_else(|e| panic!("{name}: {e}"));
    let held = md.bodies().unwrap();
    assert_eq!(held.bodies.len(), placed.bodies.len(), "{name}");
    for (b, spec) in held.bodies.iter().zip(&placed.bodies) {
        let d: f64 = (b.quat.iter().zip(&spec.orientation))
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-12, "{name}: {:?} {:?}", b.quat, spec.orientation);
    }
    md.advance(steps).unwrap_or_else(|e| panic!("{name}: {e}"));
    let which = md.grain_bodies().unwrap();
    let p = &md.particles;
    let n = placed.bodies.len();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, w) in which.iter().enumerate() {
        assert!(
            D::is_finite(p.pos[i]) && D::is_finite(p.vel[i]),
            "{name}: grain {i}"
        );
        if let Some(b) = w {
            members[*b as usize].push(i);
        }
    }
    let mut worst = 0.0f64;
    for (b, list) in members.iter().enumerate() {
        let shape = &placed.shapes[placed.bodies[b].shape];
        assert_eq!(list.len(), shape.spheres.len(), "{name}: body {b}");
        let mut ids: Vec<(u64, usize)> = list.iter().map(|&i| (p.id[i], i)).collect();
        ids.sort();
        for x in 0..ids.len() {
            for y in x + 1..ids.len() {
                let now = D::norm(md.domain.minimum_image(p.pos[ids[x].1] - p.pos[ids[y].1]));
                let was = D::norm(shape.spheres[x].center - shape.spheres[y].center);
                worst = worst.max((now - was).abs() / (2.0 * shape.spheres[x].radius));
            }
        }
    }
    eprintln!(
        "{name}: {n} bodies, {steps} steps, worst change of a distance within a body {worst:.1e} d"
    );
    assert!(worst < 1e-9, "{name}: {worst}");
}

#[test]
fn clump_scenarios_run_and_stay_rigid() {
    runs::<D3>("repose-3d-clumps", 2000);
    runs::<D3>("hopper-3d-rods", 2000);
    runs::<D2>("pour-2d-clumps", 2000);
}
