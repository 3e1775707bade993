//! MD decomposed over 1 to 4 ranks (threads standing in for MPI processes,
//! `grains::comm::ThreadComm`) against the serial engine.
//!
//! A decomposed rank sums a grain's contact forces in another order than
//! the serial engine (its list holds other indices), so the runs agree to
//! rounding, not bit for bit: every step the total kinetic energy must
//! match within 1e-9 relative and the total momentum within 1e-9 of Σm|v|
//! (its natural scale; the momentum of a periodic gas is near zero), and
//! at the end every grain's position within 1e-9 grain diameters. Rounding
//! differences grow at most by the dynamics' Lyapunov factor over the
//! 100–200 steps here (a few contact times), far from 1e-9. Every step the
//! ranks together must hold each grain exactly once. Cases: a periodic 2D
//! gas (Gear 5: the history migrates), a 3D bed on a vibrating plate
//! (periodic sides, Velocity Verlet), and a closed 2D box with side walls,
//! a vibrating floor and frozen grains (the slab axis is not periodic).
//! Speeds are high enough that grains cross slab boundaries and the
//! neighbour list is rebuilt many times.

use crate::common;

use grains::comm::{Comm, ThreadComm};
use grains::md::decomp::{index_by_id, DecomposedMd};
use grains::md::Md;
use grains::runner::checkpointing::{self, Every};
use grains::runner::{distributed, run, RunOptions, Silent};
use grains::scenario::{build_md, load_str, Loaded};
use grains::{Dim, D2, D3};
use std::path::{Path, PathBuf};

fn gas_2d() -> String {
    r#"name = "md-gas-2d"
dimension = "2d"
seed = 3
[domain]
lo = [0.0, 0.0]
hi = [24.0, 12.0]
periodic = [true, true]
[particles]
placement = "random"
count = 160
d0 = 1.0
width = 0.2
density = 1.9098593
random_velocity = 40.0
[contact]
preset = "lammps-hooke-history"
[run]
integrator = "gear5"
dt = 1.0e-4
duration = 0.02
skin = 0.1
"#
    .into()
}

fn bed_3d() -> String {
    r#"name = "md-bed-3d"
dimension = "3d"
seed = 4
gravity = [0.0, 0.0, -1000.0]
[domain]
lo = [0.0, 0.0, 0.0]
hi = [16.0, 5.0, 10.0]
periodic = [true, true, false]
[particles]
placement = "random"
count = 180
d0 = 1.0
width = 0.2
density = 1.9098593
random_velocity = 30.0
region = { lo = [0.0, 0.0, 0.6], hi = [16.0, 5.0, 6.0] }
[contact]
preset = "lammps-hooke-history"
[[walls]]
name = "plate"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
motion = { type = "vibrate", amplitude = 0.5, frequency = 40.0 }
[run]
integrator = "verlet"
dt = 1.0e-4
duration = 0.02
skin = 0.1
"#
    .into()
}

/// Random unit grains (d ∈ [0.9, 1.1]), `count` of them, with velocity
/// components up to `speed`.
fn random_grains(count: usize, speed: f64) -> String {
    format!(
        "[particles]\nplacement = \"random\"\ncount = {count}\nd0 = 1.0\nwidth = 0.2\n\
         density = 1.9098593\nrandom_velocity = {speed:.1}\n"
    )
}

/// Plane walls at x = 0 and x = `right`, facing in.
fn side_walls(right: f64) -> String {
    format!(
        "[[walls]]\nname = \"left\"\nshape = {{ type = \"plane\", point = [0.0, 0.0], \
         normal = [1.0, 0.0] }}\n[[walls]]\nname = \"right\"\nshape = {{ type = \"plane\", \
         point = [{right:.1}, 0.0], normal = [-1.0, 0.0] }}\n"
    )
}

pub(super) fn box_2d() -> String {
    r#"name = "md-box-2d"
dimension = "2d"
seed = 5
gravity = [0.0, -1000.0]
[domain]
lo = [0.0, 0.0]
hi = [20.0, 16.0]
periodic = [false, false]
#GRAINS#
region = { lo = [0.0, 1.5], hi = [20.0, 15.0] }
[[particles.add]]
position = [5.0, 0.6]
frozen = true
[[particles.add]]
position = [10.0, 0.6]
frozen = true
[[particles.add]]
position = [15.0, 0.6]
frozen = true
[contact]
preset = "lammps-hooke-history"
[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
motion = { type = "vibrate", amplitude = 0.3, frequency = 50.0 }
#WALLS#
[run]
integrator = "gear5"
dt = 1.0e-4
duration = 0.02
skin = 0.1
"#
    .replace("#GRAINS#\n", &random_grains(80, 30.0))
    .replace("#WALLS#\n", &side_walls(20.0))
}

/// A pile forming against the left wall: gravity along the slab axis (x)
/// pulls a dilute 2D gas to one end, so the ranks on the right empty out
/// and the bounds must move (threshold 0.1).
fn pile_2d() -> String {
    r#"name = "md-pile-2d"
dimension = "2d"
seed = 6
gravity = [-5000.0, 0.0]
[domain]
lo = [0.0, 0.0]
hi = [30.0, 8.0]
periodic = [false, true]
#GRAINS#
region = { lo = [0.5, 0.0], hi = [29.5, 8.0] }
[contact]
preset = "lammps-hooke-history"
kn = 1.0e7
#WALLS#
[run]
integrator = "gear5"
dt = 4.0e-5
duration = 0.04
skin = 0.1
[parallel]
rebalance = 0.1
"#
    .replace("#GRAINS#\n", &random_grains(80, 20.0))
    .replace("#WALLS#\n", &side_walls(30.0))
}

pub(super) fn loaded(text: &str) -> Loaded {
    load_str(text, "test", PathBuf::from("."), &[]).unwrap()
}

fn scale<D: Dim>(md: &Md<D>) -> f64 {
    let p = &md.particles;
    (0..p.n_owned())
        .filter(|&i| !p.frozen[i])
        .map(|i| p.mass[i] * D::norm(p.vel[i]))
        .sum()
}

/// What a decomposed run did, for checks that the test was not vacuous.
struct Activity {
    migrations: u64,
    ghosts: usize,
    builds: u64,
    contacts: bool,
    rebalances: u64,
    grid: [usize; 3],
}

/// Steps the serial engine and a decomposition on `ranks` side by side.
fn compare<D: Dim>(l: &Loaded, ranks: usize, steps: u64) -> Activity {
    let out = ThreadComm::run(ranks, |c| {
        let root = c.rank() == 0;
        let (full, _) = build_md::<D>(l).unwrap();
        let n = full.particles.n_owned();
        let mut all_ids: Vec<u64> = full.particles.id.clone();
        all_ids.sort_unstable();
        let mut serial = root.then(|| build_md::<D>(l).unwrap().0);
        let mut mirror = root.then(|| build_md::<D>(l).unwrap().0);
        let index = mirror
            .as_ref()
            .map(|m| index_by_id(&m.particles))
            .unwrap_or_default();
        let mut dec = DecomposedMd::with_spec(full, c as &dyn Comm, &l.scenario.parallel).unwrap();
        let mut ghosts = 0;
        let mut contacts = false;
        for step in 1..=steps {
            let moves = dec.balance.rebalances;
            dec.step().unwrap();
            let b = &dec.balance;
            if b.rebalances > moves {
                assert!(
                    b.last <= b.threshold,
                    "{ranks} ranks, step {step}: imbalance {} after moving the bounds",
                    b.last
                );
            }
            ghosts = ghosts.max(dec.n_ghosts());
            let mut ids_bytes = Vec::new();
            for id in dec.owned_ids() {
                ids_bytes.extend_from_slice(&id.to_le_bytes());
            }
            let ke = dec.kinetic_energy();
            let mom = D::to_xyz(dec.momentum());
            if let Some(all) = c.gather_bytes(&ids_bytes) {
                let mut ids: Vec<u64> = all
                    .concat()
                    .chunks(8)
                    .map(|b| u64::from_le_bytes(b.try_into().unwrap()))
                    .collect();
                ids.sort_unstable();
                assert_eq!(
                    ids, all_ids,
                    "{ranks} ranks, step {step}: grains lost or duplicated"
                );
            }
            if let Some(s) = serial.as_mut() {
                s.step().unwrap();
                contacts |= s.stats.contacts > 0;
                let (ke0, mom0) = (
                    s.particles.kinetic_energy(),
                    D::to_xyz(s.particles.momentum()),
                );
                assert!(
                    (ke - ke0).abs() <= 1e-9 * ke0,
                    "{ranks} ranks, step {step}: kinetic energy {ke} vs serial {ke0}"
                );
                let sc = scale(s);
                for a in 0..3 {
                    assert!(
                        (mom[a] - mom0[a]).abs() <= 1e-9 * sc,
                        "{ranks} ranks, step {step}: momentum {mom:?} vs serial {mom0:?}"
                    );
                }
            }
        }
        dec.gather(mirror.as_mut(), &index);
        if let (Some(s), Some(m)) = (serial.as_ref(), mirror.as_ref()) {
            assert_eq!((m.step, m.time), (s.step, s.time));
            let at = index_by_id(&s.particles);
            let mut worst: f64 = 0.0;
            for i in 0..n {
                let j = at[&m.particles.id[i]];
                let d = s
                    .domain
                    .minimum_image(m.particles.pos[i] - s.particles.pos[j]);
                worst = worst.max(D::norm(d));
            }
            assert!(
                worst < 1e-9,
                "{ranks} ranks: a grain is {worst} from its serial place"
            );
        }
        Activity {
            migrations: dec.migrations,
            ghosts,
            builds: dec.neighbor_builds(),
            contacts,
            rebalances: dec.balance.rebalances,
            grid: dec.subdomains().grid,
        }
    });
    out.into_iter().next().unwrap()
}

fn all_rank_counts<D: Dim>(text: &str, steps: u64) {
    let l = loaded(text);
    for ranks in 1..=4 {
        let a = compare::<D>(&l, ranks, steps);
        assert!(a.builds > 5, "{ranks} ranks: only {} list builds", a.builds);
        assert!(a.contacts);
        if ranks > 1 {
            assert!(a.ghosts > 0, "{ranks} ranks: no ghosts");
            assert!(a.migrations > 0, "{ranks} ranks: no grain changed rank");
        }
    }
}

#[test]
fn decomposed_md_matches_serial_2d_periodic_gas() {
    all_rank_counts::<D2>(&gas_2d(), 100);
}

#[test]
fn decomposed_md_matches_serial_3d_vibrated_bed() {
    all_rank_counts::<D3>(&bed_3d(), 200);
}

#[test]
fn decomposed_md_matches_serial_2d_closed_box_with_frozen_grains() {
    all_rank_counts::<D2>(&box_2d(), 200);
}

#[test]
fn decomposed_md_moves_the_bounds_of_a_pile() {
    let l = loaded(&pile_2d());
    for ranks in [2, 4] {
        let a = compare::<D2>(&l, ranks, 1000);
        assert!(a.contacts && a.migrations > 0);
        assert!(a.rebalances > 0, "{ranks} ranks: the bounds never moved");
    }
    // On a 2 × 2 grid the staggered cuts move by the counts within each slab.
    let a = compare::<D2>(
        &loaded(&with_grid(&pile_2d(), "[2, 2]").replace("[parallel]\nrebalance = 0.1\n", "")),
        4,
        1000,
    );
    assert_eq!(a.grid, [2, 2, 1]);
    assert!(a.rebalances > 0, "2 × 2: the bounds never moved");
    // Threshold 0: the bounds stay where they were cut at the start.
    let fixed = loaded(&pile_2d().replace("rebalance = 0.1", "rebalance = 0.0"));
    assert_eq!(compare::<D2>(&fixed, 2, 1000).rebalances, 0);
}

/// A decomposition on 4 ranks must match the serial run (checks of
/// [`compare`]) on the grid `want`, with grains crossing between ranks.
fn on_grid<D: Dim>(text: &str, steps: u64, want: [usize; 3]) {
    let a = compare::<D>(&loaded(text), 4, steps);
    assert_eq!(a.grid, want);
    assert!(a.contacts && a.ghosts > 0 && a.migrations > 0 && a.builds > 5);
}

fn with_grid(text: &str, grid: &str) -> String {
    format!("{text}\n[parallel]\ngrid = {grid}\n")
}

#[test]
fn decomposed_md_matches_serial_on_2d_grids() {
    // Periodic gas on a forced 2 × 2 grid (ghosts across the corners).
    on_grid::<D2>(&with_grid(&gas_2d(), "[2, 2]"), 100, [2, 2, 1]);
    // Closed box with walls: "auto" chooses 2 × 2 (cut area 36 against 48).
    on_grid::<D2>(&box_2d(), 200, [2, 2, 1]);
}

#[test]
fn decomposed_md_matches_serial_on_3d_grids() {
    let wide = bed_3d()
        .replace("hi = [16.0, 5.0, 10.0]", "hi = [16.0, 8.0, 10.0]")
        .replace("hi = [16.0, 5.0, 6.0]", "hi = [16.0, 8.0, 6.0]");
    on_grid::<D3>(&with_grid(&wide, "[2, 2, 1]"), 200, [2, 2, 1]);
    // Cut along the open vertical: the upper boxes reach to infinity.
    on_grid::<D3>(&with_grid(&wide, "[1, 2, 2]"), 200, [1, 2, 2]);
}

/// `advance` (one step's corrector and the next step's predictor in one
/// pass) against single steps on the same ranks: the same arithmetic, so
/// the same bits for every grain, Gear history included.
fn advance_matches_steps<D: Dim>(text: &str, ranks: usize, steps: u64) {
    let l = loaded(text);
    ThreadComm::run(ranks, |c| {
        let c = c as &dyn Comm;
        let spec = &l.scenario.parallel;
        let mut single = DecomposedMd::with_spec(build_md::<D>(&l).unwrap().0, c, spec).unwrap();
        let mut fused = DecomposedMd::with_spec(build_md::<D>(&l).unwrap().0, c, spec).unwrap();
        for _ in 0..steps {
            single.step().unwrap();
        }
        // Uneven stretches, so that stretches end and start between rebuilds.
        let mut done = 0;
        for k in [1, 17, 40] {
            fused.advance(k).unwrap();
            done += k;
        }
        fused.advance(steps - done).unwrap();
        let (a, b) = (&single.md.particles, &fused.md.particles);
        let n = a.n_owned();
        assert_eq!(n, b.n_owned(), "rank {}", c.rank());
        assert_eq!(a.id[..n], b.id[..n]);
        assert_eq!(a.pos[..n], b.pos[..n], "rank {}: positions", c.rank());
        assert_eq!(a.vel[..n], b.vel[..n], "rank {}: velocities", c.rank());
        assert_eq!(a.omega[..n], b.omega[..n], "rank {}: spins", c.rank());
        for (ga, gb) in a.gear.iter().zip(&b.gear) {
            assert_eq!(ga[..n], gb[..n], "rank {}: Gear history", c.rank());
        }
        assert!(single.neighbor_builds() > 2, "too few rebuilds to test");
        assert_eq!(single.neighbor_builds(), fused.neighbor_builds());
    });
}

#[test]
fn advance_gives_the_bits_of_single_steps_on_ranks() {
    advance_matches_steps::<D2>(&gas_2d(), 2, 150);
    advance_matches_steps::<D3>(&bed_3d(), 3, 150);
}

#[test]
fn too_many_ranks_for_the_box_is_a_clear_error() {
    let refused = |text: &str, ranks: usize| {
        let l = loaded(text);
        let errs = ThreadComm::run(ranks, |c| {
            let (full, _) = build_md::<D2>(&l).unwrap();
            DecomposedMd::with_spec(full, c as &dyn Comm, &l.scenario.parallel)
                .err()
                .map(|e| e.to_string())
        });
        errs[0].clone().unwrap_or_default()
    };
    // 12 slabs of 2 along x are too thin (2 reaches = 2.6) ...
    let e = refused(&with_grid(&gas_2d(), "\"slabs\""), 12);
    assert!(
        e.contains("run on fewer ranks") && e.contains("slabs"),
        "{e}"
    );
    // ... "auto" takes 6 × 2 instead, but no grid of 37 fits.
    assert_eq!(refused(&gas_2d(), 12), "");
    let e = refused(&gas_2d(), 37);
    assert!(e.contains("run on fewer ranks"), "{e}");
}

pub(super) fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-dist-md-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

pub(super) fn thermo(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("thermo.csv")).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

#[test]
fn distributed_md_run_writes_the_serial_run_to_rounding() {
    let text = format!(
        "{}\n[output]\nevery = 0.002\nframes = true\npicture = false\n",
        bed_3d()
    );
    let l = loaded(&text);
    let serial_dir = scratch("serial");
    let opts = RunOptions {
        out_dir: serial_dir.clone(),
        ..Default::default()
    };
    let s0 = run(&l, &opts, &mut Silent).unwrap();
    let (head, rows0) = thermo(&serial_dir);
    assert!(rows0.len() > 5);
    for ranks in [2, 4] {
        let dir = scratch(&format!("r{ranks}"));
        let opts = RunOptions {
            out_dir: dir.clone(),
            ..Default::default()
        };
        let s = &common::runs::run_on_threads(&l, &opts, ranks);
        assert_eq!(s["ranks"], ranks);
        assert!(s["migrations"].as_u64().unwrap() > 0);
        assert!(s["rebalances"].as_u64().is_some());
        let (i0, imax) = (&s["imbalance_initial"], &s["imbalance_max"]);
        assert!(i0.as_f64().unwrap() <= imax.as_f64().unwrap());
        assert!(s["imbalance_final"].as_f64().unwrap() <= imax.as_f64().unwrap());
        for key in ["steps", "particles", "time"] {
            assert_eq!(s[key], s0[key], "{ranks} ranks: {key}");
        }
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-300);
        for key in [
            "kinetic_energy",
            "rotational_energy",
            "granular_temperature",
        ] {
            let (a, b) = (s[key].as_f64().unwrap(), s0[key].as_f64().unwrap());
            assert!(close(a, b), "{ranks} ranks: {key} {a} vs {b}");
        }
        let (h, rows) = thermo(&dir);
        assert_eq!(h, head);
        assert_eq!(rows.len(), rows0.len());
        for (r, r0) in rows.iter().zip(&rows0) {
            for (k, name) in head.iter().enumerate() {
                // Contacts across a slab boundary count on both ranks.
                if name != "contacts" {
                    assert!(
                        close(r[k], r0[k]),
                        "{ranks} ranks: {name} {} vs {}",
                        r[k],
                        r0[k]
                    );
                }
            }
        }
        let count = |d: &Path| std::fs::read_dir(d.join("frames")).unwrap().count();
        assert_eq!(count(&dir), count(&serial_dir));
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&serial_dir);
}

#[test]
fn an_unstable_step_stops_every_rank_with_one_message() {
    // dt far above the contact time: grains sink into each other.
    let l = load_str(
        &gas_2d(),
        "test",
        PathBuf::from("."),
        &["run.dt=0.01".into()],
    )
    .unwrap();
    let (mut serial, _) = build_md::<D2>(&l).unwrap();
    let serial_err = (0..200)
        .find_map(|_| serial.step().err())
        .unwrap()
        .to_string();
    let out = ThreadComm::run(3, |c| {
        let (full, _) = build_md::<D2>(&l).unwrap();
        let mut dec = DecomposedMd::new(full, c as &dyn Comm).unwrap();
        (0..200)
            .find_map(|_| dec.step().err())
            .map(|e| (e.to_string(), dec.md.step))
    });
    let (msg, step) = out[0].clone().expect("the decomposed run must stop");
    assert!(msg.contains("overlaps"), "{msg}");
    assert!(out.iter().all(|o| o.as_ref() == Some(&(msg.clone(), step))));
    assert!(
        serial_err.contains(&format!("at step {step} ")),
        "{serial_err} vs {msg}"
    );
}

// Checkpoints of decomposed runs. A checkpoint taken on 2 ranks is the
// serial format: resumed on 2 ranks, or on one process, and a serial
// checkpoint resumed on 2 ranks, each continues like the uninterrupted run
// to rounding. The resumed run splits and builds its lists at the
// checkpoint step instead of at the straight run's rebuild, so forces are
// summed in another order: the same 1e-9 tolerances as above hold (the
// rounding differences grow by the Lyapunov factor of ~100 steps only).

/// `steps` measured steps (checkpoint every `every`) into `dir`, on `ranks`
/// thread ranks (0: the serial runner).
fn run_ranks(l: &Loaded, dir: &Path, ranks: usize, steps: u64, every: u64) {
    let opts = RunOptions {
        out_dir: dir.to_path_buf(),
        steps: Some(steps),
        checkpoint_every: Some(Every::Steps(every)),
        ..Default::default()
    };
    if ranks == 0 {
        run(l, &opts, &mut Silent).unwrap();
        return;
    }
    common::runs::run_on_threads(l, &opts, ranks);
}

/// Resumes the newest checkpoint of `dir` for `steps` steps on `ranks`.
fn resume_ranks(dir: &Path, ranks: usize, steps: u64) {
    if ranks == 0 {
        let (found, _) = checkpointing::find(dir).unwrap();
        checkpointing::resume(found, Some(steps), RunOptions::default(), &mut Silent).unwrap();
        return;
    }
    ThreadComm::run(ranks, |c| {
        let (found, _) = checkpointing::find(dir).unwrap();
        distributed::resume(found, Some(steps), RunOptions::default(), &mut Silent, c).unwrap();
    });
}

/// The newest checkpoint of `dir` as an engine, with its step.
fn newest<D: Dim>(dir: &Path) -> Md<D> {
    checkpointing::find(dir)
        .unwrap()
        .0
        .restore_md::<D>()
        .unwrap()
}

/// Every grain (by id) within 1e-9 diameters and 1e-9 of Σm|v| in
/// momentum, the kinetic energy within 1e-9 relative; the thermo tables
/// equal to the same tolerance (contacts aside: both ranks count one
/// across a slab boundary).
fn same_run<D: Dim>(a_dir: &Path, b_dir: &Path, step: u64) {
    let (a, b) = (newest::<D>(a_dir), newest::<D>(b_dir));
    assert_eq!((a.step, b.step), (step, step));
    let ib = index_by_id(&b.particles);
    let (p, q) = (&a.particles, &b.particles);
    assert_eq!(p.n_owned(), q.n_owned());
    let d = 2.0 * p.max_radius();
    let mv = scale(&a);
    for i in 0..p.n_owned() {
        let j = ib[&p.id[i]];
        // One run may have wrapped a grain into the box since its last rebuild.
        let dx = a.domain.minimum_image(p.pos[i] - q.pos[j]);
        assert!(
            D::norm(dx) <= 1e-9 * d,
            "{}: grain {} off by {:e} diameters",
            a_dir.display(),
            p.id[i],
            D::norm(dx) / d
        );
        let dv = D::norm(p.vel[i] - q.vel[j]) * p.mass[i];
        assert!(dv <= 1e-9 * mv, "grain {} velocity", p.id[i]);
    }
    let (ea, eb) = (p.kinetic_energy(), q.kinetic_energy());
    assert!((ea - eb).abs() <= 1e-9 * ea, "kinetic energy {ea} vs {eb}");
    let ((ha, ra), (hb, rb)) = (thermo(a_dir), thermo(b_dir));
    assert_eq!(ha, hb);
    assert_eq!(ra.len(), rb.len());
    for (x, y) in ra.iter().zip(&rb) {
        for (k, name) in ha.iter().enumerate() {
            let ok = (x[k] - y[k]).abs() <= 1e-9 * y[k].abs().max(1e-300);
            assert!(name == "contacts" || ok, "{name}: {} vs {}", x[k], y[k]);
        }
    }
}

/// 2K steps straight on 2 ranks against K, checkpoint, resume K: on 2
/// ranks, on one process, and from a serial checkpoint on 2 ranks.
fn checkpoint_cases<D: Dim>(text: &str, k: u64, name: &str) {
    let text = format!("{text}\n[output]\nevery = 0.001\nframes = false\npicture = false\n");
    let l = loaded(&text);
    let dir = |s: &str| scratch(&format!("ck-{name}-{s}"));
    let (straight2, straight1) = (dir("straight2"), dir("straight1"));
    run_ranks(&l, &straight2, 2, 2 * k, k);
    run_ranks(&l, &straight1, 0, 2 * k, k);
    // (ranks before the checkpoint, ranks after, the straight run to match)
    for (before, after, reference) in [(2, 0, &straight1), (0, 2, &straight1), (2, 2, &straight2)] {
        let d = dir(&format!("{before}-{after}"));
        run_ranks(&l, &d, before, k, k);
        assert_eq!(newest::<D>(&d).step, k);
        resume_ranks(&d, after, k);
        same_run::<D>(&d, reference, 2 * k);
        let _ = std::fs::remove_dir_all(&d);
    }
    // The 2-rank and serial straight runs agree too (the decomposition).
    same_run::<D>(&straight2, &straight1, 2 * k);
    let _ = std::fs::remove_dir_all(&straight1);
    let _ = std::fs::remove_dir_all(&straight2);
}

#[test]
fn checkpoints_of_decomposed_runs_resume_anywhere_3d_verlet_bed() {
    checkpoint_cases::<D3>(&bed_3d(), 60, "bed3d");
}

#[test]
fn checkpoints_of_decomposed_runs_resume_anywhere_2d_gear_box() {
    checkpoint_cases::<D2>(&box_2d(), 60, "box2d");
}

/// The numbers of the DataArray `name` in a .vtp document.
pub(super) fn vtp_array(xml: &str, name: &str) -> Vec<f64> {
    let values = common::vtk::vtk_tokens(xml, name).into_iter();
    values.map(|t| t.parse().unwrap()).collect()
}

#[test]
fn frames_in_pieces_hold_every_grain_once_across_ranks() {
    let text = format!(
        "{}\n[output]\nevery = 0.005\nframes = true\nframes_layout = \"pieces\"\npicture = false\n",
        bed_3d()
    );
    let l = loaded(&text);
    let (whole, _) = build_md::<D3>(&l).unwrap();
    let mut all: Vec<u64> = whole.particles.id.clone();
    all.sort_unstable();
    for ranks in [1, 2, 3] {
        let dir = scratch(&format!("pieces-{ranks}"));
        run_ranks(&l, &dir, ranks, 200, 1000);
        let pvd = std::fs::read_to_string(dir.join("frames.pvd")).unwrap();
        let listed = common::vtk::pvd_files(&pvd);
        // Step 0 and every 50 steps to 200.
        assert_eq!(listed.len(), 5, "{pvd}");
        for rel in listed {
            assert!(rel.ends_with(".pvtp"), "{rel}");
            let pvtp = std::fs::read_to_string(dir.join(rel)).unwrap();
            let sources = common::vtk::pvtp_sources(&pvtp);
            assert_eq!(sources.len(), ranks);
            let mut ids = Vec::new();
            for s in sources {
                let piece = std::fs::read_to_string(dir.join("frames").join(s)).unwrap();
                let n = vtp_array(&piece, "id").len();
                assert_eq!(vtp_array(&piece, "radius").len(), n);
                assert_eq!(vtp_array(&piece, "Points").len(), 3 * n);
                if ranks > 1 {
                    assert!(n > 0 && n < all.len(), "a piece holds its rank's grains");
                }
                ids.extend(vtp_array(&piece, "id").into_iter().map(|x| x as u64));
            }
            ids.sort_unstable();
            assert_eq!(ids, all, "{rel}: every grain once");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn an_unknown_frames_layout_is_refused_naming_key_and_choices() {
    let text = format!("{}\n[output]\nframes_layout = \"tiles\"\n", bed_3d());
    let err = load_str(&text, "bed.toml", PathBuf::from("."), &[])
        .unwrap_err()
        .to_string();
    for part in [
        "bed.toml",
        "output.frames_layout",
        "gathered",
        "pieces",
        "tiles",
    ] {
        assert!(err.contains(part), "{part} missing in: {err}");
    }
}
