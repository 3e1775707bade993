//! Progress lines: `grains sweep` reports how far each running variant got,
//! each line naming its variant.

use std::path::Path;
use std::process::Command;

#[test]
fn sweep_reports_progress_within_a_variant() {
    let dir = std::env::temp_dir().join(format!("grains-sweep-progress-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/seed-convection-modulated.toml");
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_grains"))
            .args(["sweep", scenario.to_str().unwrap(), "--vary", "seed=1,2"])
            .args([
                "--steps",
                "600",
                "--out",
                dir.to_str().unwrap(),
                "--overwrite",
            ])
            .args(extra)
            .output()
            .expect("start grains");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = run(&["--progress-every", "0"]);
    assert_eq!(code, Some(0), "{err}");
    for v in ["seed=1", "seed=2"] {
        // A line at every report (256 steps), and at the end.
        for step in ["step 256/600", "step 512/600", "step 600/600"] {
            let line = format!("grains: [{v}] run: {step} ");
            assert!(err.contains(&line), "no {line:?} in:\n{err}");
        }
    }
    // By default at most one line per 10 s of a variant: none in so short a run.
    let (code, err) = run(&[]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("step 256/600"), "{err}");
    let (code, err) = run(&["--progress-every", "inf"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--progress-every"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
