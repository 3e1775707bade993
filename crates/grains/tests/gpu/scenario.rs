//! Scenario runs on the GPU pipeline (`run.device = "mirror"`: its CPU
//! loops) through the run loop and its hooks: the same files as the CPU
//! engine's run, bit for bit, and a resumed checkpoint that ends as the
//! straight run.

use grains::runner::checkpointing::{self, Every};
use grains::runner::{run, RunOptions, Silent};
use grains::scenario::{load_str, Loaded};
use std::path::{Path, PathBuf};

/// 300 grains on a fixed floor, periodic sideways, under gravity tilted
/// along x, with frictional springs; measured after 200 relaxation steps
/// for 1000, output every 73 steps, convection sampled every 7.
fn scenario(device: &str, sets: &[&str]) -> Loaded {
    let dt = 2.0e-6;
    let text = format!(
        r#"name = "device-bed"
dimension = "3d"
seed = 11
gravity = [20.0, 0.0, -100.0]
[domain]
lo = [0.0, 0.0, -0.002]
hi = [0.006, 0.006, 0.03]
periodic = [true, true, false]
[particles]
placement = "lattice"
count = 300
d0 = 1.0e-3
width = 0.3
random_velocity = 0.1
region = {{ lo = [0.0, 0.0, 0.0005], hi = [0.006, 0.006, 0.028] }}
[contact]
preset = "lammps-hooke-history"
kn = 2.0e3
[[walls]]
name = "floor"
shape = {{ type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[run]
integrator = "verlet"
dt = {dt}
relax = {relax}
duration = {duration}
device = "{device}"
[output]
every = {every}
picture = false
[measure]
convection = {{ band = 0.2 }}
"#,
        relax = 200.0 * dt,
        duration = 1000.0 * dt,
        every = 73.0 * dt,
    );
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_str(&text, "device-bed", PathBuf::from("."), &sets).unwrap()
}

fn out_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-device-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Every file under `dir` (relative path, bytes), checkpoints left out.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut all = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_none_or(|x| x != "grck") {
                let rel = p.strip_prefix(dir).unwrap().to_path_buf();
                all.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    all.sort();
    all
}

/// summary.json without what depends on the machine or names the engine.
fn physics(summary: &serde_json::Value) -> serde_json::Value {
    let mut s = summary.clone();
    let m = s.as_object_mut().unwrap();
    for k in [
        "wall_seconds",
        "ns_per_particle_step",
        "phase_seconds",
        "threads",
        "device",
    ] {
        m.remove(k);
    }
    s
}

fn assert_same_files(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    let names = |f: &[(PathBuf, Vec<u8>)]| f.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&fa), names(&fb), "the runs wrote other files");
    for ((name, x), (_, y)) in fa.iter().zip(&fb) {
        if name.as_os_str() == "summary.json" {
            let parse = |b: &[u8]| physics(&serde_json::from_slice(b).unwrap());
            assert_eq!(parse(x), parse(y), "summary.json differs");
        } else {
            assert!(x == y, "{} differs", name.display());
        }
    }
}

#[test]
fn a_mirror_run_writes_the_cpu_runs_files() {
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        checkpoint_every: Some(Every::Steps(199)),
        ..Default::default()
    };
    let (cpu, mirror) = (out_dir("cpu"), out_dir("mirror"));
    let a = run(&scenario("cpu", &[]), &opts(&cpu), &mut Silent).unwrap();
    let b = run(&scenario("mirror", &[]), &opts(&mirror), &mut Silent).unwrap();
    assert_eq!(a["steps"], 1200);
    assert_eq!(b["device"]["engine"], "mirror");
    assert_eq!(a["neighbor_builds"], b["neighbor_builds"]);
    assert!(a["neighbor_builds"].as_u64().unwrap() > 2);
    assert!(cpu.join("convection_profile.csv").exists());
    assert_same_files(&cpu, &mirror);
    // The newest checkpoints hold the same engine state.
    let state = |dir: &Path| {
        let md = checkpointing::find(dir)
            .unwrap()
            .0
            .restore_md::<grains::D3>()
            .unwrap();
        assert_eq!(md.step, 1194);
        md.export_state().unwrap()
    };
    let (x, y) = (state(&cpu), state(&mirror));
    let bits = |v: &[glam::DVec3]| -> Vec<[u64; 3]> {
        v.iter().map(|a| a.to_array().map(f64::to_bits)).collect()
    };
    assert_eq!(x.particles.id, y.particles.id, "grain order");
    let (p, q) = (&x.particles, &y.particles);
    for (name, a, b) in [
        ("positions", &p.pos, &q.pos),
        ("velocities", &p.vel, &q.vel),
        ("spins", &p.omega, &q.omega),
        ("forces", &p.force, &q.force),
        ("torques", &p.torque, &q.torque),
        ("springs", &x.springs, &y.springs),
        ("wall springs", &x.wall_springs, &y.wall_springs),
    ] {
        assert!(bits(a) == bits(b), "{name} differ");
    }
    assert_eq!(x.list.pairs, y.list.pairs, "pairs");
    assert_eq!(
        (x.contacts, x.max_overlap.to_bits(), x.worst_pair),
        (y.contacts, y.max_overlap.to_bits(), y.worst_pair),
        "statistics"
    );
    let encode = |s| {
        let mut e = grains::codec::Enc::default();
        grains::md::codec::encode_md(&mut e, &s);
        e.buf
    };
    assert!(encode(x) == encode(y), "checkpoint states differ");

    // Resumed from its checkpoint at step 995 (the later one left out), the
    // mirror run ends with the straight run's files.
    let resumed = out_dir("resumed");
    std::fs::create_dir_all(&resumed).unwrap();
    let copy = |from: &Path, to: &Path| {
        for (rel, bytes) in files(from) {
            std::fs::create_dir_all(to.join(&rel).parent().unwrap()).unwrap();
            std::fs::write(to.join(&rel), bytes).unwrap();
        }
    };
    copy(&mirror, &resumed);
    let ck = "checkpoint-000000000995.grck";
    std::fs::copy(mirror.join(ck), resumed.join(ck)).unwrap();
    let (found, _) = checkpointing::find(&resumed).unwrap();
    let c = checkpointing::resume(found, None, opts(&resumed), &mut Silent).unwrap();
    assert_eq!(c["steps"], 1200);
    assert_same_files(&mirror, &resumed);
    for d in [cpu, mirror, resumed] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// What the pipeline does not run is refused before the run, by name.
#[test]
fn a_mirror_run_refuses_what_the_pipeline_does_not_run() {
    let dir = out_dir("refused");
    let opts = RunOptions {
        out_dir: dir.clone(),
        ..Default::default()
    };
    for (set, named) in [
        ("run.integrator=gear5", "run.integrator = \"gear5\""),
        ("run.events.settle_energy=1.0", "run.events"),
    ] {
        let e = run(&scenario("mirror", &[set]), &opts, &mut Silent)
            .unwrap_err()
            .to_string();
        assert!(e.contains(named), "{set}: {e}");
    }
    let _ = std::fs::remove_dir_all(dir);
}
