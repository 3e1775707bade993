//! `scenarios/shear-2d.toml` (Lees–Edwards shear cell) checks and runs
//! with its rheology, so do its fixed-pressure twin and `shear-3d.toml`,
//! and bad `domain.shear` keys (and `measure.rheology` without them) are
//! refused by name.

use crate::common::runs::run_scenario;
use grains::runner::check;
use grains::scenario::load_file;
use std::path::PathBuf;

fn path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/shear-2d.toml")
}

fn refused(sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    match load_file(&path(), &sets) {
        Err(e) => e.to_string(),
        Ok(l) => check(&l).expect_err("refused").to_string(),
    }
}

#[test]
fn the_shear_cell_checks_and_runs() {
    let loaded = load_file(&path(), &[]).unwrap();
    let v = check(&loaded).unwrap();
    assert_eq!(v["scenario"], "shear-2d");
    let s = run_scenario("shear-2d", "short", &["run.duration=0.02"]);
    assert!(s.to_string().contains("shear-2d"), "{s}");
    // measure.rheology: 500 disks of mean squared diameter d0² (1 + 0.4²/12)
    // in a 30 d0 square cover π/4 × 500 × 1.0133 / 900 = 0.442 of it, to
    // the scatter of 500 drawn diameters (0.5 %).
    let f = |k: &str| s[k].as_f64().unwrap_or(f64::NAN);
    assert!(s["rheology_samples"].as_u64().unwrap_or(0) >= 1, "{s}");
    assert!((f("packing_fraction") - 0.442).abs() < 0.01, "{s}");
    assert!(
        f("pressure") > 0.0 && f("mu").is_finite() && f("inertial_number") > 0.0,
        "{s}"
    );
}

#[test]
fn bad_shear_keys_are_refused_by_name() {
    let cases: [(&[&str], &str); 7] = [
        (&["domain.periodic=[true, false]"], "must be periodic"),
        (&["domain.shear.gradient_axis=\"x\""], "same axis"),
        (&["domain.shear.gradient_axis=\"z\""], "allowed in 2D"),
        (
            &[
                "domain.shear.axis=\"y\"",
                "domain.shear.gradient_axis=\"x\"",
            ],
            "only \"x\"",
        ),
        (&["method=\"dsmc\""], "DSMC"),
        (&["run.device=\"mirror\""], "GPU"),
        (&["domain.shear.speed=1.0"], "speed"),
    ];
    for (sets, want) in cases {
        let e = refused(sets);
        assert!(e.contains(want), "{sets:?}: {e}");
    }
    let e = refused(&["domain.shear.rate=nan"]);
    assert!(e.contains("domain.shear.rate"), "{e}");
    // The rheology needs a shear rate.
    let other = path().with_file_name("repose-2d.toml");
    let e = load_file(&other, &["measure.rheology=true".to_string()]).unwrap_err();
    assert!(
        e.to_string()
            .contains("measure.rheology needs a sheared box"),
        "{e}"
    );
    // Too short across the gradient for three cells of the reach.
    let e = refused(&["domain.hi=[0.030, 0.003]", "particles.count=10"]);
    assert!(e.contains("gradient axis"), "{e}");
}

/// The fixed-pressure cells check; `shear-2d-pressure` closes its loose
/// start (area fraction 0.44) within its 0.5 s of relaxation to a dense
/// flowing packing (above 0.75; the sweep of `shear-cell.md` measures
/// 0.82 at this rate) whose pressure tr σ/2 is near the set σ_yy = 0.1 N/m
/// (within 50 %: a 0.02 s window of a fluctuating stress, and tr σ/2 is
/// not σ_yy).
#[test]
fn the_fixed_pressure_cells_check_and_run() {
    for name in ["shear-2d-pressure", "shear-3d"] {
        let loaded = load_file(&path().with_file_name(format!("{name}.toml")), &[]).unwrap();
        let v = check(&loaded).unwrap();
        assert_eq!(v["scenario"], name);
    }
    let s = run_scenario("shear-2d-pressure", "short", &["run.duration=0.02"]);
    let f = |k: &str| s[k].as_f64().unwrap_or(f64::NAN);
    assert!(f("packing_fraction") > 0.75, "{s}");
    assert!((f("pressure") - 0.1).abs() < 0.05, "{s}");
}

#[test]
fn bad_pressure_keys_are_refused_by_name() {
    let cases: [(&[&str], &str); 5] = [
        (
            &["domain.shear.pressure=1.0"],
            "needs domain.shear.relax_time",
        ),
        (
            &["domain.shear.pressure=-1.0", "domain.shear.relax_time=0.1"],
            "domain.shear.pressure = -1",
        ),
        (
            &["domain.shear.pressure=1.0", "domain.shear.relax_time=0.0"],
            "domain.shear.relax_time = 0",
        ),
        (
            &["domain.shear.relax_time=0.1"],
            "give domain.shear.pressure",
        ),
        (
            &[
                "domain.shear.pressure=1.0",
                "domain.shear.relax_time=0.1",
                "domain.shear.pressure_every=0",
            ],
            "pressure_every = 0",
        ),
    ];
    for (sets, want) in cases {
        let e = refused(sets);
        assert!(e.contains(want), "{sets:?}: {e}");
    }
}
