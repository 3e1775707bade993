//! Runs a researcher can trust and change: output folders that never mix
//! two runs, resuming from any folder, input files checked by content, a
//! restart under changed keys that gives the same bits as a straight run
//! whose scenario switched at that step, and a closed pipe that ends the
//! process quietly.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// 40 disks held by a gate above a floor; `walls.1.remove_at` opens it.
/// Velocity Verlet, dt fixed, 500 steps between outputs.
const SCENARIO: &str = r#"name = "restart"
dimension = "2d"
gravity = [0.0, -9.81]

[domain]
lo = [0.0, -0.003]
hi = [0.01, 0.02]
periodic = [true, false]

[particles]
placement = "lattice"
count = 40
d0 = 1.0e-3
width = 0.2
random_velocity = 0.05
region = { lo = [0.0, 0.0015], hi = [0.01, 0.02] }

[contact]
preset = "lammps-hooke-history"
kn = 2.0e3

[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, -0.002], normal = [0.0, 1.0] }

[[walls]]
name = "gate"
shape = { type = "plane", point = [0.0, 0.001], normal = [0.0, 1.0] }

[run]
integrator = "verlet"
dt = 2.0e-6
duration = 0.02

[output]
every = 0.001
picture = false
"#;

struct Sandbox(PathBuf);

impl Sandbox {
    fn new(name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("grains-restart-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let sb = Sandbox(d);
        std::fs::write(sb.path("s.toml"), SCENARIO).unwrap();
        sb
    }
    fn path(&self, n: &str) -> PathBuf {
        self.0.join(n)
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `grains ARGS` in folder `cwd`; never a panic.
fn grains_in(cwd: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .current_dir(cwd)
        .stdin(Stdio::null())
        .args(args)
        .output()
        .expect("start grains");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic:\n{err}");
    out
}

fn ok(o: &Output) {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The input error (exit 2) of `o`, its message.
fn refused(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{err}");
    err
}

/// The thermo rows of `dir` from step `from` on.
fn rows_from(dir: &Path, from: u64) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("thermo.csv")).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| l.split(',').next().unwrap().parse::<f64>().unwrap() >= from as f64)
        .map(str::to_string)
        .collect()
}

/// The frame files frames.pvd lists, in order.
fn listed_frames(dir: &Path) -> Vec<String> {
    let pvd = std::fs::read_to_string(dir.join("frames.pvd")).unwrap();
    pvd.split("file=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap().to_string())
        .collect()
}

#[test]
fn a_second_run_never_mixes_with_the_first() {
    let sb = Sandbox::new("folders");
    let run = |extra: &[&str]| {
        let mut a = vec!["run", "s.toml", "--quiet"];
        a.extend_from_slice(extra);
        grains_in(&sb.0, &a)
    };
    // Without --out: runs/restart, then runs/restart-2, said on stderr.
    ok(&run(&["--steps", "1000"]));
    let o = grains_in(&sb.0, &["run", "s.toml", "--steps", "500"]);
    ok(&o);
    assert!(String::from_utf8_lossy(&o.stderr).contains("restart-2"));
    assert!(sb.path("runs/restart/thermo.csv").is_file());
    assert!(sb.path("runs/restart-2/thermo.csv").is_file());

    // A named folder that holds a run is refused, and left as it was.
    ok(&run(&["--steps", "2000", "--out", "x"]));
    let before = listed_frames(&sb.path("x"));
    assert_eq!(before.len(), 5, "{before:?}");
    let err = refused(&run(&["--steps", "500", "--out", "x"]));
    assert!(err.contains("--overwrite") && err.contains('x'), "{err}");
    assert_eq!(listed_frames(&sb.path("x")), before);

    // --overwrite: the old frames are gone, not only unlisted.
    std::fs::write(sb.path("x/notes.txt"), "mine").unwrap();
    ok(&run(&["--steps", "500", "--out", "x", "--overwrite"]));
    let listed = listed_frames(&sb.path("x"));
    assert_eq!(listed.len(), 2, "{listed:?}");
    let on_disk = std::fs::read_dir(sb.path("x/frames")).unwrap().count();
    assert_eq!(on_disk, listed.len());
    assert!(sb.path("x/notes.txt").is_file());
}

#[test]
fn a_run_folder_resumes_from_anywhere_and_checks_its_inputs() {
    let sb = Sandbox::new("anywhere");
    // The scenario reads its grains from a file beside it: a CSV of 12
    // spheres of two sizes above a floor.
    let mut data = String::from("x,y,z,diameter\n");
    for k in 0..12 {
        let (x, y) = (
            (k % 4) as f64 * 2.5e-3 - 4e-3,
            (k / 4) as f64 * 2.5e-3 - 3e-3,
        );
        let d = if k % 2 == 0 { 1.0e-3 } else { 1.4e-3 };
        data.push_str(&format!(
            "{x:e},{y:e},{:e},{d:e}\n",
            -3.0e-3 + 1.0e-4 * k as f64
        ));
    }
    std::fs::create_dir_all(sb.path("in")).unwrap();
    std::fs::write(sb.path("in/grains.csv"), &data).unwrap();
    let from_file = r#"name = "from-file"
dimension = "3d"
gravity = [0.0, 0.0, -9.81]
[domain]
lo = [-0.01, -0.01, -0.01]
hi = [0.01, 0.01, 0.01]
[particles]
placement = "file"
file = "grains.csv"
[contact]
preset = "lammps-hooke-history"
kn = 2.0e3
[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0, -0.005], normal = [0.0, 0.0, 1.0] }
[run]
dt = 2.0e-6
duration = 0.001
"#;
    std::fs::write(sb.path("in/s.toml"), from_file).unwrap();
    ok(&grains_in(
        &sb.0,
        &[
            "run",
            "in/s.toml",
            "--out",
            "v",
            "--steps",
            "200",
            "--quiet",
        ]
        .into_iter()
        .chain(["--checkpoint-every", "100steps"])
        .collect::<Vec<_>>(),
    ));
    // The run folder moved, resumed from yet another folder.
    std::fs::create_dir_all(sb.path("moved")).unwrap();
    std::fs::create_dir_all(sb.path("elsewhere")).unwrap();
    std::fs::rename(sb.path("v"), sb.path("moved/v")).unwrap();
    let resume = |extra: &[&str]| {
        let mut a = vec!["resume", "../moved/v", "--steps", "50", "--quiet"];
        a.extend_from_slice(extra);
        grains_in(&sb.path("elsewhere"), &a)
    };
    ok(&resume(&[]));
    // The input file changed: refused by key, unless allowed.
    data.push_str("# edited\n");
    std::fs::write(sb.path("in/grains.csv"), &data).unwrap();
    let err = refused(&resume(&[]));
    assert!(
        err.contains("particles.file") && err.contains("grains.csv") && err.contains("changed"),
        "{err}"
    );
    ok(&resume(&["--allow-changed-inputs"]));
}

#[test]
fn a_restart_equals_a_run_whose_scenario_switched_at_that_step() {
    let sb = Sandbox::new("switch");
    let g = |args: &[&str]| grains_in(&sb.0, args);
    // Straight: the gate opens at t = 0.01 s, step 5000.
    ok(&g(&[
        "run",
        "s.toml",
        "--out",
        "straight",
        "--steps",
        "10000",
        "--quiet",
        "--set",
        "walls.1.remove_at=0.01",
    ]));
    // The gate closed for 5000 steps, checkpointed there, then a restart
    // that opens it at the same time.
    ok(&g(&[
        "run",
        "s.toml",
        "--out",
        "closed",
        "--steps",
        "5000",
        "--quiet",
        "--checkpoint-every",
        "5000steps",
    ]));
    let o = g(&[
        "resume",
        "closed",
        "--out",
        "opened",
        "--steps",
        "5000",
        "--set",
        "walls.1.remove_at=0.01",
    ]);
    ok(&o);
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(said.contains("walls.1.remove_at"), "{said}");
    let (a, b) = (
        rows_from(&sb.path("straight"), 5000),
        rows_from(&sb.path("opened"), 0),
    );
    assert_eq!(a.len(), 11);
    assert_eq!(a, b, "thermo rows from step 5000 on");
    // The change acted: a restart without it ends elsewhere.
    ok(&g(&[
        "resume", "closed", "--out", "kept", "--steps", "5000", "--quiet",
    ]));
    let kept = rows_from(&sb.path("kept"), 0);
    assert_eq!(kept[0], a[0]);
    assert_ne!(kept[10], a[10]);
    // The last frames are the same bytes.
    let last = |dir: &str| {
        let f = listed_frames(&sb.path(dir)).pop().unwrap();
        std::fs::read(sb.path(dir).join(f)).unwrap()
    };
    assert!(last("straight") == last("opened"), "last frames differ");
    // The checkpoint's own run is left as it was.
    assert_eq!(rows_from(&sb.path("closed"), 0).len(), 11);

    // `grains run NEW.toml --from`: the same restart from a scenario file.
    let opened = SCENARIO.replace(
        "normal = [0.0, 1.0] }\n\n[run]",
        "normal = [0.0, 1.0] }\nremove_at = 0.01\n\n[run]",
    );
    std::fs::write(sb.path("opened.toml"), opened).unwrap();
    ok(&g(&[
        "run",
        "opened.toml",
        "--from",
        "closed",
        "--out",
        "from",
        "--steps",
        "5000",
        "--quiet",
    ]));
    assert_eq!(rows_from(&sb.path("from"), 0), a);
}

#[test]
fn a_restart_refuses_what_the_state_is_made_of() {
    let sb = Sandbox::new("refuse");
    let g = |args: &[&str]| grains_in(&sb.0, args);
    ok(&g(&[
        "run",
        "s.toml",
        "--out",
        "c",
        "--steps",
        "100",
        "--quiet",
        "--checkpoint-every",
        "100steps",
    ]));
    for (set, key) in [
        ("particles.count=41", "particles.count"),
        ("domain.hi=[0.02, 0.02]", "domain.hi"),
        ("run.integrator=\"gear5\"", "run.integrator"),
        ("walls.1.shape.point=[0.0, 0.002]", "walls.1.shape.point"),
    ] {
        let err = refused(&g(&["resume", "c", "--out", "d", "--set", set]));
        assert!(err.contains(&format!("`{key}")), "{set}: {err}");
    }
    // An option that would do nothing says so.
    let err = refused(&g(&[
        "run",
        "s.toml",
        "--out",
        "z",
        "--allow-changed-inputs",
    ]));
    assert!(err.contains("--from"), "{err}");
    // A changed scenario needs a folder of its own.
    let err = refused(&g(&["resume", "c", "--set", "contact.kn=1000.0"]));
    assert!(err.contains("--out"), "{err}");
    // The law, gravity and time step may change under Verlet.
    ok(&g(&[
        "resume",
        "c",
        "--out",
        "d",
        "--steps",
        "100",
        "--quiet",
        "--set",
        "contact.kn=1000.0",
        "--set",
        "gravity=[0.0, -3.0]",
        "--set",
        "run.dt=1.0e-6",
    ]));
    let rows = rows_from(&sb.path("d"), 0);
    assert_eq!(
        rows[0].split(',').next().unwrap().parse::<f64>().unwrap(),
        100.0
    );
}

/// Disks poured by an inlet onto a floor (`walls.0.remove_at` removes it)
/// above an outlet that takes out what falls through: a restart carries
/// the grains the inlet added and the outlet took out, and the inlet and
/// outlet go on where they were.
const FILL: &str = r#"name = "fill"
dimension = "2d"
gravity = [0.0, -9.81]
seed = 3

[domain]
lo = [0.0, -0.003]
hi = [0.01, 0.012]
periodic = [true, false]

[particles]
placement = "none"
d0 = 1.0e-3

[[inlets]]
region = { shape = "box", lo = [0.0, 0.004], hi = [0.01, 0.011] }
rate = 3000.0
stop = 0.045
velocity = [0.0, -0.5]
size = { distribution = "uniform", min = 0.8e-3, max = 1.2e-3 }

[[outlets]]
name = "below"
plane = { point = [0.0, -0.001], normal = [0.0, -1.0] }

[contact]
preset = "lammps-hooke-history"
kn = 2.0e3

[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }

[run]
integrator = "verlet"
dt = 2.0e-6
duration = 0.05

[output]
every = 0.001
picture = false
"#;

/// `key` of the run's summary.json.
fn summary_key(dir: &Path, key: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v[key].clone()
}

#[test]
fn a_restart_carries_the_grains_of_inlets_and_outlets() {
    let sb = Sandbox::new("fill");
    std::fs::write(sb.path("fill.toml"), FILL).unwrap();
    let g = |args: &[&str]| grains_in(&sb.0, args);
    let floor_off = "walls.0.remove_at=0.02";
    ok(&g(&[
        "run",
        "fill.toml",
        "--out",
        "straight",
        "--quiet",
        "--set",
        floor_off,
    ]));
    // Filled for 10000 steps on the floor, then restarted with the floor
    // removed at that step; that run restarted again at step 20000, once
    // the outlet has taken grains out.
    ok(&g(&[
        "run",
        "fill.toml",
        "--out",
        "kept",
        "--steps",
        "10000",
        "--quiet",
        "--checkpoint-every",
        "10000steps",
    ]));
    ok(&g(&[
        "resume",
        "kept",
        "--out",
        "opened",
        "--steps",
        "15000",
        "--quiet",
        "--checkpoint-every",
        "5000steps",
        "--set",
        floor_off,
    ]));
    ok(&g(&[
        "resume",
        "opened/checkpoint-000000020000.grck",
        "--out",
        "again",
        "--steps",
        "5000",
        "--quiet",
    ]));
    let straight = rows_from(&sb.path("straight"), 10000);
    assert_eq!(straight.len(), 31);
    assert_eq!(rows_from(&sb.path("opened"), 0), straight);
    assert_eq!(rows_from(&sb.path("again"), 0), straight[20..]);
    // The inlet did not start again and the balance spans the three runs:
    // inserted = present + removed, with grains taken out before the
    // second restart.
    let balance = summary_key(&sb.path("again"), "mass_balance");
    assert_eq!(balance, summary_key(&sb.path("straight"), "mass_balance"));
    assert_eq!(
        summary_key(&sb.path("again"), "inlets"),
        summary_key(&sb.path("straight"), "inlets")
    );
    assert_eq!(balance["exact"], true, "{balance}");
    let removed = balance["removed_grains"].as_u64().unwrap();
    assert!(removed > 0, "{balance}");
}

#[test]
fn a_closed_pipe_ends_the_run_quietly() {
    let sb = Sandbox::new("pipe");
    let mut child = Command::new(env!("CARGO_BIN_EXE_grains"))
        .current_dir(&sb.0)
        .args(["run", "s.toml", "--steps", "200", "--out", "p"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reader of the summary goes away before it is printed (`| head -0`).
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(out.status.code(), Some(101), "{err}");
    assert!(sb.path("p/summary.json").is_file());
}
