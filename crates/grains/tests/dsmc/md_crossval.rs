//! Cross-validation of the two engines: the same dilute vibrated gas
//! (`scenarios/gas-crossval-2d.toml`: 100 disks, e = 0.9, frictionless,
//! the same vibrating plate, lid, gravity and time step) run with
//! soft-sphere MD and with DSMC must give the same number density against
//! height.
//!
//! Measure: the L1 distance Σ|p_a − p_b| between profiles normalized to
//! unit sum (0 for equal profiles, 2 for disjoint ones). Statistical noise:
//! the larger of the distances between two seeds of the same engine. If
//! the engines sampled the same profile, the distance between their
//! two-seed averages would be about noise/√2 (each average has half the
//! variance of one run). The tolerance, 2 × noise, leaves room for a
//! systematic difference of about one noise level (4–5% of the profile)
//! for what the models do differently: finite contact duration in MD,
//! instantaneous wall reflection at the end of a step in DSMC, the Enskog
//! factor at ν ≈ 0.03 next to the plate. A control run of DSMC with
//! e = 0.7 must land outside the tolerance, so that the criterion is
//! known to discriminate.
//!
//! The runs are deterministic (fixed seeds, results independent of the
//! thread count), so the test gives the same figures every time.

use grains::runner::{run, RunOptions, Silent};
use grains::scenario::load_file;
use std::path::{Path, PathBuf};

fn scenario() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/gas-crossval-2d.toml")
}

/// Runs the scenario with `sets` and returns its normalized density
/// profile (one value per height bin).
fn profile(tag: &str, sets: &[&str]) -> Vec<f64> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let loaded = load_file(&scenario(), &sets).unwrap();
    let dir = std::env::temp_dir().join(format!("grains-crossval-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = RunOptions {
        out_dir: dir.clone(),
        ..RunOptions::default()
    };
    run(&loaded, &opts, &mut Silent).unwrap();
    let text = std::fs::read_to_string(dir.join("profiles.csv")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    // MD writes a comment line first; both have a header, then height and
    // number density in the first two columns.
    let n: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
        .collect();
    let total: f64 = n.iter().sum();
    assert!(total > 0.0, "{tag}: empty profile");
    n.iter().map(|x| x / total).collect()
}

fn l1(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "profiles of different binning");
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}

fn mean(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect()
}

/// The MD plate contact's restitution, which the scenario's
/// dsmc.wall_restitution must repeat: a grain–grain contact of reduced
/// stiffness κ = 2k_n/m and damping γ set for e = 0.9, against a wall
/// κ = k_n/m with the same γ (docs/scenario-reference.md §4).
#[test]
fn crossval_wall_restitution_matches_md_plate() {
    let e: f64 = 0.9;
    let w0: f64 = 1.0; // √(2k_n/m), units cancel
    let gamma = -2.0 * e.ln() * w0 / (std::f64::consts::PI.powi(2) + e.ln().powi(2)).sqrt();
    let ww = (0.5 * w0 * w0 - 0.25 * gamma * gamma).sqrt();
    let e_wall = (-gamma * std::f64::consts::PI / (2.0 * ww)).exp();
    let text = std::fs::read_to_string(scenario()).unwrap();
    let v: toml::Value = toml::from_str(&text).unwrap();
    let given = v["dsmc"]["wall_restitution"].as_float().unwrap();
    assert!((given - e_wall).abs() < 1e-4, "{given} vs {e_wall}");
    assert_eq!(
        v["dsmc"]["restitution"].as_float(),
        v["contact"]["restitution"].as_float()
    );
}

#[test]
fn dsmc_and_md_give_the_same_density_profile_of_a_vibrated_gas() {
    let dsmc = r#"method="dsmc""#;
    let runs: Vec<(&str, Vec<&str>)> = vec![
        ("md1", vec!["seed=1"]),
        ("md2", vec!["seed=2"]),
        ("dsmc1", vec![dsmc, "seed=1"]),
        ("dsmc2", vec![dsmc, "seed=2"]),
        ("dsmc-e07", vec![dsmc, "seed=3", "dsmc.restitution=0.7"]),
    ];
    // The five runs are independent: run them side by side.
    let p: Vec<Vec<f64>> = std::thread::scope(|s| {
        let handles: Vec<_> = runs
            .iter()
            .map(|(tag, sets)| s.spawn(move || profile(tag, sets)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let noise = l1(&p[0], &p[1]).max(l1(&p[2], &p[3]));
    let md = mean(&p[0], &p[1]);
    let cross = l1(&md, &mean(&p[2], &p[3]));
    let control = l1(&md, &p[4]);
    let tolerance = 2.0 * noise;
    eprintln!(
        "L1: MD seeds {:.4}, DSMC seeds {:.4}, MD vs DSMC (two-seed means) {cross:.4}, \
         tolerance {tolerance:.4}; MD vs DSMC at e = 0.7 {control:.4}",
        l1(&p[0], &p[1]),
        l1(&p[2], &p[3])
    );
    // A sane noise level: the profiles are well sampled but not identical.
    assert!(noise > 0.0 && noise < 0.15, "noise {noise}");
    assert!(
        cross < tolerance,
        "MD and DSMC profiles differ: {cross} >= {tolerance}"
    );
    assert!(
        control > tolerance,
        "the e = 0.7 control is not detected: {control}"
    );
}
