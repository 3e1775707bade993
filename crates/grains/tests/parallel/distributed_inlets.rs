//! Inlets, outlets and sensors of an MD run decomposed over thread ranks
//! against the serial run (`runner/distributed_md.rs`, `md/decomp/edit.rs`):
//! rank 0 inserts, removes and counts on its gathered mirror with the
//! serial code, and every rank inserts the new grains in its box and drops
//! its removed ones.

use super::distributed_md::{loaded, scratch, thermo};
use crate::common;
use grains::comm::{Comm, ThreadComm};
use grains::runner::checkpointing::{self, Every};
use grains::runner::{distributed, run, RunOptions, Silent};
use grains::scenario::Loaded;
use serde_json::Value;
use std::path::Path;

/// Disks poured by an inlet (4000 grains/s until 12 ms, diameters 0.8–1.2
/// mm, under 30 m/s²) onto a floor removed at 6 ms, above an outlet 1 mm
/// below it that takes out what falls through, and a sensor on the floor's
/// plane; periodic across, 8000 steps of 2 µs (the fill of
/// `grains-cli/tests/cli/restart.rs`, faster).
const FILL: &str = include_str!("../data/fill-2d.toml");

/// One frame of dump.lammpstrj: its step and its rows (id, type, radius,
/// x, y, z, vx, vy, vz) in id order.
type Frame = (u64, Vec<Vec<f64>>);

fn dump(dir: &Path) -> Vec<Frame> {
    let text = std::fs::read_to_string(dir.join("dump.lammpstrj")).unwrap();
    let mut frames = Vec::new();
    let mut lines = text.lines().peekable();
    while let Some(l) = lines.next() {
        if l == "ITEM: TIMESTEP" {
            let step = lines.next().unwrap().trim().parse().unwrap();
            frames.push((step, Vec::new()));
        } else if l.starts_with("ITEM: ATOMS") {
            let rows = &mut frames.last_mut().unwrap().1;
            while let Some(r) = lines.peek().filter(|r| !r.starts_with("ITEM")) {
                rows.push(r.split_whitespace().map(|x| x.parse().unwrap()).collect());
                lines.next();
            }
            rows.sort_by(|a: &Vec<f64>, b| a[0].total_cmp(&b[0]));
        }
    }
    frames
}

/// The largest difference of position and velocity components between
/// two dumps, which must hold the same grains (ids, kinds, radii exactly)
/// at the same steps.
fn same_grains(a: &[Frame], b: &[Frame]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let (mut dx, mut dv) = (0.0f64, 0.0f64);
    for ((s, ra), (s0, rb)) in a.iter().zip(b) {
        assert_eq!(s, s0);
        assert_eq!(ra.len(), rb.len(), "step {s}: grain count");
        for (x, y) in ra.iter().zip(rb) {
            assert_eq!(x[..3], y[..3], "step {s}: id, kind, radius");
            (3..6).for_each(|k| dx = dx.max((x[k] - y[k]).abs()));
            (6..9).for_each(|k| dv = dv.max((x[k] - y[k]).abs()));
        }
    }
    (dx, dv)
}

fn fill() -> Loaded {
    loaded(FILL)
}

fn summary_keys(s: &Value, s0: &Value) {
    for key in ["inlets", "mass_balance", "sensors", "outlets", "particles"] {
        assert_eq!(s[key], s0[key], "{key}");
    }
}

// The fill serially and on 2 and 3 thread ranks. Rank 0 inserts with the
// serial code on the gathered mirror, so the same grains (ids, kinds,
// radii) arrive at the same steps at the same spots, and the outlet takes
// out the same grains at the same steps: the inlets' report, the mass
// balance (exact), outflow.csv, sensors.csv and the sensor's counts are
// the serial run's. Positions and velocities of every grain in every frame
// of the dump agree to rounding of a different summation order: within
// 1e-12 m and 1e-10 m/s (grains of 1 mm at up to 0.5 m/s; measured: the
// same bits on 2 and 3 ranks, thermo's kinetic energy within 3e-16).
#[test]
fn inlets_outlets_and_sensors_on_ranks_give_the_serial_grains() {
    let l = fill();
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        ..Default::default()
    };
    let d0 = scratch("fill-serial");
    let s0 = run(&l, &opts(&d0), &mut Silent).unwrap();
    let balance = &s0["mass_balance"];
    assert_eq!(balance["exact"], true, "{balance}");
    assert!(
        balance["inserted_grains"].as_u64().unwrap() >= 40,
        "{balance}"
    );
    assert!(
        balance["removed_grains"].as_u64().unwrap() >= 10,
        "{balance}"
    );
    let frames0 = dump(&d0);
    let read = |d: &Path, f: &str| std::fs::read(d.join(f)).unwrap();
    for ranks in [2, 3] {
        let dir = scratch(&format!("fill-{ranks}"));
        let s = common::runs::run_on_threads(&l, &opts(&dir), ranks);
        summary_keys(&s, &s0);
        assert!(s["migrations"].as_u64().unwrap() > 0, "{s}");
        for f in ["outflow.csv", "sensors.csv"] {
            assert!(read(&dir, f) == read(&d0, f), "{ranks} ranks: {f}");
        }
        let (dx, dv) = same_grains(&dump(&dir), &frames0);
        eprintln!("{ranks} ranks: positions within {dx:e} m, velocities {dv:e} m/s");
        assert!(
            dx <= 1e-12 && dv <= 1e-10,
            "{ranks} ranks: {dx:e} m, {dv:e} m/s"
        );
        // Thermo rows as in distributed_flow.rs: kinetic energy within 1e-9.
        let ((h, rows), (h0, rows0)) = (thermo(&dir), thermo(&d0));
        assert_eq!((&h, rows.len()), (&h0, rows0.len()));
        let ke = h.iter().position(|c| c == "kinetic_energy").unwrap();
        for (r, r0) in rows.iter().zip(&rows0) {
            assert!((r[ke] - r0[ke]).abs() <= 1e-9 * r0[ke], "t = {}", r0[1]);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&d0);
}

// The fill on 2 thread ranks with a checkpoint every 4000 steps, resumed
// on 2 ranks from step 4000 (mid-insertion, after the floor's removal):
// the inlets go on where they were and the summary and the frames after
// the resume are the straight run's, as above.
#[test]
fn a_fill_on_ranks_resumes_mid_insertion() {
    let l = fill();
    let straight = scratch("fill-straight");
    let s0 = run(
        &l,
        &RunOptions {
            out_dir: straight.clone(),
            ..Default::default()
        },
        &mut Silent,
    )
    .unwrap();
    let dir = scratch("fill-resume");
    let opts = RunOptions {
        out_dir: dir.clone(),
        checkpoint_every: Some(Every::Steps(4000)),
        ..Default::default()
    };
    common::runs::run_on_threads(&l, &opts, 2);
    let mid = dir.join(grains::checkpoint::file_name(4000));
    let out = ThreadComm::run(2, |c| {
        let (found, _) = checkpointing::find(&mid).unwrap();
        distributed::resume(
            found,
            None,
            RunOptions::default(),
            &mut Silent,
            c as &dyn Comm,
        )
        .unwrap()
    });
    summary_keys(&out[0], &s0);
    let (dx, dv) = same_grains(&dump(&dir), &dump(&straight));
    assert!(dx <= 1e-12 && dv <= 1e-10, "{dx:e} m, {dv:e} m/s");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&straight);
}
