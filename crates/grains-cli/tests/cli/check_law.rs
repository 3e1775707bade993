//! Options a mode would ignore, refused by name.

use std::path::{Path, PathBuf};
use std::process::Command;

fn grains(cwd: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("start the grains binary");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scratch(name: &str, text: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("grains-check-law-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.toml");
    std::fs::write(&file, text).unwrap();
    (dir, file)
}

/// A DSMC scenario writes no dump: `output.dump` there is an input error
/// naming the key, not a silent no-op.
#[test]
fn dsmc_refuses_output_dump_by_name() {
    let gas = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/gas-cooling-2d.toml");
    let text = std::fs::read_to_string(&gas).unwrap();
    let (dir, file) = scratch("dsmc-dump", &text);
    let f = file.to_str().unwrap();
    let (code, out, err) = grains(&dir, &["check", f, "--set", "output.dump=true"]);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(err.contains("output.dump") && err.contains("dsmc"), "{err}");
    let out_dir = dir.join("out");
    let (code, _, err) = grains(
        &dir,
        &[
            "run",
            f,
            "--set",
            "output.dump=true",
            "--steps",
            "2",
            "--quiet",
            "--out",
            out_dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("output.dump"), "{err}");
    let (code, out, err) = grains(&dir, &["check", f]);
    assert_eq!(code, Some(0), "{out}{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
