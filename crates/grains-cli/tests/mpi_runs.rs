//! `mpirun -np N grains run` (built with `--features mpi`, Open MPI's
//! `mpirun` on the PATH) against the plain single-process run: for DSMC
//! the files must be the same byte for byte on 1, 2 and 4 ranks (the
//! decomposition reproduces the serial engine exactly, see
//! `grains::dsmc::decomp`), in 2D with a vibrating plate and a lid under
//! gravity and in 3D in a periodic box. For MD (`grains::md::decomp`) the
//! thermo rows must agree to rounding on 1, 2 and 4 ranks, in 2D with
//! walls and in 3D periodic; a silo recycles the same grains at the same
//! times on 2 ranks as on one, and a pile settled and tilted (run.events)
//! agrees to rounding on 1, 2 and 4 ranks, and so do trajectories on 2
//! ranks; trajectories without a vibrating wall are refused once, with
//! exit code 2. MD checkpoints written under mpirun resume on one process
//! and the reverse, continuing the straight run to rounding. DSMC frames in
//! pieces on 2 ranks hold the serial run's particles, each once. A fill
//! with an inlet, an outlet and a sensor on 2 and 3 ranks inserts, removes
//! and counts the serial run's grains, and its checkpoint written on 2
//! ranks resumes on one process.
#![cfg(feature = "mpi")]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GRAINS: &str = env!("CARGO_BIN_EXE_grains");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-mpi-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `grains args...` on `ranks` MPI ranks (0: without mpirun).
fn grains(ranks: usize, args: &[&str]) -> Output {
    let mut c = if ranks == 0 {
        Command::new(GRAINS)
    } else {
        let mut c = Command::new("mpirun");
        // CI runs as root on a two-core machine.
        c.args(["--oversubscribe", "--allow-run-as-root", "-np"])
            .arg(ranks.to_string())
            .arg(GRAINS);
        c
    };
    c.args(args)
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .output()
        .expect("mpirun (Open MPI) must be installed")
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn same_files(a: &Path, b: &Path) {
    let mut names = vec![PathBuf::from("thermo.csv")];
    if a.join("profiles.csv").exists() {
        names.push("profiles.csv".into());
    }
    if a.join("frames").exists() {
        names.push("frames.pvd".into());
        for e in std::fs::read_dir(a.join("frames")).unwrap() {
            names.push(Path::new("frames").join(e.unwrap().file_name()));
        }
    }
    assert!(names.len() > 1, "nothing to compare in {}", a.display());
    for n in names {
        assert!(
            read(&a.join(&n)) == read(&b.join(&n)),
            "{} differs between {} and {}",
            n.display(),
            a.display(),
            b.display()
        );
    }
}

fn check(scenario: &str, sets: &[&str], steps: &str) {
    let path = repo().join("scenarios").join(scenario);
    let run = |ranks: usize| run_ok(ranks, &path, steps, &format!("{scenario}-{ranks}"), sets);
    let serial = run(0);
    for ranks in [1, 2, 4] {
        let dir = run(ranks);
        same_files(&serial, &dir);
        let summary: serde_json::Value =
            serde_json::from_slice(&read(&dir.join("summary.json"))).unwrap();
        if ranks > 1 {
            assert_eq!(summary["ranks"], ranks);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&serial);
}

#[test]
fn dsmc_vibrated_2d_is_the_same_on_1_2_4_ranks() {
    check(
        "gas-vibrated-2d.toml",
        &["output.frames=true", "output.every=0.002"],
        "300",
    );
}

#[test]
fn dsmc_periodic_3d_is_the_same_on_1_2_4_ranks() {
    check(
        "gas-cooling-3d.toml",
        &[
            "particles.count=3000",
            "domain.hi=[0.08,0.08,0.08]",
            "dsmc.cell_size=0.01",
            "dsmc.profile_bins=4",
        ],
        "100",
    );
}

#[test]
fn more_ranks_than_cell_layers_is_refused_once() {
    let path = repo().join("scenarios/gas-vibrated-2d.toml");
    let dir = scratch("layers");
    let out = grains(
        4,
        &[
            "run",
            path.to_str().unwrap(),
            "--set",
            "dsmc.cell_size=0.1",
            "--steps",
            "10",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("4 ranks but only 3 layers"), "{err}");
    assert_eq!(err.matches("grains: error").count(), 1, "{err}");
}

/// thermo.csv as a header and rows of numbers.
fn thermo(dir: &Path) -> (String, Vec<Vec<f64>>) {
    let text = String::from_utf8(read(&dir.join("thermo.csv"))).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

/// The thermo rows of two MD runs agree: step and time exactly (parsed),
/// the rest within 1e-9 relative but the contact count (see [`check_md`]).
/// Rows of `dir` at steps that `reference` lacks are left out (a run that
/// ends at a checkpoint writes a row there).
fn same_thermo(dir: &Path, reference: &Path, what: &str) {
    let (head, rows0) = thermo(reference);
    assert!(rows0.len() > 3);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
    let (h, mut rows) = thermo(dir);
    rows.retain(|r| rows0.iter().any(|r0| r0[0] == r[0]));
    assert_eq!(h, head);
    assert_eq!(rows.len(), rows0.len(), "{what}");
    for (r, r0) in rows.iter().zip(&rows0) {
        for (k, col) in head.split(',').enumerate() {
            if col != "contacts" {
                assert!(close(r[k], r0[k]), "{what}: {col} {} vs {}", r[k], r0[k]);
            }
        }
    }
}

/// An MD run on 1, 2 and 4 ranks against the plain run: the same rows of
/// thermo.csv (step, time exactly; energies, temperature and the largest
/// overlap within 1e-9 relative, since a rank sums a grain's contact
/// forces in another order; the contact count is not compared: a contact
/// across a slab boundary counts on both ranks) and the same frames.
fn check_md(scenario: &Path, sets: &[&str], steps: &str, ranks: &[usize]) {
    let name = scenario.file_stem().unwrap().to_string_lossy().to_string();
    let run = |ranks: usize| run_ok(ranks, scenario, steps, &format!("{name}-{ranks}"), sets);
    let serial = run(0);
    for &ranks in ranks {
        let dir = run(ranks);
        same_thermo(&dir, &serial, &format!("{ranks} ranks"));
        let summary: serde_json::Value =
            serde_json::from_slice(&read(&dir.join("summary.json"))).unwrap();
        if ranks > 1 {
            assert_eq!(summary["ranks"], ranks);
            assert!(summary["migrations"].as_u64().unwrap() > 0, "{summary}");
            let grid = summary["grid"].as_array().unwrap();
            let product: u64 = grid.iter().map(|p| p.as_u64().unwrap()).product();
            assert_eq!(product, ranks as u64, "{summary}");
            assert!(summary["imbalance_final"].as_f64().is_some(), "{summary}");
        }
        if serial.join("frames").exists() {
            let count = |d: &Path| std::fs::read_dir(d.join("frames")).unwrap().count();
            assert_eq!(count(&dir), count(&serial));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&serial);
}

#[test]
fn md_walls_2d_agrees_on_1_2_4_ranks() {
    // Seed 002's convection cell: side walls and a vibrating plate, the
    // slab axis (y, the tall one) closed by the plate; Gear 5. Random
    // initial velocities make grains cross the slab boundaries.
    check_md(
        &repo().join("scenarios/seed-convection-walls.toml"),
        &[
            "output.every=0.001",
            "output.picture=false",
            "particles.random_velocity=0.2",
        ],
        "1000",
        &[1, 2, 4],
    );
}

#[test]
fn md_periodic_3d_agrees_on_1_2_4_ranks() {
    // A fast gas of spheres in a periodic box; Velocity Verlet.
    let dir = scratch("md-gas-3d-file");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("md-gas-3d.toml");
    std::fs::write(
        &file,
        r#"name = "md-gas-3d"
dimension = "3d"
seed = 9
[domain]
lo = [0.0, 0.0, 0.0]
hi = [20.0, 6.0, 6.0]
periodic = [true, true, true]
[particles]
placement = "random"
count = 200
d0 = 1.0
width = 0.2
density = 1.9098593
random_velocity = 40.0
[contact]
preset = "lammps-hooke-history"
[run]
integrator = "verlet"
dt = 1.0e-4
duration = 0.02
skin = 0.1
[output]
every = 0.002
frames = true
picture = false
"#,
    )
    .unwrap();
    check_md(&file, &[], "200", &[1, 2, 4]);
    // A 2 × 2 grid (y and z cut: ghosts across edges and periodic corners).
    let sets = ["domain.hi=[20.0, 12.0, 12.0]", "parallel.grid=[1, 2, 2]"];
    check_md(&file, &sets, "200", &[4]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `grains run <scenario> --steps <steps> --quiet --out <dir>` with `--set`
/// for each of `sets` on `ranks`.
fn run_set(ranks: usize, scenario: &Path, steps: &str, dir: &Path, sets: &[&str]) -> Output {
    let mut args = vec![
        "run",
        scenario.to_str().unwrap(),
        "--steps",
        steps,
        "--quiet",
    ];
    args.extend(["--out", dir.to_str().unwrap()]);
    for s in sets {
        args.extend(["--set", s]);
    }
    grains(ranks, &args)
}

/// [`run_set`] into the scratch directory `name`, which must succeed: that
/// directory.
fn run_ok(ranks: usize, scenario: &Path, steps: &str, name: &str, sets: &[&str]) -> PathBuf {
    let dir = scratch(name);
    let out = run_set(ranks, scenario, steps, &dir, sets);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{ranks} ranks: {err}");
    dir
}

/// The small silo of `grains/tests/parallel/distributed_md.rs` (150 grains over a
/// wide outlet, recycled just below the floor) for 1000 steps on `ranks`.
fn hopper(ranks: usize, extra: &[&str]) -> (PathBuf, Output) {
    let dir = scratch(&format!("hopper-{ranks}"));
    let sets = common::small_hopper_sets(extra);
    let path = repo().join("scenarios/hopper-2d.toml");
    let out = run_set(ranks, &path, "1000", &dir, &sets);
    (dir, out)
}

#[test]
fn md_hopper_recycles_the_same_grains_on_2_ranks() {
    // Rank 0 recycles with the serial code and random stream: the same
    // number of grains leave at the same times (see the thread-rank test
    // for the energies before the first exit).
    let runs: Vec<(PathBuf, serde_json::Value, String)> = [0, 2]
        .into_iter()
        .map(|ranks| {
            let (dir, out) = hopper(ranks, &[]);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let summary = serde_json::from_slice(&read(&dir.join("summary.json"))).unwrap();
            let csv = String::from_utf8(read(&dir.join("discharge.csv"))).unwrap();
            (dir, summary, csv)
        })
        .collect();
    let ((d0, s0, c0), (d2, s2, c2)) = (&runs[0], &runs[1]);
    assert!(s0["discharged_grains"].as_u64().unwrap() >= 10, "{s0}");
    assert_eq!(s2["discharged_grains"], s0["discharged_grains"]);
    assert_eq!(s2["ranks"], 2);
    let times = |c: &str| -> Vec<String> {
        c.lines()
            .map(|l| l.split(',').next().unwrap().to_string())
            .collect()
    };
    assert_eq!(times(c2), times(c0));
    let _ = std::fs::remove_dir_all(d0);
    let _ = std::fs::remove_dir_all(d2);
}

#[test]
fn md_run_events_tilt_agrees_on_1_2_4_ranks() {
    // Settle 80 disks in a closed box, then tilt gravity every step: the
    // same gravity on every rank, the settle look from the whole state.
    let sets = common::small_repose_sets(&[
        "run.events.remove_wall=\"\"",
        "run.events.tilt_rate=1500.0",
        "run.events.fail_energy=5.0",
    ]);
    check_md(
        &repo().join("scenarios/repose-2d.toml"),
        &sets,
        "1000",
        &[1, 2, 4],
    );
}

#[test]
fn md_trajectories_agree_on_2_ranks() {
    // Seed 002's convection cell, trajectories every 5 steps over the run's
    // last tenth of a cycle: rows by (id, step), positions within 1e-10 m,
    // 1e-7 of a 1 mm grain (rounding, a few hundred steps of it).
    let path = repo().join("scenarios/seed-convection-walls.toml");
    let rows = |ranks: usize| {
        let sets = [
            "output.picture=false",
            "particles.random_velocity=0.2",
            "measure.trajectories={every=5,cycles=0.1}",
        ];
        let dir = run_ok(ranks, &path, "600", &format!("traj-{ranks}"), &sets);
        let text = String::from_utf8(read(&dir.join("trajectories.csv"))).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        let mut rows: Vec<(u64, u64, Vec<f64>)> = text
            .lines()
            .skip(2)
            .map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                let xyz = c[3..].iter().map(|x| x.parse().unwrap()).collect();
                (c[0].parse().unwrap(), c[1].parse().unwrap(), xyz)
            })
            .collect();
        rows.sort_by_key(|r| (r.0, r.1));
        rows
    };
    let (r0, r2) = (rows(0), rows(2));
    assert!(r0.len() > 100, "{} rows", r0.len());
    assert_eq!(r2.len(), r0.len());
    for (a, b) in r2.iter().zip(&r0) {
        assert_eq!((a.0, a.1), (b.0, b.1));
        for (x, y) in a.2.iter().zip(&b.2) {
            assert!(
                (x - y).abs() <= 1e-10,
                "grain {} step {}: {x} vs {y}",
                a.0,
                a.1
            );
        }
    }
}

#[test]
fn md_trajectories_without_a_drive_are_refused_once() {
    let (_, out) = hopper(2, &["measure.trajectories={every=1,cycles=1.0}"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("measure.trajectories needs a vibrating"),
        "{err}"
    );
    assert_eq!(err.matches("grains: error").count(), 1, "{err}");
}

#[test]
fn md_checkpoints_cross_between_mpirun_and_one_process() {
    // Seed 002's walled cell (Gear 5, wall springs): 1000 steps straight
    // on one process, against 500 steps with a checkpoint on 2 ranks
    // resumed on one process, and 500 on one process resumed on 2 ranks.
    let path = repo().join("scenarios/seed-convection-walls.toml");
    let path = path.to_str().unwrap();
    let sets = [
        "output.every=0.001",
        "output.picture=false",
        "particles.random_velocity=0.2",
    ];
    let run = |ranks: usize, dir: &Path, extra: &[&str]| {
        let mut args = vec!["run", path, "--quiet", "--out", dir.to_str().unwrap()];
        args.extend(extra);
        for s in &sets {
            args.extend(["--set", s]);
        }
        let out = grains(ranks, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{ranks} ranks: {err}");
    };
    let straight = scratch("ck-straight");
    run(0, &straight, &["--steps", "1000"]);
    for (before, after) in [(2, 0), (0, 2)] {
        let dir = scratch(&format!("ck-{before}-{after}"));
        run(
            before,
            &dir,
            &["--steps", "500", "--checkpoint-every", "500steps"],
        );
        assert!(dir.join("checkpoint-000000000500.grck").exists());
        let args = ["resume", dir.to_str().unwrap(), "--steps", "500", "--quiet"];
        let out = grains(after, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "resume on {after} ranks: {err}");
        same_thermo(&dir, &straight, &format!("{before} ranks, then {after}"));
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&straight);
}

#[test]
fn md_bench_under_mpirun_reports_the_imbalance() {
    let out = grains(
        2,
        &[
            "bench",
            "bed3d",
            "--particles",
            "2000",
            "--steps",
            "20",
            "--json",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.starts_with('{')).unwrap();
    let v: serde_json::Value = serde_json::from_str(line).unwrap();
    assert_eq!(v["ranks"], 2);
    for key in ["imbalance_initial", "imbalance_max", "imbalance_final"] {
        let x = v[key].as_f64().unwrap_or(-1.0);
        assert!((0.0..1.0).contains(&x), "{key}: {v}");
    }
    assert!(v["rebalances"].as_u64().is_some(), "{v}");
}

/// (id, point) of every particle in the `.vtp` pieces that `pvtp` lists,
/// sorted by id (the coordinates as written: exact).
fn piece_points(frames: &Path, pvtp: &str) -> Vec<(u64, Vec<String>)> {
    let mut out = Vec::new();
    for s in common::vtk::pvtp_sources(pvtp) {
        let piece = String::from_utf8(read(&frames.join(s))).unwrap();
        let points = common::vtk::vtk_tokens(&piece, "Points");
        for (j, id) in common::vtk::vtk_tokens(&piece, "id").iter().enumerate() {
            let point = points[3 * j..3 * j + 3].iter().map(|x| x.to_string());
            out.push((id.parse().unwrap(), point.collect()));
        }
    }
    out.sort();
    out
}

#[test]
fn dsmc_frames_in_pieces_on_2_ranks_hold_the_serial_particles() {
    let path = repo().join("scenarios/gas-vibrated-2d.toml");
    let sets = [
        "output.frames=true",
        "output.every=0.001",
        "output.frames_layout=\"pieces\"",
    ];
    let run = |ranks: usize| run_ok(ranks, &path, "100", &format!("dsmc-pieces-{ranks}"), &sets);
    let (serial, two) = (run(0), run(2));
    let pvd = String::from_utf8(read(&two.join("frames.pvd"))).unwrap();
    assert!(pvd == String::from_utf8(read(&serial.join("frames.pvd"))).unwrap());
    let frames = common::vtk::pvd_files(&pvd);
    assert!(frames.len() > 3, "{pvd}");
    for f in frames {
        let pvtp = |d: &Path| String::from_utf8(read(&d.join(f))).unwrap();
        let (a, b) = (pvtp(&serial), pvtp(&two));
        assert_eq!(b.matches("Source=").count(), 2, "{f}");
        let whole = piece_points(&serial.join("frames"), &a);
        assert_eq!(piece_points(&two.join("frames"), &b), whole, "{f}");
        let n = whole.len() as u64;
        assert!(whole.iter().map(|r| r.0).eq(1..=n), "{f}: every id once");
    }
    let _ = std::fs::remove_dir_all(&serial);
    let _ = std::fs::remove_dir_all(&two);
}

/// dump.lammpstrj's frames: (step, rows of id, type, radius, x, y, z, vx,
/// vy, vz in id order).
fn dump_frames(dir: &Path) -> Vec<(u64, Vec<Vec<f64>>)> {
    let text = String::from_utf8(read(&dir.join("dump.lammpstrj"))).unwrap();
    let mut frames: Vec<(u64, Vec<Vec<f64>>)> = Vec::new();
    let mut lines = text.lines().peekable();
    while let Some(l) = lines.next() {
        if l == "ITEM: TIMESTEP" {
            frames.push((lines.next().unwrap().trim().parse().unwrap(), Vec::new()));
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

#[test]
fn md_fill_with_inlet_outlet_and_sensor_gives_the_serial_grains_on_2_3_ranks() {
    // Disks poured by an inlet onto a floor removed at 6 ms, an outlet
    // and a sensor below (grains/tests/data/fill-2d.toml). Rank 0 inserts,
    // removes and counts on its mirror with the serial code: the inlets'
    // report, the mass balance (exact), the outlets' and sensors' counts,
    // outflow.csv and sensors.csv are the serial run's; every frame of the
    // dump holds the same grains (ids, kinds, radii exactly) at positions
    // within 1e-12 m and velocities within 1e-10 m/s, and thermo.csv agrees
    // as in `check_md` (the summation order; measured: the dump's numbers
    // identical, thermo within 3e-16 relative, on 2 and 3 ranks).
    let dir = scratch("fill-file");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("fill-2d.toml");
    std::fs::write(&file, include_str!("../../grains/tests/data/fill-2d.toml")).unwrap();
    let serial = run_ok(0, &file, "8000", "fill-0", &[]);
    let summary = |d: &Path| -> serde_json::Value {
        serde_json::from_slice(&read(&d.join("summary.json"))).unwrap()
    };
    let s0 = summary(&serial);
    assert_eq!(s0["mass_balance"]["exact"], true, "{s0}");
    assert!(
        s0["mass_balance"]["removed_grains"].as_u64().unwrap() >= 10,
        "{s0}"
    );
    let frames0 = dump_frames(&serial);
    for ranks in [2, 3] {
        let d = run_ok(ranks, &file, "8000", &format!("fill-{ranks}"), &[]);
        let s = summary(&d);
        assert_eq!(s["ranks"], ranks);
        for key in ["inlets", "mass_balance", "outlets", "sensors", "particles"] {
            assert_eq!(s[key], s0[key], "{ranks} ranks: {key}");
        }
        for f in ["outflow.csv", "sensors.csv"] {
            assert!(
                read(&d.join(f)) == read(&serial.join(f)),
                "{ranks} ranks: {f}"
            );
        }
        same_thermo(&d, &serial, &format!("fill on {ranks} ranks"));
        let frames = dump_frames(&d);
        assert_eq!(frames.len(), frames0.len());
        for ((step, rows), (step0, rows0)) in frames.iter().zip(&frames0) {
            assert_eq!(step, step0);
            assert_eq!(rows.len(), rows0.len(), "{ranks} ranks, step {step}");
            for (a, b) in rows.iter().zip(rows0) {
                assert_eq!(a[..3], b[..3], "{ranks} ranks, step {step}");
                let close = |k: usize, tol: f64| (a[k] - b[k]).abs() <= tol;
                assert!((3..6).all(|k| close(k, 1e-12)), "step {step}: {a:?} {b:?}");
                assert!((6..9).all(|k| close(k, 1e-10)), "step {step}: {a:?} {b:?}");
            }
        }
        let _ = std::fs::remove_dir_all(&d);
    }
    let _ = std::fs::remove_dir_all(&serial);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn md_fill_checkpointed_on_2_ranks_resumes_on_one_process() {
    // The fill above on 2 ranks with a checkpoint every 4000 steps,
    // resumed on one process from step 4000 (mid-insertion, the floor
    // gone): the checkpoint holds the inserted grains and the inlets' and
    // outlets' state, so the resumed run ends with the straight serial
    // run's inlets' report, mass balance and outflow.csv.
    let dir = scratch("fill-ck-file");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("fill-2d.toml");
    std::fs::write(&file, include_str!("../../grains/tests/data/fill-2d.toml")).unwrap();
    let serial = run_ok(0, &file, "8000", "fill-ck-0", &[]);
    let run = scratch("fill-ck-2");
    let args = [
        "run",
        file.to_str().unwrap(),
        "--quiet",
        "--out",
        run.to_str().unwrap(),
        "--checkpoint-every",
        "4000steps",
    ];
    let out = grains(2, &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mid = run.join("checkpoint-000000004000.grck");
    let out = grains(0, &["resume", mid.to_str().unwrap(), "--quiet"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = |d: &Path| -> serde_json::Value {
        serde_json::from_slice(&read(&d.join("summary.json"))).unwrap()
    };
    let (s0, s) = (summary(&serial), summary(&run));
    assert!(s0["mass_balance"]["removed_grains"].as_u64().unwrap() > 0);
    for key in ["inlets", "mass_balance", "outlets", "sensors", "particles"] {
        assert_eq!(s[key], s0[key], "{key}");
    }
    assert!(read(&run.join("outflow.csv")) == read(&serial.join("outflow.csv")));
    same_thermo(&run, &serial, "resumed on one process");
    for d in [&serial, &run, &dir] {
        let _ = std::fs::remove_dir_all(d);
    }
}
