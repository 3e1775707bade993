//! `measure.impact` on the shipped impact scenarios (Chung & Ooi 2011,
//! tests 1 and 2) against Hertz's closed forms for an elastic head-on
//! impact: δ_max = (15 m* v² / (16 E* √R*))^{2/5}, F_max = (4/3) E* √R*
//! δ_max^{3/2}, t_c = 2.94327 δ_max / v; and the measured restitution
//! against the material's e.
//!
//! Tolerances: the scenarios run at dt ≈ t_c/2000. δ_max and F_max are
//! sampled once a step at Verlet's accuracy, (π dt/t_c)² ≈ 2.5e-6
//! (measured 3e-7); the contact time is measured from the steps at which
//! the contact opens and closes, within a step of t_c/2000 = 5e-4 at worst
//! (measured 6e-5): all three to 1e-4, where a partner's Poisson ratio in
//! place of the grain's (0.85 % on E*, 0.3 % on δ_max for alumina) fails.
//! Elastic, the rebound is the approach speed to 1e-6 (measured 1e-9).
//! Damped, velocity Verlet takes the damping force at the predicted
//! velocity, an error first order in dt/t_c: e within 5e-4 (measured
//! 2.7e-4 at e = 0.3).

use super::common::runs::{read_csv, run_scenario, run_scenario_kept};

/// Hertz's (δ_max, F_max, t_c) for reduced radius `r`, mass `m`, modulus
/// `e` and impact speed `v`.
fn hertz(r: f64, m: f64, e: f64, v: f64) -> [f64; 3] {
    let d = (15.0 * m * v * v / (16.0 * e * r.sqrt())).powf(0.4);
    [d, 4.0 / 3.0 * e * r.sqrt() * d.powf(1.5), 2.94327 * d / v]
}

fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got / want - 1.0).abs() < tol,
        "{what}: {got:e} against {want:e} ({:+.3}%)",
        100.0 * (got / want - 1.0)
    );
}

fn measured(s: &serde_json::Value) -> [f64; 4] {
    let f = |k: &str| s[k].as_f64().unwrap_or_else(|| panic!("{k} missing: {s}"));
    [
        f("impact_max_overlap"),
        f("impact_peak_force"),
        f("impact_contact_time"),
        f("impact_restitution"),
    ]
}

/// Test 2: the Al-alloy sphere on the rigid plane; impacts.csv has one
/// collision with the summary's figures.
#[test]
fn sphere_on_plane_matches_hertz() {
    let r = 0.1;
    let m = 2700.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let want = hertz(r, m, 7.0e10 / (1.0 - 0.33 * 0.33), 0.2);
    let (s, out) = run_scenario_kept("impact-sphere-plane", "hertz", &[]);
    let got = measured(&s);
    for (k, what) in ["largest overlap", "peak force", "duration"]
        .iter()
        .enumerate()
    {
        close(got[k], want[k], 1e-4, what);
    }
    close(got[3], 1.0, 1e-6, "restitution");
    assert!(s["impact_rebound_angle_deg"].as_f64().unwrap().abs() < 1e-6);
    let rows = read_csv(&out.join("impacts.csv"));
    let _ = std::fs::remove_dir_all(&out);
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(rows[0][3], got[0]);
}

/// Test 1: two glass spheres, each at 10 m/s (relative speed 20 m/s).
#[test]
fn sphere_on_sphere_matches_hertz() {
    let r = 0.01;
    let m = 2800.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let e_star = 4.8e10 / (2.0 * (1.0 - 0.2 * 0.2));
    let want = hertz(0.5 * r, 0.5 * m, e_star, 20.0);
    let got = measured(&run_scenario("impact-sphere-sphere", "hertz", &[]));
    for (k, what) in ["largest overlap", "peak force", "duration"]
        .iter()
        .enumerate()
    {
        close(got[k], want[k], 1e-4, what);
    }
    close(got[3], 1.0, 1e-6, "restitution");
}

/// The measured restitution is the material's (Tsuji damping), on a plane
/// and between spheres, for e = 0.3 and 0.7.
#[test]
fn measured_restitution_is_the_materials() {
    for e in [0.3, 0.7] {
        let set = format!("materials.0.restitution={e}");
        for name in ["impact-sphere-plane", "impact-sphere-sphere"] {
            // Sphere on plane: the mixing rule takes the smaller restitution.
            let got = measured(&run_scenario(name, "e", &[&set]))[3];
            close(got, e, 5e-4, &format!("{name} e = {e}"));
        }
    }
}
