//! `grains cg RUN_DIR`: the fields of a short bed-fields-2d run computed
//! again with another kernel and grid, and the refusals a user can meet
//! (bad options, a run without fields or contacts).

use std::path::PathBuf;
use std::process::Command;

fn grains(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(args)
        .output()
        .expect("start grains");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code(), text)
}

/// 0.01 s of settling and 0.004 s measured, a frame and a field sample
/// every 200 steps; `extra` further `--set`s.
fn bed_run(tag: &str, extra: &[&str]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("grains-cg-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scenario = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/bed-fields-2d.toml"
    );
    let mut args = vec!["run", scenario, "--quiet", "--out", dir.to_str().unwrap()];
    let sets = [
        "run.dt=1e-5",
        "run.relax=0.01",
        "run.duration=0.004",
        "output.every=0.002",
        "output.picture=false",
        "measure.fields.every=200",
    ];
    for s in sets.iter().chain(extra) {
        args.extend(["--set", s]);
    }
    let (code, text) = grains(&args);
    assert_eq!(code, Some(0), "{text}");
    dir
}

#[test]
fn cg_recomputes_with_another_kernel_and_names_bad_input() {
    let dir = bed_run("lucy", &[]);
    let d = dir.to_str().unwrap();
    let out = dir.join("again");
    let o = out.to_str().unwrap();
    let (code, text) = grains(&["cg", d, "--kernel", "lucy", "--grid", "box", "--out", o]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("1 windows from 2 frames"), "{text}");
    assert!(out.join("fields/fields_00000.csv").is_file());
    let settings = std::fs::read_to_string(out.join("fields.json")).unwrap();
    assert!(settings.contains("\"lucy\""), "{settings}");

    for (args, says) in [
        (vec!["--kernel", "cubic"], "--kernel cubic: allowed gauss"),
        (vec!["--width", "0"], "--width 0: must be positive"),
        (vec!["--grid", "z:10"], "--grid z:10"),
    ] {
        let mut all = vec!["cg", d];
        all.extend(args);
        let (code, text) = grains(&all);
        assert_eq!(code, Some(2), "{text}");
        assert!(text.contains(says), "{text}");
    }
    let _ = std::fs::remove_dir_all(&dir);

    // A run that wrote no contacts: named with what it must have written.
    let dir = bed_run("nocontacts", &["output.contacts=false"]);
    let (code, text) = grains(&["cg", dir.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{text}");
    assert!(
        text.contains("contacts.pvd") && text.contains("output.contacts = true"),
        "{text}"
    );
    // Nor fields.
    std::fs::remove_file(dir.join("fields.json")).unwrap();
    let (code, text) = grains(&["cg", dir.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{text}");
    assert!(
        text.contains("fields.json") && text.contains("[measure.fields]"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
