//! `[[outlets]]` and `[[sensors]]` with rigid bodies: an outlet takes a
//! body out whole when its centre of mass is in it (never a part: after
//! every step each body present has all its sub-spheres, and each body
//! taken out had its centre beyond the plane while each one left had not);
//! a sensor counts a body once, when its centre crosses; the mass balance
//! holds exactly by units (free grains and whole bodies: initial +
//! inserted = present + removed, counts and masses); a resume after
//! removals gives the straight run's bits.

use grains::dim::{Dim, D3};
use grains::engine::Engine;
use grains::md::Md;
use grains::runner::{run, RunOptions, Silent};
use grains::scenario::flow::FlowRun;
use grains::scenario::{build_md, load_str, Loaded};
use std::collections::HashMap;
use std::path::PathBuf;

/// A 6 x 6 mm column open below: 30 spheres placed high and rods from an
/// inlet fall through the outlet plane at z = 2 mm (every step) past the
/// sensor at z = 5 mm. Rods of three 0.8 mm spheres, 0.4 mm apart.
const BASE: &str = r#"name = "outlet-bodies"
dimension = "3d"
seed = 3
gravity = [0.0, 0.0, -9.81]
[domain]
lo = [0.0, 0.0, -0.005]
hi = [0.006, 0.006, 0.02]
[particles]
placement = "random"
count = 30
d0 = 1.0e-3
width = 0.2
density = 2500.0
region = { lo = [0.0, 0.0, 0.008], hi = [0.006, 0.006, 0.012] }
[[shapes]]
name = "rod"
units = "d0"
spheres = [{ center = [-0.4, 0.0, 0.0], radius = 0.4 }, { center = [0.0, 0.0, 0.0], radius = 0.4 }, { center = [0.4, 0.0, 0.0], radius = 0.4 }]
[[inlets]]
region = { shape = "box", lo = [0.0, 0.0, 0.013], hi = [0.006, 0.006, 0.019] }
shape = "rod"
rate = 3000.0
stop = 0.02
velocity = [0.0, 0.0, -0.3]
velocity_spread = 0.05
[[outlets]]
name = "below"
plane = { point = [0.0, 0.0, 0.002], normal = [0.0, 0.0, -1.0] }
[[sensors]]
name = "mid"
point = [0.0, 0.0, 0.005]
normal = [0.0, 0.0, -1.0]
[contact]
kn = 2.0e4
beta = 1.5
gamma_n = 1000.0
kt = 40.0
mu = 0.4
scaling = "reduced"
rotation = true
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
[run]
integrator = "verlet"
dt = 1.0e-5
duration = 0.08
skin = 0.2
[output]
every = 0.01
frames = false
picture = false
movie = false
"#;

const PLANE_Z: f64 = 0.002;

fn scenario(tag: &str) -> (Loaded, PathBuf) {
    let dir =
        std::env::temp_dir().join(format!("grains-outlet-bodies-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let loaded = load_str(BASE, "outlet-bodies.toml", dir.clone(), &[]).unwrap();
    (loaded, dir)
}

fn begin(loaded: &Loaded) -> (Md<D3>, FlowRun<D3>) {
    let (md, _) = build_md::<D3>(loaded).unwrap();
    let flow = FlowRun::begin(loaded, &md).unwrap();
    (md, flow)
}

/// One step of the run loop's flow hook: events, then the outlets.
fn step(md: &mut Md<D3>, flow: &mut FlowRun<D3>) {
    md.advance(1).unwrap();
    flow.after_step(md);
    flow.outflow(md).unwrap();
}

/// Each body's first grain id and the height of its centre of mass.
fn centres(md: &Md<D3>) -> HashMap<u64, f64> {
    let b = md.bodies().unwrap();
    b.bodies.iter().map(|b| (b.first_id, b.pos.z)).collect()
}

#[test]
fn outlets_take_bodies_out_whole_by_their_centre_of_mass() {
    let (loaded, dir) = scenario("whole");
    let (mut md, mut flow) = begin(&loaded);
    let mut removed = 0;
    while md.step < 5000 {
        md.advance(1).unwrap();
        flow.after_step(&mut md);
        let before = centres(&md);
        flow.outflow(&mut md).unwrap();
        let after = centres(&md);
        for (id, z) in &before {
            if after.contains_key(id) {
                assert!(*z >= PLANE_Z, "body {id} left in the outlet at z = {z}");
            } else {
                assert!(
                    *z < PLANE_Z,
                    "body {id} taken out at z = {z}, above the plane"
                );
                removed += 1;
            }
        }
        // Every body present has its three grains; every free grain is
        // above the plane.
        let owner = md.grain_bodies().unwrap();
        let mut count: HashMap<u32, usize> = HashMap::new();
        for (i, o) in owner.iter().enumerate() {
            match o {
                Some(b) => *count.entry(*b).or_default() += 1,
                None => assert!(D3::get(md.particles.pos[i], 2) >= PLANE_Z),
            }
        }
        let n = md.bodies().unwrap().bodies.len();
        assert_eq!(count.len(), n);
        assert!(count.values().all(|&c| c == 3), "a body lost a part");
    }
    assert!(
        removed > 20,
        "only {removed} bodies left through the outlet"
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn the_mass_balance_and_the_sensor_count_bodies() {
    let (loaded, dir) = scenario("balance");
    let opts = RunOptions {
        out_dir: dir.join("run"),
        ..Default::default()
    };
    let s = run(&loaded, &opts, &mut Silent).unwrap();
    let b = &s["mass_balance"];
    let n = |k: &str| b[k].as_u64().unwrap_or_else(|| panic!("{k} in {b}"));
    let m = |k: &str| b[k].as_f64().unwrap_or_else(|| panic!("{k} in {b}"));
    assert_eq!(b["exact"], true, "{b}");
    assert_eq!(n("initial_grains"), 30, "{b}");
    let inserted = s["inlets"][0]["inserted"].as_u64().unwrap();
    assert_eq!(n("inserted_grains"), inserted);
    assert_eq!(
        n("initial_grains") + n("inserted_grains"),
        n("present_grains") + n("removed_grains")
    );
    let supplied = m("initial_mass") + m("inserted_mass");
    assert!((m("present_mass") + m("removed_mass") - supplied).abs() <= 1e-12 * supplied);
    // 60 rods in 0.02 s, all fallen through by 0.08 s, with the spheres.
    assert_eq!(inserted, 60, "{}", s["inlets"]);
    assert_eq!(n("removed_grains"), 90, "{b}");
    // The sensor 3 mm above the outlet saw each unit go down once, net
    // (by sub-spheres it would count a rod three times).
    let mid = &s["sensors"]["mid"];
    let way = |k: &str| mid[k].as_u64().unwrap();
    assert_eq!(
        way("crossings_forward") - way("crossings_back"),
        90,
        "{mid}"
    );
    // outflow.csv: a row's count is units; its cumulative mass ends at the
    // removed mass.
    let csv = std::fs::read_to_string(dir.join("run/outflow.csv")).unwrap();
    let last: Vec<&str> = csv.lines().last().unwrap().split(',').collect();
    assert_eq!(last[5], "90", "{csv}");
    // Mid-flow, with rods still present: counted by sub-spheres the
    // present units would not balance.
    let opts = RunOptions {
        out_dir: dir.join("mid"),
        steps: Some(4500),
        ..Default::default()
    };
    let s = run(&loaded, &opts, &mut Silent).unwrap();
    let b = &s["mass_balance"];
    let n = |k: &str| b[k].as_u64().unwrap_or_else(|| panic!("{k} in {b}"));
    assert_eq!(b["exact"], true, "{b}");
    assert!(n("removed_grains") > 0 && n("present_grains") > 0, "{b}");
    assert_eq!(
        30 + s["inlets"][0]["inserted"].as_u64().unwrap(),
        n("present_grains") + n("removed_grains"),
        "{b}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// Grains and bodies as bits.
fn bits(md: &Md<D3>) -> Vec<u64> {
    let p = &md.particles;
    let mut out = Vec::new();
    for i in 0..p.n_owned() {
        out.push(p.id[i]);
        for v in [p.pos[i], p.vel[i], p.omega[i]] {
            out.extend(v.to_array().map(f64::to_bits));
        }
    }
    for b in &md.bodies().unwrap().bodies {
        out.push(b.first_id);
        for v in [b.pos, b.vel, b.ang_mom] {
            out.extend(v.to_array().map(f64::to_bits));
        }
        out.extend(b.quat.map(f64::to_bits));
    }
    out
}

#[test]
fn resume_after_removals_gives_the_straight_bits() {
    let (loaded, dir) = scenario("resume");
    let (mut a, mut fa) = begin(&loaded);
    // Past the first removals of rods and spheres, mid-insertion.
    while a.step < 1800 {
        step(&mut a, &mut fa);
    }
    let (engine, flow) = (a.export().unwrap(), fa.save());
    let (mut b, _) = build_md::<D3>(&loaded).unwrap();
    let mut fb = FlowRun::restored(&loaded, &mut b, Some(flow.as_slice()), "test").unwrap();
    b.import(&engine, "test").unwrap();
    assert!(bits(&a) == bits(&b));
    while a.step < 4000 {
        step(&mut a, &mut fa);
        step(&mut b, &mut fb);
    }
    assert!(bits(&a) == bits(&b), "the resumed run differs");
    std::fs::remove_dir_all(dir).ok();
}
