//! `[[inlets]]` of rigid bodies (`shape`, `shapes`): the body count
//! follows floor(rate (t − start)) at every step and the mass stays within
//! one body of mass_rate (t − start) (the schedule's definition, as for
//! grains); no sub-sphere of an inserted body overlaps a grain, another
//! body's sub-sphere, a plane wall or a mesh wall by more than 1e-9 of its
//! diameter (distances computed here from the geometry); the orientations
//! are uniform on rotations (moments of the body axis against those of the
//! uniform distribution on the sphere); a resume in the middle of the
//! insertion gives the straight run's bits; `grains check` says what the
//! inlet makes; keys that do not apply to bodies are refused by name.

use super::inlets::{begin, scratch_in, PLANES, SHEET_X, SHEET_Z};
use glam::DVec3;
use grains::dim::D3;
use grains::engine::Engine;
use grains::md::Md;
use grains::scenario::flow::FlowRun;
use grains::scenario::{build_md, load_str, Loaded};
use std::path::PathBuf;

/// A 6 x 6 mm box with a floor and four side walls, 40 spheres resting
/// low in it, a horizontal mesh sheet at z = 13 mm over the left half, a
/// rod of three 0.8 mm spheres 0.4 mm apart and a bent triple, and the
/// contacts of pour-3d (1 mm glass beads).
const BASE: &str = r#"name = "inlet-bodies"
dimension = "3d"
seed = 5
gravity = [0.0, 0.0, -9.81]
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.006, 0.006, 0.02]
[particles]
placement = "random"
count = 40
d0 = 1.0e-3
width = 0.2
density = 2500.0
region = { lo = [0.0, 0.0, 0.0], hi = [0.006, 0.006, 0.008] }
[[shapes]]
name = "rod"
units = "d0"
spheres = [{ center = [-0.4, 0.0, 0.0], radius = 0.4 }, { center = [0.0, 0.0, 0.0], radius = 0.4 }, { center = [0.4, 0.0, 0.0], radius = 0.4 }]
[[shapes]]
name = "bent"
units = "d0"
spheres = [{ center = [0.0, 0.0, 0.0], radius = 0.4 }, { center = [0.6, 0.0, 0.0], radius = 0.4 }, { center = [0.0, 0.6, 0.0], radius = 0.4 }]
[contact]
kn = 2.0e4
beta = 1.5
gamma_n = 1000.0
kt = 40.0
mu = 0.4
scaling = "reduced"
rotation = true
[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
[[walls]]
name = "left"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }
[[walls]]
name = "right"
shape = { type = "plane", point = [0.006, 0.0, 0.0], normal = [-1.0, 0.0, 0.0] }
[[walls]]
name = "front"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[walls]]
name = "back"
shape = { type = "plane", point = [0.0, 0.006, 0.0], normal = [0.0, -1.0, 0.0] }
[[walls]]
name = "sheet"
shape = { type = "mesh", file = "sheet.stl" }
[run]
integrator = "verlet"
dt = 1.0e-5
duration = 0.03
skin = 0.2
[output]
frames = false
picture = false
movie = false
"#;

fn scratch(tag: &str) -> PathBuf {
    scratch_in("inlet-bodies", tag)
}

/// `base` with `inlet` as its one `[[inlets]]` table.
fn scenario_on(base: &str, tag: &str, inlet: &str) -> (Loaded, PathBuf) {
    let dir = scratch(tag);
    let text = format!("{base}[[inlets]]\n{inlet}\n");
    let loaded = load_str(&text, "inlet-bodies.toml", dir.clone(), &[]).unwrap();
    (loaded, dir)
}

fn scenario(tag: &str, inlet: &str) -> (Loaded, PathBuf) {
    scenario_on(BASE, tag, inlet)
}

fn error(inlet: &str) -> String {
    let dir = scratch("bad");
    let text = format!("{BASE}[[inlets]]\n{inlet}\n");
    let e = match load_str(&text, "inlet-bodies.toml", dir.clone(), &[]) {
        Err(e) => e.to_string(),
        Ok(l) => match build_md::<D3>(&l) {
            Err(e) => e.to_string(),
            Ok((md, _)) => match FlowRun::begin(&l, &md) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("accepted: {inlet}"),
            },
        },
    };
    std::fs::remove_dir_all(dir).ok();
    e
}

const FALL: &str = r#"region = { shape = "box", lo = [0.0, 0.0, 0.010], hi = [0.006, 0.006, 0.019] }
velocity = [0.0, 0.0, -0.2]
velocity_spread = 0.05"#;

/// The run loop's way: advance to the flow run's next act, act.
fn run_to(md: &mut Md<D3>, flow: &mut FlowRun<D3>, end: u64) {
    while md.step < end {
        let next = flow.next_act(md.step, (md.step + 256).min(end));
        md.advance(next - md.step).unwrap();
        flow.after_step(md);
    }
}

/// The bodies: (count, mass).
fn bodies(md: &Md<D3>) -> (usize, f64) {
    md.bodies().map_or((0, 0.0), |b| {
        let mass = (0..b.bodies.len()).map(|k| b.shape(k).mass).sum();
        (b.bodies.len(), mass)
    })
}

/// Grains and bodies as bits: ids, positions, velocities, spins in store
/// order; each body's position, quaternion, velocity, angular momentum.
fn bits(md: &Md<D3>) -> Vec<u64> {
    let p = &md.particles;
    let mut out = Vec::new();
    for i in 0..p.n_owned() {
        out.push(p.id[i]);
        for v in [p.pos[i], p.vel[i], p.omega[i]] {
            out.extend(v.to_array().map(f64::to_bits));
        }
    }
    for b in md.bodies().map_or(&[][..], |b| &b.bodies[..]) {
        out.push(b.first_id);
        for v in [b.pos, b.vel, b.ang_mom] {
            out.extend(v.to_array().map(f64::to_bits));
        }
        out.extend(b.quat.map(f64::to_bits));
    }
    out
}

#[test]
fn body_count_follows_the_rate_within_one_body_at_every_step() {
    // 2000 bodies/s from t = 2 ms to 12 ms: 20 bodies; one act per step.
    let (rate, start, stop) = (2000.0, 0.002, 0.012);
    let inlet =
        format!("{FALL}\nshapes = [{{ name = \"rod\", fraction = 0.5 }}, {{ name = \"bent\", fraction = 0.5 }}]\nrate = {rate}\nstart = {start}\nstop = {stop}");
    let (loaded, dir) = scenario("rate", &inlet);
    let (mut md, mut flow) = begin(&loaded);
    let spheres = md.particles.n_owned();
    while md.step < 1600 {
        md.advance(1).unwrap();
        flow.after_step(&mut md);
        let t = md.time.min(stop);
        let want = if t < start { 0.0 } else { rate * (t - start) };
        let (got, _) = bodies(&md);
        let got = got as f64;
        assert!(
            got <= want && want - got < 1.0,
            "t = {}: {got} bodies, {want} requested",
            md.time
        );
        // Three grains per body, in the store beside the spheres.
        assert_eq!(md.particles.n_owned(), spheres + 3 * got as usize);
    }
    assert_eq!(bodies(&md).0, 20);
    let b = md.bodies().unwrap();
    let rods = (0..20).filter(|&k| b.shape(k).name == "rod").count();
    assert!(
        rods > 0 && rods < 20,
        "{rods} rods of 20: the mixture drew one shape"
    );
    // The run loop's way (advancing to the inlet's next act) inserts at
    // the same steps: the same bits.
    let (mut c, mut fc) = begin(&loaded);
    run_to(&mut c, &mut fc, 1600);
    assert!(bits(&md) == bits(&c), "next_act skipped or delayed a body");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn body_mass_follows_the_mass_rate_within_one_body() {
    // A rod of three 0.8 mm spheres of 2500 kg/m³ weighs about 1.6 mg:
    // 4e-3 kg/s is about 25 rods in the 10 ms.
    let inlet = format!("{FALL}\nshape = \"rod\"\nmass_rate = 4.0e-3\nstop = 0.01");
    let (loaded, dir) = scenario("mass", &inlet);
    let (mut md, mut flow) = begin(&loaded);
    let mut heaviest = 0.0;
    for _ in 0..1200 {
        md.advance(1).unwrap();
        flow.after_step(&mut md);
        let (n, mass) = bodies(&md);
        if n > 0 {
            heaviest = md.bodies().unwrap().shape(0).mass;
        }
        let want = 4.0e-3 * md.time.min(0.01);
        assert!(
            mass <= want * (1.0 + 1e-12) && (n == 0 || want - mass < heaviest),
            "t = {}: {mass} kg in {n} bodies, {want} kg requested",
            md.time
        );
    }
    assert!(bodies(&md).0 > 20, "{} bodies", bodies(&md).0);
    std::fs::remove_dir_all(dir).ok();
}

/// The deepest overlap of grain `i` with any grain of another body (or a
/// free one), plane or the sheet, as a fraction of its diameter (negative:
/// clear).
fn worst_overlap(md: &Md<D3>, owner: &[Option<u32>], i: usize) -> f64 {
    let p = &md.particles;
    let (x, r) = (p.pos[i], p.radius[i]);
    let mut worst = f64::NEG_INFINITY;
    for j in (0..p.n_owned()).filter(|&j| j != i) {
        if owner[i].is_some() && owner[i] == owner[j] {
            continue;
        }
        worst = worst.max(r + p.radius[j] - (x - p.pos[j]).length());
    }
    for (point, normal) in PLANES {
        let gap = (x - DVec3::from(point)).dot(DVec3::from(normal));
        worst = worst.max(r - gap);
    }
    if x.x <= SHEET_X {
        worst = worst.max(r - (x.z - SHEET_Z).abs());
    }
    worst / (2.0 * r)
}

#[test]
fn inserted_bodies_overlap_nothing() {
    // A crowded region across the sheet and down among the resting
    // spheres: more is asked than fits, so many spots are refused.
    let inlet = r#"region = { shape = "cylinder", center = [0.003, 0.003], radius = 0.003, bottom = 0.0, top = 0.019 }
shapes = [{ name = "rod", fraction = 0.5 }, { name = "bent", fraction = 0.5 }]
rate = 40000.0
stop = 0.02"#;
    let (loaded, dir) = scenario("overlap", inlet);
    let (mut md, mut flow) = begin(&loaded);
    let mut checked = 0;
    while md.step < 1500 {
        let next = flow.next_act(md.step, md.step + 256);
        md.advance(next - md.step).unwrap();
        let before: std::collections::HashSet<u64> = md.particles.id.iter().copied().collect();
        flow.after_step(&mut md);
        let owner = md.grain_bodies().unwrap();
        for i in 0..md.particles.n_owned() {
            if before.contains(&md.particles.id[i]) {
                continue;
            }
            assert!(owner[i].is_some(), "a new grain belongs to no body");
            let w = worst_overlap(&md, &owner, i);
            assert!(
                w <= 1e-9,
                "sub-sphere {} inserted overlapping by {w:e} of its diameter",
                md.particles.id[i]
            );
            checked += 1;
        }
    }
    assert!(checked > 150, "only {checked} sub-spheres inserted");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn inserted_orientations_are_uniform_on_rotations() {
    // 2400 rods at once into a tall empty box: the rod's axis is its
    // principal x axis (the smallest moment). Turned uniformly on
    // rotations it points uniformly on the sphere, whose components have
    // mean 0 and variance 1/3, and whose squares have mean 1/3 and
    // variance E[x⁴] − 1/9 = 1/5 − 1/9 = 4/45. Held to 4 standard errors
    // of the mean of n: 4 √(1/(3n)) and 4 √(4/(45 n)).
    let base = BASE
        .replace("hi = [0.006, 0.006, 0.02]", "hi = [0.006, 0.006, 0.5]")
        .replace("count = 40", "count = 1");
    let inlet = r#"region = { shape = "box", lo = [0.0, 0.0, 0.02], hi = [0.006, 0.006, 0.5] }
shape = "rod"
count = 2400"#;
    let (loaded, dir) = scenario_on(&base, "turns", inlet);
    let (mut md, mut flow) = begin(&loaded);
    md.advance(1).unwrap();
    flow.after_step(&mut md);
    let b = md.bodies().unwrap();
    let n = b.bodies.len();
    assert_eq!(n, 2400);
    let axes: Vec<DVec3> = (0..n).map(|k| b.rotation(k) * DVec3::X).collect();
    let (one, two) = (
        4.0 * (1.0 / (3.0 * n as f64)).sqrt(),
        4.0 * (4.0 / (45.0 * n as f64)).sqrt(),
    );
    for a in 0..3 {
        let mean = axes.iter().map(|x| x[a]).sum::<f64>() / n as f64;
        let square = axes.iter().map(|x| x[a] * x[a]).sum::<f64>() / n as f64;
        eprintln!("axis component {a}: mean {mean:+.4} (±{one:.4}), mean square {square:.4} (1/3 ± {two:.4})");
        assert!(mean.abs() < one, "component {a}: mean {mean}");
        assert!(
            (square - 1.0 / 3.0).abs() < two,
            "component {a}: mean square {square}"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn resume_in_the_middle_of_the_body_insertion_gives_the_straight_bits() {
    let inlet = format!("{FALL}\nshapes = [{{ name = \"rod\", fraction = 0.3 }}, {{ name = \"bent\", fraction = 0.7 }}]\nrate = 5000.0\nstop = 0.015");
    let (loaded, dir) = scenario("resume", &inlet);
    let (mut a, mut fa) = begin(&loaded);
    // Stop right after an insertion, before the list is rebuilt.
    while bodies(&a).0 < 12 {
        a.advance(1).unwrap();
        fa.after_step(&mut a);
    }
    let (engine, flow) = (a.export().unwrap(), fa.save());
    let (mut b, _) = build_md::<D3>(&loaded).unwrap();
    let mut fb = FlowRun::restored(&loaded, &mut b, Some(flow.as_slice()), "test").unwrap();
    b.import(&engine, "test").unwrap();
    assert!(bits(&a) == bits(&b));
    run_to(&mut a, &mut fa, 2500);
    run_to(&mut b, &mut fb, 2500);
    assert!(bodies(&a).0 > 40, "{} bodies", bodies(&a).0);
    assert!(bits(&a) == bits(&b), "the resumed run differs");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn grains_check_prints_the_bodies_an_inlet_makes() {
    let inlet = format!("{FALL}\nshape = \"rod\"\nrate = 1000.0\nstart = 0.01");
    let (loaded, dir) = scenario("check", &inlet);
    let v = grains::scenario::inlet::check_report(&loaded, 0.03).unwrap();
    assert_eq!(v[0]["rate_unit"], "bodies/s");
    assert_eq!(v[0]["expected_unit"], "bodies");
    assert!((v[0]["expected"].as_f64().unwrap() - 20.0).abs() < 1e-9);
    assert_eq!(v[0]["bodies"][0]["name"], "rod");
    assert_eq!(v[0]["bodies"][0]["sub_spheres"], 3);
    assert_eq!(v[0]["orientation"], "random");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn keys_that_do_not_apply_to_bodies_are_named() {
    let e = error(&format!("{FALL}\nrate = 10.0\nshape = \"disc\""));
    assert!(
        e.contains("inlets[0].shape") && e.contains("\"rod\""),
        "{e}"
    );
    let e = error(&format!(
        "{FALL}\nrate = 10.0\nshape = \"rod\"\nshapes = [{{ name = \"bent\", fraction = 1.0 }}]"
    ));
    assert!(e.contains("inlets[0].shape and shapes"), "{e}");
    let e = error(&format!(
        "{FALL}\nrate = 10.0\nshape = \"rod\"\nsize = {{ distribution = \"uniform\", min = 0.9e-3, max = 1.1e-3 }}"
    ));
    assert!(e.contains("inlets[0].size") && e.contains("scale"), "{e}");
    let e = error(&format!(
        "{FALL}\nrate = 10.0\nshapes = [{{ name = \"rod\", fraction = 0.5 }}, {{ name = \"bent\", fraction = 0.4 }}]"
    ));
    assert!(
        e.contains("inlets[0].shapes") && e.contains("sum to 1"),
        "{e}"
    );
    let e = error(&format!("{FALL}\nrate = 10.0\norientation = \"random\""));
    assert!(
        e.contains("inlets[0].orientation") && e.contains("shape"),
        "{e}"
    );
    let e = error(&format!(
        "{FALL}\nrate = 10.0\nshape = \"rod\"\norientation = [1.0, 1.0, 0.0, 0.0]"
    ));
    assert!(
        e.contains("inlets[0].orientation") && e.contains("unit quaternion"),
        "{e}"
    );
}
