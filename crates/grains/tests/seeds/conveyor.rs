//! Seed 002 Fig. 4 at reduced length: transport on a vibrating conveyor.

use crate::common;

use common::runs::{num, run_scenario};

/// Mean transport velocity over `run.cycles=10` after 10 relaxation cycles;
/// `extra` may override both (later `--set`s win).
fn transport(name: &str, tag: &str, extra: &[&str]) -> f64 {
    let mut sets = vec![
        "run.relax_cycles=10",
        "run.cycles=10",
        "measure.trajectories.cycles=0.2",
    ];
    sets.extend_from_slice(extra);
    num(&run_scenario(name, tag, &sets), "transport_velocity")
}

#[test]
fn no_shear_friction_no_transport() {
    let v = transport("seed-conveyor", "gs0", &["contact.gamma_t=0"]);
    let v500 = transport("seed-conveyor", "gs500", &[]);
    assert!(
        v.abs() < 0.05 * v500,
        "gamma_s = 0: {v} m/s; gamma_s = 500: {v500} m/s"
    );
}

// Full-length sweep (docs/seed-figures.md): 0.093, 0.176, 0.191, 0.169,
// 0.149 m/s at 20, 40, 60, 80, 100 Hz: growth up to ~60 Hz, then a slow
// decline (A_z fixed, so Gamma grows as f^2 and the bed turns gas-like).
#[test]
fn transport_grows_with_frequency() {
    let v20 = transport(
        "seed-conveyor",
        "f20",
        &["walls.0.motion.frequency=20", "run.relax_cycles=5"],
    );
    // At 60 Hz the bed takes longer to reach its steady speed: after 10 + 10
    // cycles it is still accelerating (0.080 m/s; 0.166 after 20 + 30).
    let v60 = transport(
        "seed-conveyor",
        "f60",
        &[
            "walls.0.motion.frequency=60",
            "run.relax_cycles=20",
            "run.cycles=30",
        ],
    );
    assert!(v60 > v20 && v20 > 0.0, "20 Hz: {v20} m/s, 60 Hz: {v60} m/s");
}

#[test]
fn an_obstacle_slows_the_flow() {
    // Steady state needs 20 + 30 cycles (measured: free 0.150, obstacle
    // 0.048 m/s; after 10 + 10 the free bed is still accelerating).
    let long = ["run.relax_cycles=20", "run.cycles=30"];
    let free = transport("seed-conveyor", "free", &long);
    let blocked = transport("seed-conveyor-obstacle", "obstacle", &long);
    assert!(
        blocked < 0.8 * free,
        "free {free} m/s, with obstacle {blocked} m/s"
    );
}
