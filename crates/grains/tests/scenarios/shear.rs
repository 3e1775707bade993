//! `scenarios/shear-2d.toml` (Lees–Edwards shear cell) checks and runs,
//! and bad `domain.shear` keys are refused by name.

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
    // Too short across the gradient for three cells of the reach.
    let e = refused(&["domain.hi=[0.030, 0.003]", "particles.count=10"]);
    assert!(e.contains("gradient axis"), "{e}");
}
