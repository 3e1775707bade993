//! Checkpoint and resume with a mesh wall: grains against the turning
//! blade of an STL mixer, with friction, so that a checkpoint holds the
//! mesh's per-grain, per-patch tangential springs and the load on the
//! blade, and the blade's pose is where its motion puts it at the resumed
//! time. A straight run with checkpoints, against the same run resumed from
//! its middle checkpoint: the final engine state and `walls.csv` (the force
//! and torque on the blade) bit for bit.

use grains::dim::D3;
use grains::runner::checkpointing::{find, resume, Every};
use grains::runner::{run, RunOptions, Silent};
use grains::scenario::load_str;
use std::path::{Path, PathBuf};

const DT: f64 = 2.0e-6;
const N: u64 = 3000;

/// 30 grains moving at random beside the blade (the plane y = 0, turning
/// at 20 rev/s about z, sweeping through them, read from `stl`) in a drum with a
/// floor.
fn scenario(stl: &Path) -> String {
    format!(
        r#"name = "ck-mesh-mixer"
dimension = "3d"
seed = 5
gravity = [0.0, 0.0, -9.81]

[domain]
lo = [-0.013, -0.013, 0.0]
hi = [0.013, 0.013, 0.030]

[particles]
placement = "random"
count = 30
d0 = 1.0e-3
width = 0.2
density = 2500.0
random_velocity = 0.1
region = {{ lo = [0.002, 0.0007, 0.0007], hi = [0.009, 0.006, 0.008] }}

[contact]
kn = 1.0e4
restitution = 0.5
kt = 2.857e3
gamma_t = 2.0
mu = 0.5
rotation = true

[[walls]]
name = "drum"
shape = {{ type = "cylinder", point = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.012, inside = true }}

[[walls]]
name = "bottom"
shape = {{ type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}

[[walls]]
name = "blade"
shape = {{ type = "mesh", file = "{stl}", scale = 1.0e-3, translate = [0.0, 0.0, 0.0003], load_point = [0.0, 0.0, 0.0] }}
motion = {{ type = "rotate", center = [0.0, 0.0, 0.0], omega = [0.0, 0.0, 125.66370614359172] }}

[run]
integrator = "verlet"
dt = {DT:e}
duration = {duration:e}

[output]
every = {every:e}
frames = false
picture = false
"#,
        stl = stl.display(),
        duration = (2 * N) as f64 * DT,
        every = 200.0 * DT,
    )
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-ck-mesh-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn ck(dir: &Path, step: u64) -> PathBuf {
    dir.join(grains::checkpoint::file_name(step))
}

#[test]
fn a_run_with_a_turning_mesh_resumes_bit_for_bit() {
    // The shipped blade, copied: it is changed at the end.
    let blade = scratch("blade");
    std::fs::create_dir_all(&blade).unwrap();
    let stl = blade.join("blade.stl");
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/meshes/mixer-blade.stl");
    std::fs::copy(shipped, &stl).unwrap();
    let loaded = load_str(&scenario(&stl), "test", PathBuf::from("."), &[]).unwrap();
    let straight = scratch("straight");
    let opts = RunOptions {
        out_dir: straight.clone(),
        checkpoint_every: Some(Every::Steps(N)),
        ..RunOptions::default()
    };
    let s1 = run(&loaded, &opts, &mut Silent).unwrap();
    assert_eq!(s1["steps"], 2 * N);
    let final_state = read(&ck(&straight, 2 * N));
    let walls = read(&straight.join("walls.csv"));
    let thermo = read(&straight.join("thermo.csv"));

    // The middle checkpoint holds stretched springs on the blade's patches
    // and its load.
    let (found, skipped) = find(&ck(&straight, N)).unwrap();
    assert!(skipped.is_empty());
    let state = found.restore_md::<D3>().unwrap().export_state().unwrap();
    let on_blade = state.mesh_springs.iter().filter(|(k, _)| k.1 == 2).count();
    assert!(
        on_blade >= 1,
        "{on_blade} mesh springs stretched at the stop ({} in all; loads {:?})",
        state.mesh_springs.len(),
        state.wall_loads
    );
    let (loads, at) = &state.wall_loads;
    assert_eq!(*at, state.time);
    assert!(loads[2][0].length() > 0.0, "no load on the blade");

    // Resumed from step N: the same engine state and files at the end.
    std::fs::remove_file(ck(&straight, 2 * N)).unwrap();
    let s2 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
    assert_eq!(s2["steps"], 2 * N);
    assert!(
        read(&ck(&straight, 2 * N)) == final_state,
        "the resumed engine state differs from the straight run's"
    );
    assert!(
        read(&straight.join("walls.csv")) == walls,
        "walls.csv differs"
    );
    assert!(
        read(&straight.join("thermo.csv")) == thermo,
        "thermo.csv differs"
    );
    // The blade's rows: one per output step (and the header).
    let rows = String::from_utf8(walls).unwrap().lines().count();
    assert!(rows > 2 * N as usize / 200, "{rows} rows in walls.csv");

    // A mesh file changed since (one vertex moved by one unit in the last
    // place of its single-precision x) is refused as another scenario.
    let mut bytes = read(&stl);
    let x = 84 + 12; // the first triangle's first vertex, after its normal
    let v = f32::from_le_bytes(bytes[x..x + 4].try_into().unwrap());
    bytes[x..x + 4].copy_from_slice(&f32::from_bits(v.to_bits() + 1).to_le_bytes());
    std::fs::write(&stl, bytes).unwrap();
    let (found, _) = find(&ck(&straight, N)).unwrap();
    let e = resume(found, None, RunOptions::default(), &mut Silent)
        .unwrap_err()
        .to_string();
    assert!(e.contains("different scenario"), "{e}");
    let _ = std::fs::remove_dir_all(&straight);
    let _ = std::fs::remove_dir_all(&blade);
}
