//! `runner::choose`, the one place that picks what runs a scenario: each
//! scenario's method, device and dimension reach the engine of that kind,
//! and an entry that declines the GPU pipeline (the session, `check`) gets
//! the CPU engine of the same dimension.

use grains::dim::Dim;
use grains::dsmc::GasDim;
use grains::runner::choose::{choose, Runs};
use grains::scenario::load_file;
use std::path::PathBuf;

/// Names the engine it is given; runs the pipeline when `device`.
struct Name {
    device: bool,
}

impl Runs for Name {
    type Out = String;
    fn md<D: Dim>(self) -> String {
        format!("md {}", D::NAME)
    }
    fn gas<D: GasDim>(self) -> String {
        format!("dsmc {}", D::NAME)
    }
    fn device(self) -> Result<String, Self> {
        match self.device {
            true => Ok("device".into()),
            false => Err(self),
        }
    }
}

fn picked(name: &str, sets: &[&str], device: bool) -> String {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenarios/{name}.toml"));
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let loaded = load_file(&path, &sets).unwrap_or_else(|e| panic!("{name}: {e}"));
    choose(&loaded.scenario, Name { device })
}

#[test]
fn each_scenario_reaches_its_engine() {
    assert_eq!(picked("gas-cooling-2d", &[], true), "dsmc 2d");
    assert_eq!(picked("gas-cooling-3d", &[], true), "dsmc 3d");
    assert_eq!(picked("drum-2d", &[], true), "md 2d");
    assert_eq!(picked("chute-3d", &[], true), "md 3d");
    let mirror = ["run.device=mirror"];
    assert_eq!(picked("bench-chute", &mirror, true), "device");
    // Declined: the CPU engine of the scenario's own dimension.
    assert_eq!(picked("bench-chute", &mirror, false), "md 3d");
}
