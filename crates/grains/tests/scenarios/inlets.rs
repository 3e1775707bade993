//! `[[inlets]]`: grains arriving during a run. The count follows
//! floor(rate (t − start)) at every step and the mass stays within one
//! grain of mass_rate (t − start) (the schedule's definition); no inserted
//! grain overlaps a grain, a plane wall or a mesh wall by more than 1e-9 of
//! its diameter (distances computed here from the geometry, not by the
//! engine's wall code); the loop driven by the inlets' own schedule gives
//! the bits of acting after every step; 1 and 2 threads give the same
//! bits; a resume from the middle of the insertion gives the straight
//! run's bits; a full region is reported in summary.json; bad keys are
//! named.

use glam::DVec3;
use grains::dim::D3;
use grains::engine::Engine;
use grains::md::Md;
use grains::runner::{run, RunOptions, Silent};
use grains::scenario::flow::FlowRun;
use grains::scenario::{build_md, load_str, Loaded};
use std::path::PathBuf;

/// A 6 x 6 mm box with a floor and four side walls, 40 grains resting low
/// in it, a horizontal mesh sheet at z = 13 mm over the left half, and the
/// contacts of pour-3d (1 mm glass beads).
const BASE: &str = r#"name = "inlets"
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
region = { lo = [0.0, 0.0, 0.0], hi = [0.006, 0.006, 0.012] }
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
dt = 1.0e-5
duration = 0.03
skin = 0.2
[output]
frames = false
picture = false
movie = false
"#;

/// The planes of BASE (and of `inlet_bodies`' box): (point, inward normal).
pub(super) const PLANES: [([f64; 3], [f64; 3]); 5] = [
    ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
    ([0.006, 0.0, 0.0], [-1.0, 0.0, 0.0]),
    ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ([0.0, 0.006, 0.0], [0.0, -1.0, 0.0]),
];

/// The sheet: z = 13 mm over x in [0, 3] mm, y in [0, 6] mm.
pub(super) const SHEET_Z: f64 = 0.013;
pub(super) const SHEET_X: f64 = 0.003;

fn scratch(tag: &str) -> PathBuf {
    scratch_in("inlets", tag)
}

/// A fresh folder `grains-{prefix}-{pid}-{tag}` holding the sheet's STL.
pub(super) fn scratch_in(prefix: &str, tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-{prefix}-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let (x, y, z) = (SHEET_X, 0.006, SHEET_Z);
    let stl = format!(
        "solid sheet\n\
         facet normal 0 0 1\n outer loop\n  vertex 0 0 {z}\n  vertex {x} 0 {z}\n  vertex {x} {y} {z}\n endloop\nendfacet\n\
         facet normal 0 0 1\n outer loop\n  vertex 0 0 {z}\n  vertex {x} {y} {z}\n  vertex 0 {y} {z}\n endloop\nendfacet\n\
         endsolid sheet\n"
    );
    std::fs::write(d.join("sheet.stl"), stl).unwrap();
    d
}

/// BASE with `inlet` as its one `[[inlets]]` table (its keys, one a line).
fn scenario(tag: &str, inlet: &str) -> (Loaded, PathBuf) {
    let dir = scratch(tag);
    let text = format!("{BASE}[[inlets]]\n{inlet}\n");
    let loaded = load_str(&text, "inlets.toml", dir.clone(), &[]).unwrap();
    (loaded, dir)
}

fn error(inlet: &str) -> String {
    let dir = scratch("bad");
    let text = format!("{BASE}[[inlets]]\n{inlet}\n");
    let e = match load_str(&text, "inlets.toml", dir.clone(), &[]) {
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

pub(super) fn begin(loaded: &Loaded) -> (Md<D3>, FlowRun<D3>) {
    let (md, _) = build_md::<D3>(loaded).unwrap();
    let flow = FlowRun::begin(loaded, &md).unwrap();
    (md, flow)
}

/// The run loop's way: advance to the flow run's next act, act.
fn run_to(md: &mut Md<D3>, flow: &mut FlowRun<D3>, end: u64) {
    while md.step < end {
        let next = flow.next_act(md.step, (md.step + 256).min(end));
        md.advance(next - md.step).unwrap();
        flow.after_step(md);
    }
}

/// Positions, velocities, spins and ids as bits, in store order.
fn bits(md: &Md<D3>) -> Vec<u64> {
    let p = &md.particles;
    let mut out = Vec::new();
    for i in 0..p.n_owned() {
        out.push(p.id[i]);
        for v in [p.pos[i], p.vel[i], p.omega[i]] {
            out.extend(v.to_array().map(f64::to_bits));
        }
    }
    out
}

#[test]
fn count_follows_the_rate_within_one_grain_at_every_step() {
    // 2000 grains/s from t = 2 ms to 12 ms: 20 grains; one act per step.
    let (rate, start, stop) = (2000.0, 0.002, 0.012);
    let inlet = format!("{FALL}\nrate = {rate}\nstart = {start}\nstop = {stop}");
    let (loaded, dir) = scenario("rate", &inlet);
    let (mut md, mut flow) = begin(&loaded);
    let placed = md.particles.n_owned();
    while md.step < 1600 {
        md.advance(1).unwrap();
        flow.after_step(&mut md);
        let t = md.time.min(stop);
        let want = if t < start { 0.0 } else { rate * (t - start) };
        let got = (md.particles.n_owned() - placed) as f64;
        assert!(
            got <= want && want - got < 1.0,
            "t = {}: {got} grains, {want} requested",
            md.time
        );
    }
    let total = (rate * (stop - start)).floor() as usize;
    assert_eq!(md.particles.n_owned() - placed, total);
    assert_eq!(total, 20);
    // The run loop's way (advancing to the inlet's next act) inserts at
    // the same steps: the same bits.
    let (mut b, mut fb) = begin(&loaded);
    run_to(&mut b, &mut fb, 1600);
    assert!(bits(&md) == bits(&b), "next_act skipped or delayed a grain");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn mass_follows_the_mass_rate_within_one_grain() {
    // 2500 kg/m³ beads of 0.9–1.1 mm weigh 0.95–1.74 mg: 4e-3 kg/s is
    // about 30 grains in the 10 ms.
    let q = 4.0e-3;
    let inlet = format!("{FALL}\nmass_rate = {q}\nstop = 0.01");
    let (loaded, dir) = scenario("mass", &inlet);
    let (mut md, mut flow) = begin(&loaded);
    let placed = md.particles.n_owned();
    let heaviest = 2500.0 * std::f64::consts::PI * 1.1e-3f64.powi(3) / 6.0;
    for _ in 0..1200 {
        md.advance(1).unwrap();
        flow.after_step(&mut md);
        let p = &md.particles;
        let mass: f64 = p.mass[..p.n_owned()]
            .iter()
            .zip(&p.id)
            .filter(|&(_, &id)| id > placed as u64)
            .map(|(m, _)| m)
            .sum();
        let want = q * md.time.min(0.01);
        assert!(
            mass <= want * (1.0 + 1e-12) && want - mass < heaviest,
            "t = {}: {mass} kg inserted, {want} kg requested",
            md.time
        );
    }
    // The rate was met, not trivially undershot: 4e-5 kg is 23 grains of
    // the heaviest size at least.
    let n = md.particles.n_owned() - placed;
    assert!(n >= 23, "{n} grains inserted in 10 ms at {q} kg/s");
    std::fs::remove_dir_all(dir).ok();
}

/// The deepest overlap of grain `i` with any other grain, plane or the
/// sheet, as a fraction of its diameter (negative: clear).
fn worst_overlap(md: &Md<D3>, i: usize) -> f64 {
    let p = &md.particles;
    let (x, r) = (p.pos[i], p.radius[i]);
    let mut worst = f64::NEG_INFINITY;
    for j in (0..p.n_owned()).filter(|&j| j != i) {
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
fn inserted_grains_overlap_nothing() {
    // A crowded region across the sheet and down among the resting grains:
    // more is asked than fits, so many candidate spots are refused.
    let inlet = r#"region = { shape = "cylinder", center = [0.003, 0.003], radius = 0.003, bottom = 0.0, top = 0.019 }
rate = 40000.0
stop = 0.02"#;
    let (loaded, dir) = scenario("overlap", inlet);
    let (mut md, mut flow) = begin(&loaded);
    let mut checked = 0;
    while md.step < 2000 {
        let next = flow.next_act(md.step, md.step + 256);
        md.advance(next - md.step).unwrap();
        let before: std::collections::HashSet<u64> = md.particles.id.iter().copied().collect();
        flow.after_step(&mut md);
        for i in 0..md.particles.n_owned() {
            if before.contains(&md.particles.id[i]) {
                continue;
            }
            let w = worst_overlap(&md, i);
            assert!(
                w <= 1e-9,
                "grain {} inserted overlapping by {w:e} of its diameter",
                md.particles.id[i]
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "only {checked} grains inserted");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn same_bits_on_one_and_two_threads() {
    let inlet = format!("{FALL}\nrate = 5000.0\nstop = 0.015");
    let (loaded, dir) = scenario("threads", &inlet);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (mut md, mut flow) = begin(&loaded);
            run_to(&mut md, &mut flow, 2000);
            bits(&md)
        })
    };
    let one = on(1);
    assert!(one == on(2), "1 and 2 threads differ");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn resume_in_the_middle_of_the_insertion_gives_the_straight_bits() {
    let inlet = format!("{FALL}\nrate = 5000.0\nstop = 0.015");
    let (loaded, dir) = scenario("resume", &inlet);
    let (mut a, mut fa) = begin(&loaded);
    // Stop right after an insertion, before the list is rebuilt.
    let n0 = a.particles.n_owned();
    while a.particles.n_owned() < n0 + 12 {
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
    assert!(a.particles.n_owned() > n0 + 50);
    assert!(bits(&a) == bits(&b), "the resumed run differs");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_full_region_is_reported_not_dropped() {
    // A 2 mm layer can hold about 40 grains; 300 are asked for.
    let inlet = r#"region = { shape = "box", lo = [0.0, 0.0, 0.016], hi = [0.006, 0.006, 0.018] }
count = 300
start = 0.001
stop = 0.002"#;
    let (loaded, dir) = scenario("full", inlet);
    let opts = RunOptions {
        out_dir: dir.join("run"),
        steps: Some(400),
        ..Default::default()
    };
    let s = run(&loaded, &opts, &mut Silent).unwrap();
    let row = &s["inlets"][0];
    let n = |k: &str| row[k].as_u64().unwrap_or_else(|| panic!("{k} in {row}"));
    assert_eq!(n("requested"), 300);
    assert!(n("inserted") > 10 && n("inserted") < 300, "{row}");
    assert_eq!(n("inserted") + n("not_inserted"), 300);
    assert!(n("failed_attempts") >= 50, "{row}");
    assert!(row["mass"].as_f64().unwrap() > 0.0);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn grains_check_prints_the_expected_count() {
    let inlet = format!("{FALL}\nrate = 1000.0\nstart = 0.01");
    let (loaded, dir) = scenario("check", &inlet);
    let v = grains::scenario::inlet::check_report(&loaded, 0.03).unwrap();
    assert_eq!(v[0]["rate_unit"], "grains/s");
    assert!((v[0]["expected"].as_f64().unwrap() - 20.0).abs() < 1e-9);
    let mean = v[0]["size"]["number_mean"].as_f64().unwrap();
    assert!((mean - 1.0e-3).abs() < 1e-6, "{mean}");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_inlets_are_named() {
    let e = error(&format!("{FALL}\nrate = 10.0\ncount = 5"));
    assert!(
        e.contains("inlets[0]") && e.contains("rate, count") && e.contains("mass_rate"),
        "{e}"
    );
    let e = error(FALL);
    assert!(e.contains("inlets[0]") && e.contains("exactly one"), "{e}");
    let e = error(&format!("{FALL}\nrat = 10.0"));
    assert!(e.contains("rat"), "{e}");
    let e = error(&format!("{FALL}\nrate = -1.0"));
    assert!(e.contains("inlets[0].rate"), "{e}");
    let e = error(
        "region = { shape = \"box\", lo = [0.0, 0.0, 0.01], hi = [0.006, 0.006, 0.03] }\nrate = 1.0",
    );
    assert!(
        e.contains("inlets[0].region") && e.contains("domain"),
        "{e}"
    );
    let e = error(&format!(
        "{FALL}\nrate = 1.0\nsize = {{ distribution = \"lognormal\", mean = 1.0e-3, min = 0.5e-3, max = 2e-3 }}"
    ));
    assert!(e.contains("inlets[0].size.std"), "{e}");
    let e = error("region = { shape = \"box\", lo = [0.0, 0.0], hi = [0.006, 0.006] }\nrate = 1.0");
    assert!(e.contains("inlets[0].region.lo"), "{e}");
    let e = error(&format!("{FALL}\nrate = 1.0\nstart = 0.02\nstop = 0.01"));
    assert!(e.contains("inlets[0].stop"), "{e}");
}
