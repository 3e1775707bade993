//! The clump scenarios pass `grains check`: their shapes, mass properties
//! and bodies are reported (the engine adds the bodies when run).

use grains::runner::check;
use grains::scenario::load_file;
use std::path::PathBuf;

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenarios/{name}.toml"))
}

#[test]
fn clump_scenarios_check() {
    for (name, bodies, shapes) in [
        ("repose-3d-clumps", 240, 2),
        ("hopper-3d-rods", 500, 1),
        ("pour-2d-clumps", 200, 2),
    ] {
        let loaded = load_file(&path(name), &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let v = check(&loaded).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(v["scenario"], name);
        let c = &v["clumps"];
        assert_eq!(c["total"], bodies, "{name}: {c}");
        assert_eq!(c["shapes"].as_array().unwrap().len(), shapes, "{name}: {c}");
        eprintln!("{name}: {}", serde_json::to_string(c).unwrap());
    }
}
