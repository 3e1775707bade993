//! Grains that leave (`md/remove.rs`, `scenario/outlet.rs`): the silo of
//! scenarios/silo-2d.toml filled behind a gate, settled, opened and
//! emptied through an outlet, its grains not recycled.
//!
//! What is checked, each against something the code under test does not
//! compute: the mass balance (initial = present + removed, integers and
//! the same f64 sums; with an inlet feeding the silo, initial + inserted); the outlet removes exactly the grains whose centres
//! a scan of the frames finds beyond its plane; the sensor's crossings
//! equal those counted from the frames; the same bytes on 1 and 2 threads
//! and after a resume mid-discharge; and a removal changes nothing of the
//! grains it leaves but what physics implies (a cluster far from the
//! removed grains moves as it moves alone).

use crate::common;

use common::runs::read_csv;
use glam::DVec2;
use grains::contact::mass_scaling::MassScaling;
use grains::contact::ContactLaw;
use grains::md::{Md, MdSettings};
use grains::particles::{ParticleRecord, Particles};
use grains::runner::checkpointing::{find, resume};
use grains::runner::{run, Progress, RunOptions, Silent};
use grains::scenario::outlet::Outlets;
use grains::scenario::{load_file, Loaded};
use grains::{Domain, D2};
use serde_json::Map;
use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The small silo: 150 disks under g = 30 m/s², an 8 mm slot (8 d0),
/// dt 30 µs; settling ends at the first look after `settle_min` (with the
/// gate: then it opens).
const SMALL: &[&str] = &[
    "gravity=[0.0,-30.0]",
    "particles.count=150",
    "particles.region={lo=[0.0,0.001],hi=[0.03,0.02]}",
    "hopper.outlet=0.008",
    "run.dt=3e-5",
    "run.events.settle_min=0.015",
    "run.events.settle_energy=1e9",
    "output.picture=false",
    "output.frames=false",
];

fn silo(extra: &[&str]) -> Loaded {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/silo-2d.toml");
    let sets: Vec<String> = SMALL.iter().chain(extra).map(|s| s.to_string()).collect();
    load_file(&path, &sets).expect("silo-2d loads")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-silo-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn opts(dir: &Path) -> RunOptions {
    RunOptions {
        out_dir: dir.to_path_buf(),
        ..RunOptions::default()
    }
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Filled, settled (the gate opens at step 500, the first look at or
/// after 15 ms), emptied: the balance holds exactly, outflow.csv adds up to the
/// removed grains, and the steady rate lies inside the window it states.
#[test]
fn silo_mass_balance_is_exact_over_fill_and_discharge() {
    let dir = scratch("balance");
    let s = run(&silo(&["run.duration=0.25"]), &opts(&dir), &mut Silent).unwrap();
    let b = &s["mass_balance"];
    eprintln!(
        "{b}\nrate {} ± {}",
        s["discharge_rate"], s["discharge_rate_error"]
    );
    let n = |k: &str| b[k].as_u64().unwrap();
    let m = |k: &str| b[k].as_f64().unwrap();
    // The count is the scenario's, not the code's.
    assert_eq!(n("initial_grains"), 150);
    assert_eq!(n("inserted_grains"), 0);
    assert_eq!(n("present_grains") + n("removed_grains"), 150);
    assert!(n("removed_grains") >= 50, "the silo discharged: {b}");
    assert_eq!(b["exact"], true, "{b}");
    assert_eq!(m("accounted_mass").to_bits(), m("initial_mass").to_bits());
    // 150 disks of sphere mass, diameters in 1 ± 0.15 mm, 2500 kg/m³.
    let one = 2500.0 * std::f64::consts::PI / 6.0 * 1e-9;
    assert!(m("initial_mass") > 150.0 * one * 0.85f64.powi(3));
    assert!(m("initial_mass") < 150.0 * one * 1.15f64.powi(3));
    // outflow.csv: count and mass columns add up to the removed grains
    // (mass to rounding: the rows sum in groups).
    let rows = read_csv(&dir.join("outflow.csv"));
    let count: f64 = rows.iter().map(|r| r[3]).sum();
    let mass: f64 = rows.iter().map(|r| r[4]).sum();
    assert_eq!(count as u64, n("removed_grains"));
    assert!((mass - m("removed_mass")).abs() <= 1e-12 * m("removed_mass"));
    // Three size classes: each row's classes add up to its count.
    assert!(rows
        .iter()
        .all(|r| r.len() == 10 && r[7] + r[8] + r[9] == r[3]));
    // Nothing leaves before the gate opens (step 500 at 30 µs).
    let opened = s["settle_time"].as_f64().unwrap();
    assert!((opened - 500.0 * 3e-5).abs() < 1e-9, "{s}");
    assert!(rows[0][0] > opened, "first removal at {}", rows[0][0]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Fed and emptied at once: an inlet pours grains into the open silo
/// while the outlet takes them out below. Every grain is accounted for by
/// count (the inlets' own counters against the grains present and
/// removed), and the masses agree to the rounding of their sums.
#[test]
fn silo_fed_by_an_inlet_balances_inserted_against_present_and_removed() {
    let dir = scratch("fed");
    let inlet = "inlets=[{region={shape=\"box\",lo=[0.002,0.024],hi=[0.028,0.034]},\
                 rate=4000.0,stop=0.1,velocity=[0.0,-0.2]}]";
    let loaded = silo(&[
        "hopper.gate=false",
        "run.events.remove_wall=\"\"",
        "run.duration=0.2",
        inlet,
    ]);
    let s = run(&loaded, &opts(&dir), &mut Silent).unwrap();
    let b = &s["mass_balance"];
    let n = |k: &str| b[k].as_u64().unwrap();
    // 4000 grains/s for 0.1 s: floor(rate t) = 400, none short.
    let fed = &s["inlets"][0];
    assert_eq!(fed["inserted"], 400, "{fed}");
    assert_eq!(fed["not_inserted"], 0, "{fed}");
    assert_eq!(n("initial_grains"), 150);
    assert_eq!(n("inserted_grains"), 400, "{b}");
    assert_eq!(n("present_grains") + n("removed_grains"), 550, "{b}");
    assert!(n("removed_grains") >= 50, "the silo discharged: {b}");
    assert_eq!(b["exact"], true, "{b}");
    let supplied = b["initial_mass"].as_f64().unwrap() + fed["mass"].as_f64().unwrap();
    let gap = b["accounted_mass"].as_f64().unwrap() - supplied;
    assert!(gap.abs() <= 1e-12 * supplied, "{b}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Steps the small silo by hand (gate open from the start): after each
/// step a scan of the frame finds the grains beyond the outlet's plane
/// (y < -5 mm) and the grains whose centre crossed the sensor's line
/// (y = 0) since the last step; the outlet must remove exactly those, and
/// the sensor's totals equal the crossings counted.
#[test]
fn outlet_and_sensor_agree_with_a_scan_of_the_frames() {
    let loaded = silo(&["hopper.gate=false", "run.events.remove_wall=\"\""]);
    let loaded = grains::scenario::hopper::expand(&loaded)
        .unwrap()
        .into_owned();
    let (mut md, _) = grains::scenario::build_md::<D2>(&loaded).unwrap();
    let mut outlets = Outlets::<D2>::begin(&loaded.scenario, &md)
        .unwrap()
        .unwrap();
    let below = |f: &grains::io::Frame| -> HashMap<u64, bool> {
        f.id.iter()
            .zip(&f.pos)
            .map(|(&id, p)| (id, p[1] < 0.0))
            .collect()
    };
    let mut side = below(&md.frame());
    let (mut forward, mut back, mut removed) = (0u64, 0u64, 0usize);
    for _ in 0..4000 {
        md.step().unwrap();
        let f = md.frame();
        let now = below(&f);
        for (id, &b) in &now {
            match (side[id], b) {
                (false, true) => forward += 1,
                (true, false) => back += 1,
                _ => {}
            }
        }
        side = now;
        let beyond: BTreeSet<u64> =
            f.id.iter()
                .zip(&f.pos)
                .filter(|(_, p)| p[1] < -0.005)
                .map(|(&id, _)| id)
                .collect();
        outlets.after_step(&mut md).unwrap();
        let kept: BTreeSet<u64> = md.frame().id.into_iter().collect();
        let before: BTreeSet<u64> = f.id.iter().copied().collect();
        let gone: BTreeSet<u64> = before.difference(&kept).copied().collect();
        assert_eq!(gone, beyond, "step {}", md.step);
        for id in &gone {
            side.remove(id);
        }
        removed += gone.len();
    }
    eprintln!("removed {removed}, crossed forward {forward}, back {back}");
    assert!(removed >= 50 && forward >= removed as u64, "a discharge");
    let dir = scratch("scan");
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = Map::new();
    outlets.finish(&dir, &md, (0, 0.0), &mut s).unwrap();
    let o = &s["sensors"]["orifice"];
    assert_eq!(o["crossings_forward"], forward, "{o}");
    assert_eq!(o["crossings_back"], back, "{o}");
    assert_eq!(s["mass_balance"]["removed_grains"], removed);
    assert_eq!(s["mass_balance"]["exact"], true);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same discharge on 1 and 2 threads: the same bytes.
#[test]
fn silo_discharge_same_bits_on_one_and_two_threads() {
    let loaded = silo(&["run.duration=0.06"]);
    let mut dirs = Vec::new();
    for threads in [1, 2] {
        let dir = scratch(&format!("threads{threads}"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let s = pool.install(|| run(&loaded, &opts(&dir), &mut Silent).unwrap());
        assert!(s["mass_balance"]["removed_grains"].as_u64().unwrap() > 10);
        dirs.push(dir);
    }
    for f in ["thermo.csv", "outflow.csv", "sensors.csv"] {
        assert!(
            read(&dirs[0].join(f)) == read(&dirs[1].join(f)),
            "{f} differs"
        );
    }
    for d in dirs {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// Raises the stop flag once the run's progress reaches `at` steps.
struct StopAt(Arc<AtomicBool>, u64);

impl Progress for StopAt {
    fn phase(&mut self, _: &str, _: u64) {}
    fn advance(&mut self, done: u64, _: f64) {
        if done >= self.1 {
            self.0.store(true, Ordering::SeqCst);
        }
    }
    fn finish(&mut self) {}
}

/// Stopped mid-discharge (step 1280, the gate open since step 500) and resumed:
/// the same thermo.csv, outflow.csv, sensors.csv and summary as straight.
#[test]
fn silo_resumed_mid_discharge_gives_the_same_bytes() {
    let loaded = silo(&["run.duration=0.06"]);
    let plain = scratch("plain");
    let s0 = run(&loaded, &opts(&plain), &mut Silent).unwrap();
    let dir = scratch("stopped");
    let flag = Arc::new(AtomicBool::new(false));
    let o = RunOptions {
        stop: Some(flag.clone()),
        ..opts(&dir)
    };
    let s = run(&loaded, &o, &mut StopAt(flag, 1280)).unwrap();
    assert_eq!(s["interrupted"], true, "{s}");
    let (found, _) = find(&dir).unwrap();
    let at = found.step;
    let s1 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
    eprintln!("stopped at step {at}");
    let rows = read_csv(&plain.join("outflow.csv"));
    assert!(
        rows.iter().any(|r| (r[1] as u64) < at) && rows.iter().any(|r| (r[1] as u64) > at),
        "grains leave before and after the stop"
    );
    for f in ["thermo.csv", "outflow.csv", "sensors.csv"] {
        assert!(read(&plain.join(f)) == read(&dir.join(f)), "{f} differs");
    }
    for (k, v) in s0.as_object().unwrap() {
        if k.contains("seconds") || k.starts_with("ns_per") || k == "threads" {
            continue;
        }
        assert_eq!(Some(v), s1.get(k), "summary {k}");
    }
    let _ = std::fs::remove_dir_all(&plain);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two clusters of touching disks, far apart, without gravity, each
/// squeezed and sheared (so the tangential springs stretch while they
/// rebound): removing the second at step 20, mid-contact, leaves the first
/// moving as it moves alone, to rounding (the force sums may run in another
/// order, nothing more).
#[test]
fn removing_grains_leaves_the_others_moving_as_physics_implies() {
    let cluster = |first: u64, x0: f64| -> Vec<ParticleRecord<D2>> {
        (0..6u64)
            .map(|k| {
                let x = DVec2::new(x0 + 0.95 * (k % 3) as f64, 0.95 * (k / 3) as f64);
                let mut g = ParticleRecord::new(first + k, x, 0.5, 1.0, 0.125);
                g.vel = DVec2::new(0.01 * k as f64, -0.02 * (k % 2) as f64);
                g.omega = 0.1 * k as f64;
                g
            })
            .collect()
    };
    let engine = |records: Vec<ParticleRecord<D2>>| {
        let mut p = Particles::<D2>::new();
        for r in records {
            p.push_record(r);
        }
        let domain = Domain::new(DVec2::splat(-10.0), DVec2::splat(60.0), [false; 3]);
        // LAMMPS chute's Hooke-with-history coefficients, m = 1: a contact
        // lasts about 5 ms, 50 steps.
        let law = ContactLaw {
            kn: 2e5,
            beta: 1.0,
            gamma_n: 50.0,
            gamma_t: 30.0,
            kt: 2e5 * 2.0 / 7.0,
            mu: 0.5,
            scaling: MassScaling::Reduced,
            rotation: true,
        };
        let settings = MdSettings::new(1e-4, law, 0.2);
        Md::new(p, domain, vec![], settings).unwrap()
    };
    let a = cluster(1, 0.0);
    let mut both = a.clone();
    both.extend(cluster(7, 40.0));
    let mut alone = engine(a);
    let mut pair = engine(both);
    pair.advance(20).unwrap();
    let gone = pair.remove_grains(&[7, 8, 9, 10, 11, 12]).unwrap();
    assert_eq!(
        gone.iter().map(|g| g.id).collect::<Vec<_>>(),
        [7, 8, 9, 10, 11, 12]
    );
    assert!(pair.remove_grains(&[7]).is_err(), "a removed id is refused");
    pair.advance(480).unwrap();
    alone.advance(500).unwrap();
    let (fa, fp) = (alone.frame(), pair.frame());
    let by_id = |f: &grains::io::Frame| -> Vec<(u64, [f64; 3], [f64; 3])> {
        let mut v: Vec<_> = (0..f.len())
            .map(|i| (f.id[i], f.pos[i], f.vel[i]))
            .collect();
        v.sort_by_key(|e| e.0);
        v
    };
    let (ga, gp) = (by_id(&fa), by_id(&fp));
    assert_eq!(ga.len(), gp.len());
    let moved = ga
        .iter()
        .zip(&cluster(1, 0.0))
        .any(|(g, c)| (g.1[0] - c.pos.x).abs() > 1e-3);
    assert!(moved, "the cluster moved");
    for (x, y) in ga.iter().zip(&gp) {
        assert_eq!(x.0, y.0);
        for k in 0..2 {
            assert!(
                (x.1[k] - y.1[k]).abs() < 1e-12,
                "grain {} pos {x:?} {y:?}",
                x.0
            );
            assert!(
                (x.2[k] - y.2[k]).abs() < 1e-12,
                "grain {} vel {x:?} {y:?}",
                x.0
            );
        }
    }
}

/// On the GPU (its CPU mirror) the silo is refused by name before it runs
/// (under mpirun it runs: `tests/parallel/distributed_inlets.rs`).
#[test]
fn outlets_are_refused_on_the_gpu() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/pour-3d.toml");
    let sets = [
        "run.device=\"mirror\"".to_string(),
        "outlets=[{name=\"low\",plane={point=[0.0,0.0,0.0],normal=[0.0,0.0,-1.0]}}]".into(),
    ];
    let gpu = load_file(&path, &sets).unwrap();
    let e = grains::scenario::device::check_device(&gpu)
        .unwrap_err()
        .to_string();
    assert!(e.contains("[[outlets]]/[[sensors]]"), "{e}");
}

/// Bad keys: a clear error naming the key, never a panic.
#[test]
fn outlet_keys_are_checked_by_name() {
    let err = |sets: &[&str]| {
        let l = silo(sets);
        let dir = scratch("bad");
        let e = run(&l, &opts(&dir), &mut Silent).unwrap_err().to_string();
        let _ = std::fs::remove_dir_all(&dir);
        e
    };
    let e = err(&["outlets=[{name=\"x\"}]"]);
    assert!(
        e.contains("outlets[0] (\"x\")") && e.contains("exactly one of"),
        "{e}"
    );
    let e = err(&["outlets=[{name=\"x\",plane={point=[0.0,0.0],normal=[0.0,0.0]}}]"]);
    assert!(e.contains("outlets[0] (\"x\").plane.normal"), "{e}");
    let e = err(&["outlets=[]"]);
    assert!(e.contains("hopper.recycle = false"), "{e}");
    let e = err(&["sensors=[{name=\"below\",point=[0.0,0.0],normal=[0.0,1.0]}]"]);
    assert!(e.contains("\"below\" is used twice"), "{e}");
}
