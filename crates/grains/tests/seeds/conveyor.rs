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

/// "For γ_s ≥ 50g [the transport] depends only very weakly on γ_s": with
/// γ and γ_s in units of √(g/d0) (γ = 50g → 5000 s⁻¹, at the seed's time
/// step; t_c/50 lets a grain sink 92 % into the belt) doubling γ_s from
/// 5000 to 10000 s⁻¹ changed the full-length transport by −4 ± 4 % over
/// seeds 1-8 (seeds 1-4: 0.246 → 0.222 m/s, spreads 0.015 and 0.018),
/// where the shipped reading's doubling from 500 to 1000 s⁻¹ gains
/// 43 ± 2 % (seeds 1-4: 0.167 → 0.239, spreads 0.005 and 0.004). The test
/// asks seeds 1-4 for a change under 20 % in the first reading (the ratio's
/// standard error is about 5 %) and over 30 % in the second.
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn transport_saturates_in_shear_friction_in_the_unit_reading() {
    let mean = |tag: &str, sets: &[&str]| {
        (1..=4)
            .map(|seed| {
                let seed = format!("seed={seed}");
                let mut all = vec!["run.relax_cycles=20", "run.cycles=20", seed.as_str()];
                all.extend_from_slice(sets);
                transport("seed-conveyor", &format!("{tag}-{seed}"), &all)
            })
            .sum::<f64>()
            / 4.0
    };
    let unit = ["contact.gamma_n=5000", "run.dt=6.25e-7"];
    let u5 = mean("u5000", &[&unit[..], &["contact.gamma_t=5000"]].concat());
    let u10 = mean("u10000", &[&unit[..], &["contact.gamma_t=10000"]].concat());
    let t5 = mean("t500", &["contact.gamma_t=500"]);
    let t10 = mean("t1000", &["contact.gamma_t=1000"]);
    assert!(
        (u10 / u5 - 1.0).abs() < 0.2,
        "sqrt(g/d0) reading: {u5} m/s at gamma_s = 5000, {u10} at 10000"
    );
    assert!(
        t10 / t5 > 1.3,
        "shipped reading: {t5} m/s at gamma_s = 500, {t10} at 1000"
    );
}
