//! `grains cg` (`measure::fields::replay`): a run's fields computed again
//! from its saved frames and contacts. With the run's own kernel, width
//! and grid they are the run's (the files carry shortest round-trip
//! decimals, so everything comes back bit for bit but a wall contact's
//! force, its normal and tangential parts added again: a last-bit
//! difference); with a wider Gaussian the density is the narrower one's
//! convolved with a Gaussian of width √(w₂² − w₁²), as Gaussians compose.

use crate::common::runs::{read_csv, run_scenario_kept};
use grains::measure::fields::replay::{recompute, Recompute};
use std::path::Path;

/// bed-fields-2d settling: the frames at the fields' sample steps (dt
/// 1e-5 s, relaxation 10,000 steps, a frame and a sample every 200
/// steps, windows of 5 samples), so the frames are the run's samples.
const SETS: [&str; 8] = [
    "run.dt=1e-5",
    "run.relax=0.1",
    "run.duration=0.02",
    "output.every=0.002",
    "output.frames=true",
    "output.contacts=true",
    "measure.fields.every=200",
    "measure.fields.average=5",
];

fn csv(dir: &Path, k: usize) -> Vec<Vec<f64>> {
    read_csv(&dir.join(format!("fields/fields_{k:05}.csv")))
}

#[test]
fn the_runs_own_kernel_gives_the_runs_fields() {
    let (summary, dir) = run_scenario_kept("bed-fields-2d", "cg-same", &SETS);
    assert_eq!(summary["fields_windows"], 2);
    let out = dir.join("cg");
    let done = recompute(&dir, &out, &Recompute::default()).unwrap();
    assert_eq!((done.samples, done.off_schedule, done.windows), (10, 0, 2));
    let (mut worst, mut same, mut all) = (0.0f64, 0, 0);
    for k in 0..2 {
        let (run, again) = (csv(&dir, k), csv(&out, k));
        assert_eq!(run.len(), again.len());
        for c in 0..run[0].len() {
            let scale = run.iter().map(|r| r[c].abs()).fold(0.0, f64::max);
            for (a, b) in run.iter().zip(&again) {
                worst = worst.max((a[c] - b[c]).abs() / scale.max(f64::MIN_POSITIVE));
                same += usize::from(a[c].to_bits() == b[c].to_bits());
                all += 1;
            }
        }
    }
    println!(
        "cg again: {same} of {all} values bit for bit, worst {worst:.2e} of a column's largest"
    );
    assert!(worst <= 1e-12, "{worst:e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_wider_gaussian_is_the_narrower_one_smoothed() {
    let (_, dir) = run_scenario_kept("bed-fields-2d", "cg-wide", &SETS);
    let out = dir.join("cg-w2");
    let wide = Recompute {
        width: Some(2.0),
        grid: Some("y:60".into()),
        ..Recompute::default()
    };
    recompute(&dir, &out, &wide).unwrap();
    // Profiles along y of 60 points over 30 mm (h = 0.5 mm), w₁ = d0 =
    // 1 mm, w₂ = 2 mm: ρ₂(y_k) = Σ_l ρ₁(y_l) g_s(y_k − y_l) h, s = √3 mm.
    let (w1, w2, h) = (1e-3f64, 2e-3, 0.5e-3);
    let s = (w2 * w2 - w1 * w1).sqrt();
    let g = |x: f64| (-x * x / (2.0 * s * s)).exp() / (s * (2.0 * std::f64::consts::PI).sqrt());
    let (narrow, broad) = (csv(&dir, 0), csv(&out, 0));
    let rho_max = narrow.iter().map(|r| r[1]).fold(0.0, f64::max);
    let (mut worst, mut change) = (0.0f64, 0.0f64);
    for k in 0..broad.len() {
        let y = broad[k][0];
        let predicted: f64 = narrow.iter().map(|r| r[1] * g(y - r[0]) * h).sum();
        change = change.max((broad[k][1] - narrow[k][1]).abs());
        // From 4 s above the floor: what lies below it, which the profile
        // does not hold, weighs under e^-8 there.
        if y >= 4.0 * s {
            worst = worst.max((broad[k][1] - predicted).abs());
        }
    }
    println!(
        "w = 2 d0 against w = d0 smoothed: worst {:.2e} of the largest density (the profiles differ by up to {:.2e} of it)",
        worst / rho_max,
        change / rho_max
    );
    // The kernels are cut at 3w and normalised again: each puts back the
    // 0.27 % of a Gaussian's mass the cut leaves out, so their composition
    // differs from the wider cut Gaussian by about that much.
    assert!(worst <= 0.01 * rho_max, "{worst:e}");
    assert!(
        change >= 0.1 * rho_max,
        "the step at the surface is smoothed"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
