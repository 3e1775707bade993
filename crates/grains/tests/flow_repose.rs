//! Angle of repose in 2D (seed 000 §3, Lee & Herrmann 1993), reduced to fit
//! CI: 300 disks settle in a box, the right wall goes, the slope of what stays
//! is fitted. One avalanche is chaotic (the last bits of the force sums change
//! θ_r by several degrees), so every figure is a mean over three seeds and the
//! assertions keep margins far wider than that spread.

use grains::runner::{run, RunOptions, Silent};
use grains::scenario::load_file;
use serde_json::Value;
use std::path::PathBuf;

const SEEDS: [u64; 3] = [3, 4, 5];

fn run_repose(mu: f64, seed: u64, extra: &[&str]) -> Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/repose-2d.toml");
    let mut sets = vec![
        format!("contact.mu={mu}"),
        format!("seed={seed}"),
        "output.picture=false".into(),
    ];
    sets.extend(extra.iter().map(|s| s.to_string()));
    let loaded = load_file(&path, &sets).unwrap();
    let dir = std::env::temp_dir().join(format!(
        "grains-flow-repose-{mu}-{seed}-{}-{}",
        extra.join("_").replace(['=', '.'], ""),
        std::process::id()
    ));
    let s = run(
        &loaded,
        &RunOptions {
            out_dir: dir.clone(),
            steps: None,
            ..Default::default()
        },
        &mut Silent,
    )
    .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(s["settled"], 1, "the pile must settle before the wall goes");
    s
}

/// θ_r of one run. Without a fit (fewer than three columns below the fill
/// height) the pile either flowed away entirely, which is flat, or stood as a
/// block, which the caller must not average as an angle.
fn angle(s: &Value) -> f64 {
    match s["repose_angle_deg"].as_f64() {
        Some(a) => a,
        None => {
            let left = s["remaining_grains"].as_u64().unwrap();
            assert!(left < 30, "no slope fitted but {left} grains stayed: {s}");
            0.0
        }
    }
}

fn mean_angle(mu: f64, extra: &[&str]) -> (f64, Vec<f64>) {
    let a: Vec<f64> = SEEDS
        .iter()
        .map(|&seed| angle(&run_repose(mu, seed, extra)))
        .collect();
    (a.iter().sum::<f64>() / a.len() as f64, a)
}

/// Rotation off, the seed's set-up. Measured (seeds 3–5): μ = 0 flat (2–10
/// grains stay), μ = 0.1 10–13°, μ = 0.2 35–38°: the steep rise the seed
/// calls linear for μ < 0.2. Above μ ≈ 0.3 non-rotating disks pass 45° (see
/// docs/validation.md), so the bound is asserted where it holds.
#[test]
fn repose_angle_rises_with_mu_and_flattens_without_friction() {
    let (a0, r0) = mean_angle(0.0, &[]);
    let (a1, r1) = mean_angle(0.1, &[]);
    let (a2, r2) = mean_angle(0.2, &[]);
    eprintln!("theta_r rotation off: mu=0 {r0:.1?}, mu=0.1 {r1:.1?}, mu=0.2 {r2:.1?} deg");
    assert!(
        r0.iter().all(|&a| a < 5.0),
        "mu = 0 must flatten the pile: {r0:?}"
    );
    assert!(a1 > a0 + 5.0, "theta_r must rise with mu: {a0} -> {a1}");
    assert!(a2 > a1 + 5.0, "theta_r must rise with mu: {a1} -> {a2}");
    assert!(a2 < 45.0, "theta_r(mu = 0.2) = {a2} deg");
}

/// Rotation on: disks can roll off the pile, so it stays far below 45° up to
/// μ = 1 and still rises with μ (measured: 0–1° at μ = 0.1, 10–14° at μ = 1).
#[test]
fn rolling_disks_stay_below_45_deg_up_to_mu_1() {
    let rot = ["contact.rotation=true"];
    let (lo, r_lo) = mean_angle(0.1, &rot);
    let (hi, r_hi) = mean_angle(1.0, &rot);
    eprintln!("theta_r rotation on: mu=0.1 {r_lo:.1?}, mu=1 {r_hi:.1?} deg");
    assert!(r_hi.iter().all(|&a| a < 45.0), "mu = 1: {r_hi:?}");
    assert!(hi > lo + 3.0, "theta_r must rise with mu: {lo} -> {hi}");
}

/// The angle of marginal stability: the pile the avalanche left is tilted
/// until it fails. θ_m must exceed θ_r by a few degrees (Lee & Herrmann 1993;
/// measured here 4–7° at μ = 0.1–0.2), never by more than the tilt reached.
#[test]
fn marginal_angle_exceeds_repose_angle_by_a_few_degrees() {
    let mut gaps = Vec::new();
    for seed in SEEDS {
        let s = run_repose(
            0.2,
            seed,
            &[
                "run.events.tilt_rate=10",
                "run.duration=4",
                "run.events.fail_energy=1e-3",
            ],
        );
        let m = s["marginal_angle_deg"]
            .as_f64()
            .unwrap_or_else(|| panic!("the tilted pile must fail: {s}"));
        let base = s["repose_before_tilt_deg"].as_f64().unwrap();
        gaps.push(m - base);
    }
    eprintln!("theta_m - theta_r at mu = 0.2: {gaps:.1?} deg");
    let mean = gaps.iter().sum::<f64>() / gaps.len() as f64;
    assert!(gaps.iter().all(|&g| g > 0.0), "theta_m > theta_r: {gaps:?}");
    assert!(
        (1.0..15.0).contains(&mean),
        "theta_m - theta_r = {mean} deg"
    );
}
