//! The servo compression scenarios pass `grains check`, and a servo's bad
//! keys are refused with the wall, the key and what it takes.

use grains::runner::check;
use grains::scenario::load_file;
use std::path::PathBuf;

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenarios/{name}.toml"))
}

#[test]
fn the_compression_scenarios_check() {
    for name in ["compress-3d", "compress-2d"] {
        let loaded = load_file(&path(name), &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let v = check(&loaded).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(v["scenario"], name);
    }
}

#[test]
fn a_servos_bad_keys_are_refused_by_name() {
    let refused = |set: &str| {
        let loaded = load_file(&path("compress-3d"), &[set.into()]);
        match loaded {
            Err(e) => e.to_string(),
            Ok(l) => check(&l).unwrap_err().to_string(),
        }
    };
    let e = refused("walls.1.motion.gain=-1.0");
    assert!(
        e.contains("lid") && e.contains("gain") && e.contains("m/(s·Pa)"),
        "{e}"
    );
    let e = refused("walls.1.motion.max_speed=0.0");
    assert!(e.contains("lid") && e.contains("max_speed"), "{e}");
    // An unknown key: serde lists the servo's keys.
    let e = refused("walls.1.motion.relax=0.3");
    assert!(e.contains("relax") && e.contains("max_speed"), "{e}");
}
