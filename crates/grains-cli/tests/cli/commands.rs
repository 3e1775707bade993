//! End-to-end tests of the `grains` binary: bad input must exit 2 with a
//! message naming the key and what is allowed, an unstable run exits 3, and
//! a good run writes every output file. Each test works in its own
//! temporary directory with small scenarios (30 grains, 50 steps).

use crate::common;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A small 2d scenario: 30 disks on a lattice above a floor.
pub(super) const BASE: &str = r#"name = "small"
dimension = "2d"
gravity = [0.0, -9.81]

[domain]
lo = [0.0, 0.0]
hi = [0.01, 0.02]
periodic = [true, false]

[particles]
placement = "lattice"
count = 30
d0 = 1.0e-3
width = 0.2

[contact]
preset = "seed"

[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }

[run]
duration = 0.01
"#;

/// A small 3d scenario: 27 spheres in a periodic column above a floor.
pub(super) const BASE_3D: &str = r#"name = "small3d"
dimension = "3d"
gravity = [0.0, 0.0, -9.81]

[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.006, 0.006, 0.02]
periodic = [true, true, false]

[particles]
placement = "lattice"
count = 27
d0 = 1.0e-3
width = 0.2

[contact]
preset = "lammps-hooke-history"
kn = 5.0e7

[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }

[run]
duration = 0.01
"#;

const THERMO_HEADER: &str =
    "step,time,kinetic_energy,rotational_energy,granular_temperature,contacts,max_overlap";

/// A fresh directory under the system's temp dir, removed when dropped.
pub(super) struct Sandbox {
    pub(super) dir: PathBuf,
}

impl Sandbox {
    pub(super) fn new(name: &str) -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("grains-cli-test-{}-{n}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create sandbox");
        Sandbox { dir }
    }

    pub(super) fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    pub(super) fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, text).expect("write sandbox file");
        p
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

pub(super) struct Outcome {
    pub(super) code: Option<i32>,
    pub(super) stdout: String,
    pub(super) stderr: String,
}

impl Outcome {
    pub(super) fn describe(&self) -> String {
        format!(
            "exit {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.code, self.stdout, self.stderr
        )
    }

    pub(super) fn assert_no_panic(&self) {
        assert!(
            !self.stderr.contains("panicked"),
            "the binary panicked:\n{}",
            self.describe()
        );
    }

    pub(super) fn assert_code(&self, code: i32) {
        self.assert_no_panic();
        assert_eq!(self.code, Some(code), "{}", self.describe());
    }

    pub(super) fn assert_stderr_has(&self, needles: &[&str]) {
        for n in needles {
            assert!(
                self.stderr.contains(n),
                "stderr lacks {n:?}:\n{}",
                self.describe()
            );
        }
    }
}

/// Runs the binary in `cwd` with `args`.
pub(super) fn grains(cwd: &Path, args: &[&str]) -> Outcome {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("start the grains binary");
    Outcome {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

pub(super) fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

/// `base` with each `(from, to)` replaced once; `from` must occur.
pub(super) fn edited(base: &str, edits: &[(&str, &str)]) -> String {
    let mut text = base.to_string();
    for (from, to) in edits {
        assert!(text.contains(from), "edit target {from:?} not in scenario");
        text = text.replacen(from, to, 1);
    }
    text
}

fn check_json(sb: &Sandbox, file: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["check", s(file)];
    args.extend_from_slice(extra);
    let run = grains(&sb.dir, &args);
    run.assert_code(0);
    serde_json::from_str(&run.stdout)
        .unwrap_or_else(|e| panic!("check output is not JSON ({e}):\n{}", run.describe()))
}

#[test]
fn check_prints_resolved_json() {
    let sb = Sandbox::new("check");
    let file = sb.write("s.toml", BASE);
    let v = check_json(&sb, &file, &[]);
    let dt = v["dt"].as_f64().expect("dt");
    let tc = v["contact_time"].as_f64().expect("contact_time");
    assert!(dt > 0.0 && tc > 0.0, "{v}");
    // dt = "auto" is t_c / 50.
    assert!((tc / dt - 50.0).abs() < 1e-9, "{v}");
    assert_eq!(v["particles"], 30);
    assert_eq!(v["dimension"], "2d");
    assert_eq!(v["scenario"], "small");
    assert_eq!(v["contact"]["mu"], "inf");
}

#[test]
fn set_takes_effect() {
    let sb = Sandbox::new("set");
    let file = sb.write("s.toml", BASE);
    let v = check_json(&sb, &file, &["--set", "contact.mu=0.3"]);
    assert_eq!(v["contact"]["mu"].as_f64(), Some(0.3), "{v}");
    let v = check_json(
        &sb,
        &file,
        &["--set", "run.dt=1e-6", "--set", "particles.count=12"],
    );
    assert_eq!(v["dt"].as_f64(), Some(1e-6), "{v}");
    assert_eq!(v["particles"], 12, "{v}");
}

/// The `Step` field of a .vtp frame.
fn vtp_step(path: &Path) -> u64 {
    let text = std::fs::read_to_string(path).expect("read frame");
    let step = common::vtk::vtk_tokens(&text, "Step");
    assert_eq!(step.len(), 1, "Step holds one value: {step:?}");
    step[0].parse().expect("Step is an integer")
}

/// Checks the files of a finished run of `steps` steps of `particles` grains.
fn check_run_dir(out: &Path, steps: u64, particles: u64) -> Value {
    let thermo = std::fs::read_to_string(out.join("thermo.csv")).expect("thermo.csv");
    let mut lines = thermo.lines();
    assert_eq!(lines.next(), Some(THERMO_HEADER));
    let rows: Vec<&str> = lines.collect();
    assert!(rows.len() >= 2, "thermo.csv: {thermo}");
    assert!(rows[0].starts_with("0,"), "thermo.csv: {thermo}");
    let last = rows.last().unwrap();
    assert!(
        last.starts_with(&format!("{steps},")),
        "last thermo row is not step {steps}: {thermo}"
    );
    for r in &rows {
        assert_eq!(r.split(',').count(), 7, "thermo row {r:?}");
    }

    let pvd = std::fs::read_to_string(out.join("frames.pvd")).expect("frames.pvd");
    assert!(pvd.contains("type=\"Collection\""), "{pvd}");
    assert!(out.join("frames/frame_000000.vtp").is_file());
    assert_eq!(vtp_step(&out.join("frames/frame_000000.vtp")), 0);
    let files = common::vtk::pvd_files(&pvd);
    assert_eq!(files.first(), Some(&"frames/frame_000000.vtp"), "{pvd}");
    for f in &files {
        assert!(out.join(f).is_file(), "frames.pvd lists missing {f}");
    }
    let on_disk = std::fs::read_dir(out.join("frames")).unwrap().count();
    assert_eq!(
        on_disk,
        files.len(),
        "frames on disk vs listed in frames.pvd"
    );
    let final_frame = out.join(files.last().unwrap());
    assert_eq!(vtp_step(&final_frame), steps, "final frame's step");
    let vtp = std::fs::read_to_string(&final_frame).unwrap();
    assert!(
        vtp.contains(&format!("NumberOfPoints=\"{particles}\"")),
        "final frame point count"
    );

    let png = std::fs::read(out.join("final.png")).expect("final.png");
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "final.png is a PNG");

    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
            .expect("summary.json is JSON");
    for key in [
        "scenario",
        "dimension",
        "particles",
        "steps",
        "time",
        "wall_seconds",
        "ns_per_particle_step",
        "kinetic_energy",
        "rotational_energy",
    ] {
        assert!(
            summary.get(key).is_some(),
            "summary.json lacks {key}: {summary}"
        );
    }
    assert_eq!(summary["steps"], steps);
    assert_eq!(summary["particles"], particles);
    let time = summary["time"].as_f64().unwrap();
    let dt = summary["dt"].as_f64().unwrap();
    assert!((time - steps as f64 * dt).abs() <= 1e-9 * time, "{summary}");
    assert!(summary["kinetic_energy"].as_f64().unwrap().is_finite());
    summary
}

#[test]
fn run_writes_every_output() {
    let sb = Sandbox::new("run");
    let file = sb.write("s.toml", BASE);
    let out = sb.path("out");
    let run = grains(
        &sb.dir,
        &[
            "run",
            s(&file),
            "--steps",
            "50",
            "--quiet",
            "--out",
            s(&out),
        ],
    );
    run.assert_code(0);
    assert!(
        run.stdout.is_empty() && run.stderr.is_empty(),
        "--quiet: {}",
        run.describe()
    );
    let summary = check_run_dir(&out, 50, 30);
    assert_eq!(summary["scenario"], "small");
    assert_eq!(summary["dimension"], "2d");
}

#[test]
fn run_prints_the_summary_unless_quiet() {
    let sb = Sandbox::new("run-loud");
    let file = sb.write("s.toml", BASE);
    let out = sb.path("out");
    let run = grains(
        &sb.dir,
        &[
            "run",
            s(&file),
            "--steps",
            "50",
            "--out",
            s(&out),
            "--threads",
            "1",
        ],
    );
    run.assert_code(0);
    let printed: Value = serde_json::from_str(&run.stdout).expect("summary on stdout");
    let written: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(printed["steps"], written["steps"]);
    run.assert_stderr_has(&[s(&out)]);
}

#[test]
fn run_3d() {
    let sb = Sandbox::new("run3d");
    let file = sb.write("s.toml", BASE_3D);
    let v = check_json(&sb, &file, &[]);
    assert_eq!(v["dimension"], "3d");
    let out = sb.path("out");
    let run = grains(
        &sb.dir,
        &[
            "run",
            s(&file),
            "--steps",
            "50",
            "--quiet",
            "--out",
            s(&out),
        ],
    );
    run.assert_code(0);
    check_run_dir(&out, 50, 27);
}

#[test]
fn builtin_default_runs() {
    let sb = Sandbox::new("default");
    let out = sb.path("out");
    let run = grains(
        &sb.dir,
        &["run", "--steps", "20", "--quiet", "--out", s(&out)],
    );
    run.assert_code(0);
    let summary = check_run_dir(&out, 20, 200);
    assert_eq!(summary["scenario"], "seed-convection-modulated");
}

#[test]
fn unstable_run_exits_3_and_names_dt() {
    let sb = Sandbox::new("unstable");
    let cases: [(&str, &[(&str, &str)]); 3] = [
        // A time step far above the contact time.
        (
            "big_dt",
            &[("duration = 0.01", "duration = 0.01\ndt = 1.0e-3")],
        ),
        // Soft contacts with a big explicit step (undamped, so the step is
        // not refused up front for the damping).
        (
            "soft",
            &[
                (
                    "preset = \"seed\"",
                    "preset = \"seed\"\nkn = 1.0e3\ngamma_n = 0.0",
                ),
                ("duration = 0.01", "duration = 0.1\ndt = 1.0e-2"),
            ],
        ),
        // Grains thrown at each other at 1 km/s.
        (
            "fast",
            &[("width = 0.2", "width = 0.2\nrandom_velocity = 1.0e3")],
        ),
    ];
    for (name, edits) in cases {
        let text = edited(BASE, edits);
        let file = sb.write(&format!("{name}.toml"), &text);
        let out = sb.path(&format!("out-{name}"));
        let run = grains(
            &sb.dir,
            &[
                "run",
                s(&file),
                "--steps",
                "50",
                "--quiet",
                "--out",
                s(&out),
            ],
        );
        run.assert_code(3);
        run.assert_stderr_has(&["unstable", "dt"]);
    }
}

#[test]
fn unwritable_output_dir() {
    let sb = Sandbox::new("unwritable");
    let file = sb.write("s.toml", BASE);
    let blocker = sb.write("a-file", "not a directory");
    let out = blocker.join("out");
    let run = grains(
        &sb.dir,
        &[
            "run",
            s(&file),
            "--steps",
            "50",
            "--quiet",
            "--out",
            s(&out),
        ],
    );
    run.assert_no_panic();
    assert!(
        run.code.is_some_and(|c| c != 0),
        "expected failure: {}",
        run.describe()
    );
    run.assert_stderr_has(&[s(&out)]);
}

#[test]
fn bad_command_line_is_exit_2() {
    let sb = Sandbox::new("cli");
    let file = sb.write("s.toml", BASE);
    for args in [
        vec!["run", s(&file), "--steps", "many"],
        vec!["run", s(&file), "--threads", "0", "--steps", "5"],
        vec!["frobnicate"],
    ] {
        let run = grains(&sb.dir, &args);
        run.assert_code(2);
    }
}

/// `grains bench --json` splits the time per particle-step into the
/// phases of the step; the phases and the rest add up to the whole.
#[test]
fn bench_reports_time_per_phase() {
    let sb = Sandbox::new("bench-phases");
    let run = grains(
        &sb.dir,
        &[
            "bench",
            "bed3d",
            "--particles",
            "2000",
            "--steps",
            "40",
            "--threads",
            "1",
            "--json",
        ],
    );
    run.assert_code(0);
    let line: Value = serde_json::from_str(run.stdout.trim()).expect("one JSON line");
    let phases = &line["phase_ns_per_particle_step"];
    let mut sum = 0.0;
    for key in ["contacts", "fields", "integrate", "neighbors", "other"] {
        let ns = phases[key].as_f64().unwrap_or(-1.0);
        assert!(ns >= 0.0, "{key}: {line}");
        sum += ns;
    }
    // The grains touch and fall: contacts, gravity and integration cost time.
    for key in ["contacts", "fields", "integrate"] {
        assert!(phases[key].as_f64().unwrap() > 0.0, "{key}: {line}");
    }
    let whole = line["ns_per_particle_step"].as_f64().unwrap();
    assert!(
        (sum - whole).abs() <= 1e-6 * whole,
        "{sum} vs {whole}: {line}"
    );
}
