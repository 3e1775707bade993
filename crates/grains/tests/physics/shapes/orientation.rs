//! Random orientations are uniform on rotations (Haar measure): a body
//! axis turned by them points uniformly on the sphere, so its cos θ is
//! uniform on [−1, 1]; and the rotation angle ψ has the density
//! (1 − cos ψ)/π on [0, π] (Miles 1965, "On random rotations in R³",
//! Biometrika 52), CDF (ψ − sin ψ)/π. Each is checked by a
//! Kolmogorov–Smirnov test at the 1 % level on 10⁴ draws: the critical
//! distance is 1.628/√n (the asymptotic Kolmogorov quantile, accurate to
//! well under 1 % at this n). A naive draw of Euler angles uniform in
//! their ranges fails the same tests.

use glam::{DQuat, DVec3};
use grains::scenario::clumps::{random_orientation, STREAM_ORIENTATIONS};
use grains::scenario::placement::stream;
use rand::Rng;
use std::f64::consts::PI;

const N: usize = 10_000;

/// The largest distance between the empirical CDF of `xs` and `cdf`.
fn ks(mut xs: Vec<f64>, cdf: impl Fn(f64) -> f64) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len() as f64;
    xs.iter()
        .enumerate()
        .map(|(i, &x)| {
            let f = cdf(x);
            (f - i as f64 / n).abs().max((f - (i + 1) as f64 / n).abs())
        })
        .fold(0.0, f64::max)
}

fn critical() -> f64 {
    1.628 / (N as f64).sqrt()
}

/// (KS distance of cos θ of the body z axis, KS distance of ψ).
fn distances(draws: &[DQuat]) -> (f64, f64) {
    let cos: Vec<f64> = draws.iter().map(|q| (*q * DVec3::Z).z).collect();
    let psi: Vec<f64> = draws
        .iter()
        .map(|q| 2.0 * q.w.abs().min(1.0).acos())
        .collect();
    (
        ks(cos, |c| (c + 1.0) / 2.0),
        ks(psi, |p| (p - p.sin()) / PI),
    )
}

#[test]
fn shoemake_draws_are_uniform_on_rotations() {
    for seed in [1, 2, 3] {
        let mut rng = stream(seed, STREAM_ORIENTATIONS);
        let draws: Vec<DQuat> = (0..N).map(|_| random_orientation(&mut rng, 3)).collect();
        for q in &draws {
            assert!((q.length() - 1.0).abs() < 1e-12);
        }
        let (dc, dp) = distances(&draws);
        eprintln!(
            "seed {seed}: KS cos θ {dc:.4}, ψ {dp:.4} (1 % critical {:.4})",
            critical()
        );
        assert!(dc < critical() && dp < critical(), "seed {seed}: {dc} {dp}");
    }
}

#[test]
fn naive_euler_angles_fail_the_test() {
    let mut rng = stream(1, 99);
    let draws: Vec<DQuat> = (0..N)
        .map(|_| {
            let (a, b, c): (f64, f64, f64) = (rng.gen(), rng.gen(), rng.gen());
            DQuat::from_euler(glam::EulerRot::ZYZ, 2.0 * PI * a, PI * b, 2.0 * PI * c)
        })
        .collect();
    let (dc, dp) = distances(&draws);
    eprintln!("naive Euler angles: KS cos θ {dc:.4}, ψ {dp:.4}");
    assert!(dc > critical(), "{dc}");
}

#[test]
fn two_dimensional_turns_are_uniform_about_z() {
    let mut rng = stream(7, STREAM_ORIENTATIONS);
    let angles: Vec<f64> = (0..N)
        .map(|_| {
            let q = random_orientation(&mut rng, 2);
            assert!(q.x == 0.0 && q.y == 0.0);
            let v = q * DVec3::X;
            v.y.atan2(v.x).rem_euclid(2.0 * PI)
        })
        .collect();
    let d = ks(angles, |a| a / (2.0 * PI));
    assert!(d < critical(), "{d}");
}
