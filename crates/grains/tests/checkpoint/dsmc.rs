//! Checkpoint and resume of DSMC runs (e = 0.9, 2D and 3D): a straight run
//! of R relaxation + 2N measured steps against the same run resumed from
//! its checkpoint at step R + N. The resumed run's own checkpoint at the end
//! (the whole engine state: particles in store order, cell sort, v_max and
//! remainders, tallies; the validity and profile accumulators) must equal
//! the straight run's byte for byte, and so must thermo.csv, frames.pvd,
//! every frame and profiles.csv. A checkpoint written on a stop request
//! (the SIGINT/SIGTERM path) resumes to the same end.

use grains::runner::checkpointing::{find, resume, Every};
use grains::runner::{run, RunOptions, Silent};
use grains::scenario::load_str;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

const DT: f64 = 2.0e-3;
const RELAX: u64 = N;
const N: u64 = 150;

fn scenario(dim: &str) -> String {
    let (lo, hi, per, count) = if dim == "2d" {
        ("[0.0, 0.0]", "[0.2, 0.2]", "[true, true]", 1500)
    } else {
        (
            "[0.0, 0.0, 0.0]",
            "[0.05, 0.05, 0.05]",
            "[true, true, true]",
            2000,
        )
    };
    format!(
        r#"name = "ck-dsmc-{dim}"
dimension = "{dim}"
method = "dsmc"
seed = 11

[domain]
lo = {lo}
hi = {hi}
periodic = {per}

[particles]
placement = "random"
count = {count}
d0 = 1.0e-3
density = 2500.0

[dsmc]
restitution = 0.9
thermal_speed = 1.0
particles_per_cell = 8.0
dense = "enskog"
regions = 2
profile_bins = 4

[run]
dt = {DT:e}
relax = {relax:e}
duration = {duration:e}

[output]
every = {every:e}
frames = true
picture = false
"#,
        relax = RELAX as f64 * DT,
        duration = (2 * N) as f64 * DT,
        every = 20.0 * DT,
    )
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-ck-dsmc-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn ck(dir: &Path, step: u64) -> PathBuf {
    dir.join(grains::checkpoint::file_name(step))
}

/// The files that must match between two run directories.
fn same_outputs(a: &Path, b: &Path) {
    for f in ["thermo.csv", "frames.pvd", "profiles.csv"] {
        assert!(read(&a.join(f)) == read(&b.join(f)), "{f} differs");
    }
    let mut names: Vec<_> = std::fs::read_dir(a.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(names.len() > 10);
    for n in names {
        let (x, y) = (a.join("frames").join(&n), b.join("frames").join(&n));
        assert!(read(&x) == read(&y), "{} differs", x.display());
    }
}

fn check(dim: &str) {
    let text = scenario(dim);
    let loaded = load_str(&text, "test", PathBuf::from("."), &[]).unwrap();
    let end = RELAX + 2 * N;
    let mid = RELAX + N;

    // Straight run, checkpoints every N steps (R = N; the two newest, at
    // R + N and at the end, are kept).
    let every = N;
    assert_eq!(end % every, 0);
    let straight = scratch(&format!("{dim}-straight"));
    let opts = RunOptions {
        out_dir: straight.clone(),
        checkpoint_every: Some(Every::Steps(every)),
        ..RunOptions::default()
    };
    let s1 = run(&loaded, &opts, &mut Silent).unwrap();
    assert_eq!(s1["steps"], end);
    let final_state = read(&ck(&straight, end));

    // A run without checkpoints writes the same files.
    let plain = scratch(&format!("{dim}-plain"));
    let opts = RunOptions {
        out_dir: plain.clone(),
        ..RunOptions::default()
    };
    let s0 = run(&loaded, &opts, &mut Silent).unwrap();
    same_outputs(&straight, &plain);
    assert_eq!(s0["kinetic_energy"], s1["kinetic_energy"]);

    // Resume from the checkpoint at R + N: it cuts the outputs back and
    // runs N more steps.
    let (found, skipped) = find(&ck(&straight, mid)).unwrap();
    assert!(skipped.is_empty());
    assert_eq!(found.step, mid);
    std::fs::remove_file(ck(&straight, end)).unwrap();
    let s2 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
    assert!(
        read(&ck(&straight, end)) == final_state,
        "{dim}: the resumed engine state differs from the straight run's"
    );
    same_outputs(&straight, &plain);
    for k in [
        "kinetic_energy",
        "granular_temperature",
        "collisions",
        "time",
        "validity",
    ] {
        assert_eq!(s2[k], s0[k], "{dim}: summary {k}");
    }

    // Stop request (what SIGINT/SIGTERM set) during relaxation and during
    // the measurement: a checkpoint at the stop, then resume to the end.
    for stop_at in [0, 256] {
        let dir = scratch(&format!("{dim}-stop{stop_at}"));
        // 0: raised before the run (stop after step 1, in relaxation);
        // 256: at the progress report of measured step 256.
        let flag = Arc::new(AtomicBool::new(stop_at == 0));
        let mut p = StopAt {
            flag: flag.clone(),
            at: stop_at,
            run: false,
        };
        let opts = RunOptions {
            out_dir: dir.clone(),
            stop: Some(flag.clone()),
            ..RunOptions::default()
        };
        let s = run(&loaded, &opts, &mut p).unwrap();
        assert_eq!(s["interrupted"], true, "{s}");
        let (found, _) = find(&dir).unwrap();
        let s3 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
        same_outputs(&dir, &plain);
        for k in ["kinetic_energy", "collisions", "validity"] {
            assert_eq!(s3[k], s0[k], "{dim}: stop at {stop_at}: summary {k}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&straight);
    let _ = std::fs::remove_dir_all(&plain);
}

/// Raises the stop flag when the measurement's progress reaches a step (the
/// runner checks the flag after every step, as after a signal).
struct StopAt {
    flag: Arc<AtomicBool>,
    at: u64,
    run: bool,
}

impl grains::runner::Progress for StopAt {
    fn phase(&mut self, name: &str, _: u64) {
        self.run = name == "run";
    }
    fn advance(&mut self, done: u64, _: f64) {
        if self.run && self.at > 0 && done >= self.at {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
    fn finish(&mut self) {}
}

#[test]
fn dsmc_resume_is_exact_2d() {
    check("2d");
}

#[test]
fn dsmc_resume_is_exact_3d() {
    check("3d");
}

#[test]
fn md_checkpoint_of_dsmc_kind_is_refused() {
    let text = scenario("2d");
    let loaded = load_str(&text, "test", PathBuf::from("."), &[]).unwrap();
    let dir = scratch("kind");
    let opts = RunOptions {
        out_dir: dir.clone(),
        steps: Some(5),
        checkpoint_every: Some(Every::Steps(5)),
        ..RunOptions::default()
    };
    run(&loaded, &opts, &mut Silent).unwrap();
    // The engine state of a DSMC checkpoint carries its kind tag.
    let payload = grains::checkpoint::read(&ck(&dir, 5)).unwrap();
    let tag = grains::dsmc::contract::TAG;
    assert!(payload.windows(tag.len()).any(|w| w == tag));
    // Restoring that state into an MD engine is refused by name, in both
    // dimensions, before any byte of it is read as MD state.
    let (found, _) = find(&ck(&dir, 5)).unwrap();
    for e in [
        found.restore_md::<grains::D2>().err(),
        found.restore_md::<grains::D3>().err(),
    ] {
        let e = e.expect("a DSMC checkpoint restored as MD").to_string();
        assert!(e.contains("holds a DSMC engine state"), "{e}");
        assert!(e.contains(&ck(&dir, 5).display().to_string()), "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
