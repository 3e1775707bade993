//! The flow runs of a scenario decomposed over thread ranks against the
//! serial run: `[hopper]` recycling, `run.events` (wall removal, tilt,
//! sink) and their checkpoints, and the per-step measurements (phases,
//! trajectories), to the rounding of a different summation order (see
//! `distributed_md.rs`).

use super::distributed_md::{box_2d, loaded, scratch, thermo, vtp_array};
use crate::common;
use grains::comm::{Comm, ThreadComm};
use grains::runner::checkpointing::{self, Every};
use grains::runner::{distributed, run, RunOptions, Silent};
use grains::scenario::{build_md, load_str, Loaded};
use grains::D2;
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// `scenarios/<file>` with the `--set` overrides of `sets` and `extra`.
fn scenario_with(file: &str, sets: &[&str], extra: &[&str]) -> Loaded {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    let text = std::fs::read_to_string(dir.join(file)).unwrap();
    let sets: Vec<String> = sets.iter().chain(extra).map(|s| s.to_string()).collect();
    load_str(&text, file, PathBuf::from("."), &sets).unwrap()
}

/// The 2D silo of `scenarios/hopper-2d.toml` cut down to 150 grains that
/// start on the floor over a wide outlet, under 30 m/s², with the sink
/// 1.2 d0 below the floor and the refill band just above the pile, so that
/// grains leave and are recycled within 1000 steps (`data/small-hopper.sets`,
/// shared with the mpirun test); `extra` adds keys.
fn small_hopper(extra: &[&str]) -> Loaded {
    let sets = include_str!("../data/small-hopper.sets");
    scenario_with("hopper-2d.toml", &sets.lines().collect::<Vec<_>>(), extra)
}

/// The (time, cumulative mass) rows of discharge.csv.
fn discharge(dir: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(dir.join("discharge.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let (t, m) = l.split_once(',').unwrap();
            (t.parse().unwrap(), m.parse().unwrap())
        })
        .collect()
}

/// The ids in the pieces of the frame at each output step of `dir`.
fn piece_ids(dir: &Path) -> Vec<Vec<u64>> {
    let pvd = std::fs::read_to_string(dir.join("frames.pvd")).unwrap();
    common::vtk::pvd_files(&pvd)
        .into_iter()
        .map(|rel| {
            let pvtp = std::fs::read_to_string(dir.join(rel)).unwrap();
            let mut ids: Vec<u64> = common::vtk::pvtp_sources(&pvtp)
                .into_iter()
                .flat_map(|name| {
                    let piece = std::fs::read_to_string(dir.join("frames").join(name)).unwrap();
                    vtp_array(&piece, "id").into_iter().map(|x| x as u64)
                })
                .collect();
            ids.sort_unstable();
            ids
        })
        .collect()
}

// Hopper recycling on 2 thread ranks against the serial run. Until the
// first grain is recycled only the summation order differs: kinetic energy
// within 1e-9 relative at every thermo row (as in the tests above). Rank 0
// recycles with the serial code and random stream, so a grain that leaves
// alone is put at the serial run's spot; when two leave in one step they
// may swap spots (the mirror is not re-sorted like the serial engine), so
// after the first exit the counts and exit times are compared, not the
// energies: the same grains leave at the same steps while the runs stay
// within rounding of each other, which 1000 steps (about 550 after the
// first exit, 20 contact times) leave them.
#[test]
fn hopper_recycling_on_two_ranks_matches_the_serial_run() {
    let steps = 1000;
    let l = small_hopper(&[
        "output.every=3e-5",
        "output.frames=true",
        "output.frames_layout=\"pieces\"",
    ]);
    let serial_dir = scratch("hopper-serial");
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        steps: Some(steps),
        ..Default::default()
    };
    let s0 = run(&l, &opts(&serial_dir), &mut Silent).unwrap();
    let dir = scratch("hopper-2");
    let s = &common::runs::run_on_threads(&l, &opts(&dir), 2);
    assert!(s["migrations"].as_u64().unwrap() > 0);
    let exits = s0["discharged_grains"].as_u64().unwrap();
    assert!(exits >= 10, "the test needs grains to leave: {exits}");
    assert_eq!(s["discharged_grains"], s0["discharged_grains"]);
    assert_eq!(s["particles"], s0["particles"]);
    let (d0, d) = (discharge(&serial_dir), discharge(&dir));
    assert_eq!(d.len(), d0.len());
    for (a, b) in d.iter().zip(&d0) {
        assert_eq!(a.0, b.0, "exit times");
        assert!(
            (a.1 - b.1).abs() <= 1e-12 * b.1,
            "cumulative mass {a:?} vs {b:?}"
        );
    }
    let first_exit = d0[0].0;
    let ((h0, rows0), (h, rows)) = (thermo(&serial_dir), thermo(&dir));
    assert_eq!(h, h0);
    assert_eq!(rows.len(), rows0.len());
    let (t, ke) = (1, h.iter().position(|c| c == "kinetic_energy").unwrap());
    let before: Vec<_> = rows
        .iter()
        .zip(&rows0)
        .filter(|r| r.1[t] < first_exit)
        .collect();
    assert!(
        before.len() > 300,
        "{} rows before the first exit",
        before.len()
    );
    for (r, r0) in before {
        let tol = 1e-9 * r0[ke];
        assert!(
            (r[ke] - r0[ke]).abs() <= tol,
            "t = {}: {} vs {}",
            r0[t],
            r[ke],
            r0[ke]
        );
    }
    // Every grain once at every step (a frame per step, a piece per rank).
    let (whole, _) = build_md::<D2>(&l).unwrap();
    let mut all = whole.particles.id.clone();
    all.sort_unstable();
    let frames = piece_ids(&dir);
    assert_eq!(frames.len() as u64, steps + 1);
    for (k, ids) in frames.iter().enumerate() {
        assert_eq!(ids, &all, "step {k}: grains lost or duplicated");
    }
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&serial_dir);
}

/// `scenarios/repose-2d.toml` cut down to 80 grains in a layer 8 d0 deep
/// under 30 m/s², settled at the first look after 3 ms (the energy bound is
/// loose: the test is the event's timing, not a settled pile;
/// `data/small-repose.sets`, shared with the mpirun test), the sink just
/// below the floor; `extra` adds keys.
fn small_repose(extra: &[&str]) -> Loaded {
    let mut sets: Vec<&str> = include_str!("../data/small-repose.sets").lines().collect();
    sets.push("run.events.sink=-0.0005");
    scenario_with("repose-2d.toml", &sets, extra)
}

/// `l` for `steps` steps serially and on 2 thread ranks: the summaries.
/// Every thermo row's kinetic energy within 1e-9 relative (wall removal,
/// tilt and parking act at the same steps on every rank, so only the
/// summation order differs; parked grains are frozen below the sink, out of
/// reach of the mobile ones, so which grain parks in which spot when two
/// go in one step changes no energy).
fn events_both(l: &Loaded, steps: u64, name: &str) -> (Value, Value) {
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        steps: Some(steps),
        ..Default::default()
    };
    let (d0, d2) = (scratch(&format!("{name}-1")), scratch(&format!("{name}-2")));
    let s0 = run(l, &opts(&d0), &mut Silent).unwrap();
    let s2 = common::runs::run_on_threads(l, &opts(&d2), 2);
    let ((h0, rows0), (h, rows)) = (thermo(&d0), thermo(&d2));
    assert_eq!(h, h0);
    assert_eq!(rows.len(), rows0.len());
    let ke = h.iter().position(|c| c == "kinetic_energy").unwrap();
    for (r, r0) in rows.iter().zip(&rows0) {
        let tol = 1e-9 * r0[ke];
        assert!(
            (r[ke] - r0[ke]).abs() <= tol,
            "{name}: t = {}: {} vs {}",
            r0[1],
            r[ke],
            r0[ke]
        );
    }
    let _ = std::fs::remove_dir_all(&d0);
    let _ = std::fs::remove_dir_all(&d2);
    (s0, s2)
}

#[test]
fn run_events_on_two_ranks_match_the_serial_run() {
    // Settle, remove the right wall: grains run off the floor's end and are
    // parked below the sink.
    let (s0, s) = events_both(&small_repose(&[]), 1500, "remove");
    assert_eq!(s0["settled"], 1);
    assert!(s0["lost_grains"].as_u64().unwrap() >= 2, "{s0}");
    for key in [
        "settled",
        "settle_time",
        "lost_grains",
        "repose_surface_points",
    ] {
        assert_eq!(s[key], s0[key], "{key}");
    }
    assert!(s["migrations"].as_u64().unwrap() > 0);
    // Settle, then tilt gravity at 1500 deg/s in the closed box (gravity
    // changes every step on every rank).
    let tilt = small_repose(&[
        "run.events.remove_wall=\"\"",
        "run.events.tilt_rate=1500.0",
        "run.events.fail_energy=5.0",
    ]);
    let (s0, s) = events_both(&tilt, 1000, "tilt");
    let key = "marginal_angle_lower_bound_deg";
    assert!(s0[key].as_f64().unwrap() > 20.0, "{s0}");
    for key in ["settled", "settle_time", key] {
        assert_eq!(s[key], s0[key], "{key}");
    }
}

/// A `run.events` pile on 2 thread ranks, checkpointed every 1024 steps
/// and resumed on 2 ranks from its checkpoint at step 1024, while tilting
/// (wall removed at step 300, tilt from step 600, failure near step 1950):
/// the flow state (stage, tilted gravity, removed wall) continues on every
/// rank. Equal settling time, lost grains and angles, and every thermo
/// row's kinetic energy within 1e-9 relative (the ranks rebuild the list at
/// the checkpoint, so only the summation order differs).
#[test]
fn run_events_resume_on_two_ranks() {
    let l = small_repose(&[
        "run.events.settle_min=0.009",
        "run.events.tilt_rate=1500.0",
        "run.events.fail_energy=1.0",
        "run.dt=3e-5",
        "run.duration=0.0768",
    ]);
    let dir = scratch("events-resume");
    let opts = RunOptions {
        out_dir: dir.clone(),
        checkpoint_every: Some(Every::Steps(1024)),
        ..Default::default()
    };
    let s0 = common::runs::run_on_threads(&l, &opts, 2);
    assert!(s0["tilt_at_failure_deg"].as_f64().unwrap() > 20.0, "{s0}");
    let (h, rows0) = thermo(&dir);
    let mid = dir.join(grains::checkpoint::file_name(1024));
    let out = ThreadComm::run(2, |c| {
        let (found, _) = checkpointing::find(&mid).unwrap();
        distributed::resume(found, None, RunOptions::default(), &mut Silent, c).unwrap()
    });
    let s = &out[0];
    for key in [
        "settled",
        "settle_time",
        "lost_grains",
        "marginal_angle_deg",
        "tilt_at_failure_deg",
        "repose_before_tilt_deg",
    ] {
        assert_eq!(s[key], s0[key], "{key}");
    }
    let (_, rows) = thermo(&dir);
    assert_eq!(rows.len(), rows0.len());
    let ke = h.iter().position(|c| c == "kinetic_energy").unwrap();
    for (r, r0) in rows.iter().zip(&rows0) {
        assert!((r[ke] - r0[ke]).abs() <= 1e-9 * r0[ke], "t = {}", r0[1]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The numeric rows of a measurement CSV (comment and header lines
/// skipped), keyed by their first `key` columns.
fn csv_rows(path: &Path, key: usize) -> HashMap<Vec<u64>, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let rows = text.lines().filter(|l| !l.starts_with('#')).skip(1);
    rows.map(|l| {
        let cols: Vec<&str> = l.split(',').collect();
        let k = cols[..key].iter().map(|c| c.parse().unwrap()).collect();
        let v = cols[key..].iter().map(|c| c.parse().unwrap()).collect();
        (k, v)
    })
    .collect()
}

/// Every keyed row of `file` in `a` is in `b`, its numbers within `tol`.
fn same_rows(a: &Path, b: &Path, file: &str, key: usize, tol: f64) -> usize {
    let (ra, rb) = (csv_rows(&a.join(file), key), csv_rows(&b.join(file), key));
    assert_eq!(ra.len(), rb.len(), "{file}");
    for (k, x) in &ra {
        let y = &rb[k];
        let worst = x
            .iter()
            .zip(y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(worst <= tol, "{file} {k:?}: {x:?} vs {y:?}");
    }
    ra.len()
}

// Phase snapshots and trajectories on 2 and 3 thread ranks against the
// serial run, on the closed 2D box with its floor vibrating at 50 Hz
// (200 steps a cycle): snapshots at phases π/2, π, 3π/2 and 0 and the
// displacement from phase 0 over 5 ms, trajectories every 5 steps over the
// last half cycle. Rows by grain id (and step). A snapshot row holds a
// position and a velocity, checked together at the velocity bound, 1e-9 of
// the grains' speed scale (30 m/s) = 3e-8; displacement and trajectory rows
// within 1e-9. These are the rounding bounds of the tests above, as only
// the summation order differs.
#[test]
fn phases_and_trajectories_on_ranks_match_the_serial_run() {
    let text = format!(
        "{}\n[measure]\nphases = {{ phases = [1.5707963267948966, 3.141592653589793, \
         4.71238898038469, 0.0], displacement_after = 0.005 }}\n\
         trajectories = {{ every = 5, cycles = 0.5 }}\n\
         [output]\nevery = 0.005\nframes = false\npicture = false\n",
        box_2d()
    );
    let l = loaded(&text);
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        steps: Some(300),
        ..Default::default()
    };
    let serial = scratch("measure-1");
    run(&l, &opts(&serial), &mut Silent).unwrap();
    for ranks in [2, 3] {
        let dir = scratch(&format!("measure-{ranks}"));
        common::runs::run_on_threads(&l, &opts(&dir), ranks);
        for k in 0..4 {
            let n = same_rows(&dir, &serial, &format!("phase_{k}.csv"), 1, 3e-8);
            assert_eq!(n, 83, "phase {k}: every grain");
        }
        let n = same_rows(&dir, &serial, "phase_displacement.csv", 1, 1e-9);
        assert_eq!(n, 83);
        // 80 mobile grains at 21 steps (the window's ends included).
        let n = same_rows(&dir, &serial, "trajectories.csv", 2, 1e-9);
        assert_eq!(n, 80 * 21);
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&serial);
}

#[test]
fn per_step_measurements_without_a_drive_are_refused_on_every_rank() {
    let l = small_hopper(&["measure.trajectories={every=1,cycles=1.0}"]);
    let opts = RunOptions {
        out_dir: scratch("refused"),
        ..Default::default()
    };
    let out = ThreadComm::run(2, |c| {
        distributed::run(&l, &opts, &mut Silent, c as &dyn Comm)
            .unwrap_err()
            .to_string()
    });
    for e in &out {
        assert!(e.contains("measure.trajectories needs a vibrating"), "{e}");
    }
}
