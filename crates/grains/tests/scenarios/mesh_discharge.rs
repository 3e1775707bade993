//! The silo of hopper-3d with its floor read from an STL (mesh-silo-3d)
//! discharges as fast as with the analytic floor, within the scatter of
//! three seeds. Six 1 s runs of 3000 grains: about 10 minutes on one
//! core, so in the long tier (`.ci/long.sh`, feature `long-tests`);
//! docs/validation.md ("Mesh walls") quotes the figures of a run.
//!
//!     cargo test --profile opt-test -p grains --features long-tests --test scenarios mesh_discharge -- --nocapture

use crate::common;

use common::runs::{num, run_scenario};

/// Mean and standard error of the mean.
fn mean_sem(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn stl_floor_discharges_like_the_analytic_floor() {
    let rates = |name: &str| -> Vec<f64> {
        (1..=3)
            .map(|seed| {
                let set = format!("seed={seed}");
                num(&run_scenario(name, &set, &[set.as_str()]), "flow_rate")
            })
            .collect()
    };
    let (analytic, mesh) = (rates("hopper-3d"), rates("mesh-silo-3d"));
    let (ma, sa) = mean_sem(&analytic);
    let (mm, sm) = mean_sem(&mesh);
    let sigma = (sa * sa + sm * sm).sqrt();
    eprintln!("analytic {analytic:?}: {ma:.4e} ± {sa:.1e}");
    eprintln!("mesh     {mesh:?}: {mm:.4e} ± {sm:.1e}");
    eprintln!("difference {:.2} σ", (mm - ma).abs() / sigma);
    // Three standard errors of the difference: with three seeds a side the
    // errors are estimates too (Student's t, 4 degrees of freedom: |t| < 3
    // in 96 % of trials when the two silos are the same).
    assert!((mm - ma).abs() < 3.0 * sigma, "{mm} vs {ma} (σ {sigma})");
    assert!(
        mesh.iter().all(|&w| w > 0.0),
        "a mesh silo clogged: {mesh:?}"
    );
}
