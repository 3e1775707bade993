//! DSMC decomposed over 1 to 4 ranks (threads standing in for MPI
//! processes, `grains::comm::ThreadComm`) against the serial engine.
//!
//! The decomposition keeps each cell's particles in serial order and draws
//! from the same (seed, step, cell) streams, so the gathered state must
//! equal the serial one bit for bit after every step: positions,
//! velocities, cell bounds v_max, remainders, collision counters, tallies.
//! Every step also checks that the ranks together hold each particle
//! exactly once (no loss or duplication across migrations). Cases: 2D and
//! 3D, a periodic cooling gas and a gas under gravity between a vibrating
//! plate and a lid, with the slab boundaries moved whenever they can be.
//! The runner test checks that the files of a distributed run are the
//! serial run's, byte for byte, and that frames written in pieces hold
//! every particle of the gathered frame exactly once, with the same bits.

use crate::common;

use common::runs::run_on_threads;
use common::vtk::{pvtp_sources, vtk_tokens};
use grains::comm::{Comm, ThreadComm};
use grains::dsmc::collide::GasDim;
use grains::dsmc::decomp::Decomposed;
use grains::dsmc::Dsmc;
use grains::runner::{dsmc::build, run, RunOptions, Silent};
use grains::scenario::{load_str, Loaded};
use grains::{D2, D3};
use std::path::{Path, PathBuf};

const STEPS: u64 = 100;

/// A periodic cooling gas or a vibrated bed (plate + lid, gravity), small
/// cells and a long step so that particles cross slab boundaries often.
fn scenario(dim: &str, walls: bool) -> String {
    let three = dim == "3d";
    let v = |xy: &str, z: &str| {
        if three {
            format!("[{xy}, {xy}, {z}]")
        } else {
            format!("[{xy}, {z}]")
        }
    };
    let body = if walls {
        format!(
            r#"gravity = {g}
[domain]
lo = {lo}
hi = {hi}
periodic = {per}
[particles]
placement = "random"
count = 1500
d0 = 1.0e-3
density = 2500.0
random_velocity = 1.0
region = {{ lo = {rlo}, hi = {rhi} }}
[dsmc]
restitution = 0.8
wall_restitution = 0.9
cell_size = 0.004
regions = 3
profile_bins = 10
[[walls]]
name = "plate"
shape = {{ type = "plane", point = {lo}, normal = {up} }}
motion = {{ type = "vibrate", amplitude = 1.0e-3, frequency = 50.0 }}
[[walls]]
name = "lid"
shape = {{ type = "plane", point = {hi}, normal = {down} }}
[run]
dt = 2.0e-4
duration = 0.02
"#,
            g = v("0.0", "-9.81"),
            lo = v("0.0", "0.0"),
            hi = v("0.03", "0.1"),
            per = v("true", "false"),
            rlo = v("0.0", "0.002"),
            rhi = v("0.03", "0.04"),
            up = v("0.0", "1.0"),
            down = v("0.0", "-1.0"),
        )
    } else {
        format!(
            r#"[domain]
lo = {lo}
hi = {hi}
periodic = {per}
[particles]
placement = "random"
count = 2000
d0 = 1.0e-3
density = 2500.0
[dsmc]
restitution = 0.9
thermal_speed = 1.0
particles_per_cell = 6.0
dense = "enskog"
regions = 2
profile_bins = 8
[run]
dt = 2.0e-3
duration = 0.2
"#,
            lo = v("0.0", "0.0"),
            hi = if three {
                v("0.05", "0.05")
            } else {
                v("0.2", "0.2")
            },
            per = v("true", "true"),
        )
    };
    format!(
        "name = \"dist-{dim}\"\ndimension = \"{dim}\"\nmethod = \"dsmc\"\nseed = 5\n{body}\n[output]\nevery = 0.002\nframes = true\npicture = false\n"
    )
}

fn loaded(dim: &str, walls: bool) -> Loaded {
    load_str(&scenario(dim, walls), "test", PathBuf::from("."), &[]).unwrap()
}

fn bits<D: GasDim>(sim: &Dsmc<D>) -> Vec<u64> {
    let mut out = Vec::new();
    for q in &sim.store.p {
        for x in D::to_xyz(q.x).into_iter().chain(D::to_xyz(q.v)) {
            out.push(x.to_bits());
        }
    }
    for c in &sim.cells {
        out.extend([
            c.vmax.to_bits(),
            c.remainder.to_bits() as u64,
            c.collisions as u64,
        ]);
    }
    out.extend([
        sim.totals.candidates,
        sim.totals.collisions,
        sim.step,
        sim.time.to_bits(),
    ]);
    out
}

/// Steps the serial engine and a decomposition on `ranks` side by side;
/// returns how often the slab boundaries moved.
fn compare<D: GasDim>(l: &Loaded, ranks: usize) -> u64 {
    let moved = ThreadComm::run(ranks, |c| {
        let root = c.rank() == 0;
        let (full, _) = build::<D>(l).unwrap();
        let mut serial = root.then(|| build::<D>(l).unwrap().0);
        let mut mirror = root.then(|| build::<D>(l).unwrap().0);
        let mut dec = Decomposed::new(full, c as &dyn Comm).unwrap();
        // Move the boundaries at every re-sort where the counts differ.
        dec.threshold = 0.0;
        let n = dec.total();
        for step in 1..=STEPS {
            dec.step();
            if let Some(mut keys) = dec.gather_keys() {
                keys.sort_unstable();
                assert!(
                    keys.iter().copied().eq(0..n),
                    "{ranks} ranks, step {step}: particles lost or duplicated"
                );
            }
            dec.gather(mirror.as_mut());
            if let (Some(s), Some(m)) = (serial.as_mut(), mirror.as_ref()) {
                s.step();
                assert!(
                    bits(s) == bits(m),
                    "{ranks} ranks, step {step}: state differs from the serial run"
                );
            }
        }
        if let Some(s) = &serial {
            // The run did something: collisions happened.
            assert!(s.totals.collisions > 100, "{}", s.totals.collisions);
        }
        dec.rebalances
    });
    moved[0]
}

fn all_rank_counts<D: GasDim>(dim: &str, walls: bool) {
    let l = loaded(dim, walls);
    let mut moved = 0;
    for ranks in 1..=4 {
        moved += compare::<D>(&l, ranks);
    }
    if walls {
        // The bed expands from its initial slabs: the boundaries followed.
        assert!(moved > 0);
    }
}

#[test]
fn decomposed_dsmc_is_serial_bit_for_bit_2d_periodic() {
    all_rank_counts::<D2>("2d", false);
}

#[test]
fn decomposed_dsmc_is_serial_bit_for_bit_2d_walls() {
    all_rank_counts::<D2>("2d", true);
}

#[test]
fn decomposed_dsmc_is_serial_bit_for_bit_3d_periodic() {
    all_rank_counts::<D3>("3d", false);
}

#[test]
fn decomposed_dsmc_is_serial_bit_for_bit_3d_walls() {
    all_rank_counts::<D3>("3d", true);
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-dist-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn distributed_run_writes_the_serial_files() {
    let l = loaded("2d", true);
    let serial_dir = scratch("serial");
    let opts = RunOptions {
        out_dir: serial_dir.clone(),
        ..Default::default()
    };
    let s0 = run(&l, &opts, &mut Silent).unwrap();
    for ranks in [2, 4] {
        let dir = scratch(&format!("r{ranks}"));
        let opts = RunOptions {
            out_dir: dir.clone(),
            ..Default::default()
        };
        let s = run_on_threads(&l, &opts, ranks);
        assert_eq!(s["ranks"], ranks);
        for key in [
            "kinetic_energy",
            "granular_temperature",
            "collisions",
            "validity",
            "steps",
        ] {
            assert_eq!(s[key], s0[key], "{ranks} ranks: {key}");
        }
        for f in ["thermo.csv", "profiles.csv", "frames.pvd"] {
            assert!(
                read(&dir.join(f)) == read(&serial_dir.join(f)),
                "{ranks} ranks: {f} differs"
            );
        }
        let frames: Vec<_> = std::fs::read_dir(serial_dir.join("frames"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(frames.len() > 5);
        for f in frames {
            let (a, b) = (
                dir.join("frames").join(&f),
                serial_dir.join("frames").join(&f),
            );
            assert!(read(&a) == read(&b), "{} differs", a.display());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&serial_dir);
}

/// The values of particle `j` in `xml`: every point array but the id, in a
/// fixed order (the text is exact: full-precision shortest round trip).
fn particle_row(xml: &str, j: usize) -> Vec<&str> {
    let arrays = [
        ("Points", 3),
        ("velocity", 3),
        ("angular_velocity", 3),
        ("radius", 1),
        ("type", 1),
    ];
    let mut row = Vec::new();
    for (name, c) in arrays {
        row.extend_from_slice(&vtk_tokens(xml, name)[j * c..(j + 1) * c]);
    }
    row
}

#[test]
fn frames_in_pieces_hold_the_gathered_frame_once_across_ranks() {
    let l = loaded("2d", true);
    let gathered = scratch("pieces-gathered");
    let opts = RunOptions {
        out_dir: gathered.clone(),
        ..Default::default()
    };
    run(&l, &opts, &mut Silent).unwrap();
    let text = format!("{}frames_layout = \"pieces\"\n", scenario("2d", true));
    let lp = load_str(&text, "test", PathBuf::from("."), &[]).unwrap();
    for ranks in [2, 3] {
        let dir = scratch(&format!("pieces-{ranks}"));
        let opts = RunOptions {
            out_dir: dir.clone(),
            ..Default::default()
        };
        run_on_threads(&lp, &opts, ranks);
        let pvd = String::from_utf8(read(&dir.join("frames.pvd"))).unwrap();
        let listed = pvd.matches(".pvtp\"").count();
        // 100 steps, a frame at step 0 and every 10 steps.
        assert_eq!(listed, 11, "{pvd}");
        assert_eq!(
            pvd.replace(".pvtp\"", ".vtp\""),
            String::from_utf8(read(&gathered.join("frames.pvd"))).unwrap()
        );
        for i in 0..listed {
            let whole = String::from_utf8(read(&gathered.join(format!("frames/frame_{i:06}.vtp"))));
            let whole = whole.unwrap();
            let n = vtk_tokens(&whole, "id").len();
            let pvtp = String::from_utf8(read(&dir.join(format!("frames/frame_{i:06}.pvtp"))));
            let pvtp = pvtp.unwrap();
            let sources = pvtp_sources(&pvtp);
            assert_eq!(sources.len(), ranks);
            let mut rows: Vec<Option<Vec<String>>> = vec![None; n];
            let mut nonempty = 0;
            for s in sources {
                let piece = String::from_utf8(read(&dir.join("frames").join(s))).unwrap();
                for f in ["TimeValue", "Step"] {
                    assert_eq!(vtk_tokens(&piece, f), vtk_tokens(&whole, f), "{s}: {f}");
                }
                let ids = vtk_tokens(&piece, "id");
                nonempty += usize::from(!ids.is_empty());
                for (j, id) in ids.iter().enumerate() {
                    let k: usize = id.parse().unwrap();
                    assert!((1..=n).contains(&k), "{s}: id {k} of {n}");
                    let row = particle_row(&piece, j).into_iter().map(String::from);
                    assert!(
                        rows[k - 1].replace(row.collect()).is_none(),
                        "{s}: id {k} twice"
                    );
                }
            }
            assert!(
                nonempty > 1,
                "frame {i}: the particles are spread over the ranks"
            );
            for (k, row) in rows.iter().enumerate() {
                let row = row
                    .as_ref()
                    .unwrap_or_else(|| panic!("frame {i}: id {} lost", k + 1));
                assert_eq!(
                    *row,
                    particle_row(&whole, k),
                    "frame {i}: particle {}",
                    k + 1
                );
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&gathered);
}
