//! Every flow scenario of issue 7, and their variants from materials, passes
//! `grains check` (it builds an engine, generated hopper walls and event
//! settings included), and the outlet is settable as `hopper.outlet`.

use grains::runner::check;
use grains::scenario::load_file;
use std::path::PathBuf;

const SCENARIOS: [&str; 17] = [
    "repose-2d",
    "repose-3d",
    "repose-3d-sand",
    "repose-3d-glass",
    "pour-3d-sand",
    "hopper-2d",
    "hopper-3d",
    "chute-3d",
    "pipe-2d",
    "drum-2d",
    "segregation-3d",
    "pour-3d-psd",
    "pour-inlet-3d",
    "silo-2d",
    "silo-3d-glass",
    "beverloo-3d-glass",
    "mesh-hopper-3d-glass",
];

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenarios/{name}.toml"))
}

#[test]
fn every_flow_scenario_checks() {
    for name in SCENARIOS {
        let loaded = load_file(&path(name), &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let v = check(&loaded).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(v["scenario"], name);
    }
}

#[test]
fn hopper_outlet_is_a_key_and_is_checked() {
    let loaded = load_file(&path("hopper-2d"), &["hopper.outlet=0.003".into()]).unwrap();
    assert_eq!(loaded.scenario.hopper.as_ref().unwrap().outlet, 0.003);
    let v = check(&loaded).unwrap();
    assert!(v["walls"].to_string().contains("floor-left"));
    let bad = load_file(&path("hopper-2d"), &["hopper.outlet=1.0".into()]).unwrap();
    assert!(check(&bad)
        .unwrap_err()
        .to_string()
        .contains("hopper.outlet"));
    let wall = load_file(&path("repose-2d"), &["run.events.remove_wall=nope".into()]).unwrap();
    assert!(check(&wall).unwrap_err().to_string().contains("nope"));
}
