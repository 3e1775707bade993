//! Checkpoint and resume of flow runs: a `[hopper]` silo recycling its
//! grains (with `measure.spacetime` and `measure.surface_angle` sampling),
//! and a `run.events` pile that settles, loses its right wall and is then
//! tilted. Each runs straight through, then again stopped (the path of
//! SIGINT/SIGTERM) at steps in each stage and resumed from the checkpoint
//! written there: thermo.csv, frames.pvd, every frame, the flow files
//! (discharge.csv, spacetime.csv, surface.csv) and every summary scalar but
//! the timings must be the same bytes. A run with `--checkpoint-every`
//! resumed from its next-to-last checkpoint ends with the same last
//! checkpoint (engine and flow state) as the straight run.

use grains::md::Md;
use grains::runner::checkpointing::{find, resume, Every};
use grains::runner::{run, Progress, RunOptions, Silent};
use grains::scenario::{load_str, Loaded};
use grains::{Dim, D2};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

fn scenario_with(file: &str, sets: &str, extra: &[&str]) -> Loaded {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    let text = std::fs::read_to_string(dir.join(file)).unwrap();
    let sets: Vec<String> = sets
        .lines()
        .chain(extra.iter().copied())
        .map(String::from)
        .collect();
    load_str(&text, file, PathBuf::from("."), &sets).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-ck-flow-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// `files` (those of `a` that exist must exist in `b`) and every frame of
/// `a` equal those of `b`, byte for byte.
fn same_files(a: &Path, b: &Path, files: &[&str], what: &str) {
    for f in ["thermo.csv", "frames.pvd"].iter().chain(files) {
        assert!(read(&a.join(f)) == read(&b.join(f)), "{what}: {f} differs");
    }
    let mut names: Vec<_> = std::fs::read_dir(a.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(names.len() >= 10, "{what}: {} frames", names.len());
    for n in names {
        let (x, y) = (a.join("frames").join(&n), b.join("frames").join(&n));
        assert!(read(&x) == read(&y), "{what}: {} differs", x.display());
    }
}

/// Every summary entry of `a` in `b` alike, the timings aside.
fn same_summary(a: &Value, b: &Value, what: &str) {
    let (a, b) = (a.as_object().unwrap(), b.as_object().unwrap());
    for (k, v) in a {
        if k.contains("seconds") || k.starts_with("ns_per") || k == "threads" {
            continue;
        }
        assert_eq!(Some(v), b.get(k), "{what}: summary {k}");
    }
}

/// Raises the stop flag when the progress of phase `phase` reaches `at`
/// (the runner reports progress every 256 steps and checks the flag right
/// after, as after a signal: `at` a multiple of 256 is the step it stops
/// at).
struct StopAt {
    flag: Arc<AtomicBool>,
    phase: &'static str,
    at: u64,
    on: bool,
}

impl Progress for StopAt {
    fn phase(&mut self, name: &str, _: u64) {
        self.on = name == self.phase;
    }
    fn advance(&mut self, done: u64, _: f64) {
        if self.on && done >= self.at {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
    fn finish(&mut self) {}
}

/// `loaded` straight through; with checkpoints every `every` steps; and
/// stopped at each of `stops` (phase, step of the phase) and resumed.
/// `stage(k, md)` checks the engine of stop k's checkpoint (the stage it
/// was taken in). Returns the straight run's summary.
fn check(
    name: &str,
    loaded: &Loaded,
    files: &[&str],
    every: u64,
    stops: &[(&'static str, u64)],
    stage: &dyn Fn(usize, &Md<D2>),
) -> Value {
    let plain = scratch(&format!("{name}-plain"));
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        ..RunOptions::default()
    };
    let s0 = run(loaded, &opts(&plain), &mut Silent).unwrap();
    let end = s0["steps"].as_u64().unwrap();
    assert_eq!(end % every, 0, "{name}: {end} steps");

    // With checkpoints: the same files; resumed from the next-to-last
    // checkpoint, the same last one.
    let straight = scratch(&format!("{name}-straight"));
    let o = RunOptions {
        checkpoint_every: Some(Every::Steps(every)),
        ..opts(&straight)
    };
    let s1 = run(loaded, &o, &mut Silent).unwrap();
    same_files(&plain, &straight, files, name);
    same_summary(&s0, &s1, name);
    let last = straight.join(grains::checkpoint::file_name(end));
    let final_state = read(&last);
    let (found, _) = find(&straight.join(grains::checkpoint::file_name(end - every))).unwrap();
    std::fs::remove_file(&last).unwrap();
    let s2 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
    assert!(
        read(&last) == final_state,
        "{name}: the resumed run's last checkpoint differs"
    );
    same_files(&plain, &straight, files, name);
    same_summary(&s0, &s2, name);

    for (k, &(phase, at)) in stops.iter().enumerate() {
        let what = format!("{name}: stop in {phase} at {at}");
        let dir = scratch(&format!("{name}-stop{k}"));
        let flag = Arc::new(AtomicBool::new(false));
        let mut p = StopAt {
            flag: flag.clone(),
            phase,
            at,
            on: false,
        };
        let o = RunOptions {
            stop: Some(flag),
            ..opts(&dir)
        };
        let s = run(loaded, &o, &mut p).unwrap();
        assert_eq!(s["interrupted"], true, "{what}: {s}");
        let (found, _) = find(&dir).unwrap();
        eprintln!("{what}: checkpoint at step {}", found.step);
        stage(k, &found.restore_md::<D2>().unwrap());
        let s3 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
        same_files(&plain, &dir, files, &what);
        same_summary(&s0, &s3, &what);
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&straight);
    let _ = std::fs::remove_dir_all(&plain);
    s0
}

/// The small silo of `data/small-hopper.sets` (150 grains, recycled within
/// a few hundred steps), relaxing 300 steps then measured 1200, with the
/// space–time density and a surface fit sampled: stopped while relaxing
/// and twice while measuring, grains already recycled.
#[test]
fn hopper_with_flow_measurements_resumes_bit_for_bit() {
    let loaded = scenario_with(
        "hopper-2d.toml",
        include_str!("../data/small-hopper.sets"),
        &[
            "run.relax=0.009",
            "run.duration=0.036",
            "output.every=0.0015",
            "output.frames=true",
            "measure.spacetime.bin=2.0",
            "measure.surface_angle.column=2.0",
            "measure.surface_angle.x_range=[0.0,0.03]",
        ],
    );
    let files = ["discharge.csv", "spacetime.csv"];
    let stops = [("relax", 256), ("run", 256), ("run", 768)];
    let s = check("hopper", &loaded, &files, 300, &stops, &|_, _| {});
    assert!(s["discharged_grains"].as_u64().unwrap() >= 20, "{s}");
    assert!(s["density_contrast"].as_f64().unwrap() > 0.0, "{s}");
    assert!(s["dynamic_angle_sd_deg"].as_f64().unwrap() > 0.0, "{s}");
}

/// The small pile of `data/small-repose.sets` (80 disks) settled at the
/// first look after 9 ms (step 300), its right wall removed then, the
/// grains that run off parked below the sink, then tilted at 1500 deg/s
/// once the pile is at rest again (from step 600) until the pile fails
/// (step 1950): stopped while settling (step 256), after the removal (512),
/// during the tilt (1024) and after the failure (2048).
#[test]
fn repose_events_resume_bit_for_bit() {
    let loaded = scenario_with(
        "repose-2d.toml",
        include_str!("../data/small-repose.sets"),
        &[
            "run.events.settle_min=0.009",
            "run.events.sink=-0.0005",
            "run.events.tilt_rate=1500.0",
            "run.events.fail_energy=1.0",
            "run.dt=3e-5",
            "run.duration=0.0768",
            "output.frames=true",
        ],
    );
    let files = ["surface.csv"];
    let stops = [("run", 256), ("run", 512), ("run", 1024), ("run", 2048)];
    // Gravity starts vertical, (0, -30) m/s².
    let stage = |k: usize, md: &Md<D2>| {
        let right = md.walls.iter().find(|w| w.name == "right").unwrap();
        let tilted = D2::get(md.settings.gravity, 0) != 0.0;
        let got = (right.remove_at.is_some(), tilted);
        let want = [(false, false), (true, false), (true, true), (true, true)][k];
        assert_eq!(got, want, "stop {k}: (wall removed, tilted)");
    };
    let s = check("repose", &loaded, &files, 512, &stops, &stage);
    assert!(s["lost_grains"].as_u64().unwrap() >= 2, "{s}");
    // Failed 60.7° into the tilt, at step 1950: the last stop is after it.
    let failed = s["tilt_at_failure_deg"].as_f64().unwrap();
    assert!(failed > 1.5e3 * 3e-5 * (1024.0 - 600.0), "{s}");
    assert!(failed < 1.5e3 * 3e-5 * (2048.0 - 600.0), "{s}");
}
