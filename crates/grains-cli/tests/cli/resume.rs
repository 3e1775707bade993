//! `grains run --checkpoint-every` and `grains resume`: a run killed with
//! SIGKILL at random moments (also during checkpoint writes) and resumed
//! ends with the same files, byte for byte, as a run never interrupted;
//! SIGINT stops with a checkpoint and a resume hint; damaged, truncated,
//! wrong-version and wrong-scenario checkpoints exit 2 with a message.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// 40 disks on a vibrating floor with frictional springs; about 1 s of CPU.
const SCENARIO: &str = r#"name = "resume"
dimension = "2d"
gravity = [0.0, -9.81]

[domain]
lo = [0.0, -0.002]
hi = [0.01, 0.02]
periodic = [true, false]

[particles]
placement = "lattice"
count = 40
d0 = 1.0e-3
width = 0.2
random_velocity = 0.05
region = { lo = [0.0, 0.0005], hi = [0.01, 0.02] }

[contact]
preset = "lammps-hooke-history"
kn = 2.0e3

[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
motion = { type = "vibrate", amplitude = 3.0e-4, frequency = 50.0 }

[run]
dt = 2.0e-6
duration = 0.03

[output]
every = 0.001
dump = true
picture = false
"#;

struct Sandbox(PathBuf);

impl Sandbox {
    fn new(name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("grains-resume-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Sandbox(d)
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

fn grains() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_grains"));
    c.stdin(Stdio::null());
    c
}

fn run(args: &[&str]) -> Output {
    let out = grains().args(args).output().expect("start grains");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic:\n{err}");
    out
}

/// [`run`], which must succeed.
fn run_ok(args: &[&str]) {
    let o = run(args);
    assert_eq!(code(&o), Some(0), "{}", stderr(&o));
}

/// `grains run <scen> --out <out> --quiet <extra>...`, which must succeed.
fn run_quiet(scen: &Path, out: &Path, extra: &[&str]) {
    let (scen, out) = (scen.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec!["run", scen, "--out", out, "--quiet"];
    args.extend_from_slice(extra);
    run_ok(&args);
}

fn code(o: &Output) -> Option<i32> {
    o.status.code()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every output file that must match between runs (not summary.json, whose
/// wall-clock figures differ).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = Vec::new();
    for name in ["thermo.csv", "dump.lammpstrj", "frames.pvd"] {
        v.push((name.to_string(), std::fs::read(dir.join(name)).unwrap()));
    }
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "vtp"))
        .collect();
    frames.sort();
    for f in frames {
        v.push((
            f.file_name().unwrap().to_string_lossy().into_owned(),
            std::fs::read(&f).unwrap(),
        ));
    }
    v
}

fn summary_state(dir: &Path) -> String {
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let keys = [
        "steps",
        "time",
        "kinetic_energy",
        "rotational_energy",
        "neighbor_builds",
    ];
    keys.iter().map(|k| format!("{k}={} ", s[*k])).collect()
}

/// The seed of the random interruption times: `GRAINS_KILL_SEED`, else
/// `default` mixed with the process id (other moments on every run).
fn kill_seed(default: u64) -> u64 {
    std::env::var("GRAINS_KILL_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default ^ std::process::id() as u64)
}

/// Starts the next try at the interrupted run in `dir`: `grains resume`
/// once it holds a checkpoint; at the `first` try, or while none was
/// written, a fresh `grains run` of `scen` with a checkpoint every
/// `every`, the directory cleared. Standard error piped.
fn next_attempt(first: bool, scen: &Path, dir: &Path, every: &str) -> Child {
    let has_ckpt = dir.exists()
        && std::fs::read_dir(dir)
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().ends_with(".grck"));
    let d = dir.to_str().unwrap();
    let mut cmd = grains();
    if first || !has_ckpt {
        let _ = std::fs::remove_dir_all(dir);
        cmd.args(["run", scen.to_str().unwrap(), "--out", d, "--quiet"])
            .args(["--checkpoint-every", every]);
    } else {
        cmd.args(["resume", d, "--quiet"]);
    }
    cmd.stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// A small deterministic pseudo-random sequence (no extra dependency).
struct Lcg(u64);
impl Lcg {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) % n
    }
}

#[test]
fn sigkill_at_random_moments_then_resume_matches_straight_run() {
    let sb = Sandbox::new("kill");
    let scen = sb.path("s.toml");
    std::fs::write(&scen, SCENARIO).unwrap();
    let straight = sb.path("straight");
    run_quiet(&scen, &straight, &[]);

    let t0 = Instant::now();
    run_quiet(
        &scen,
        &sb.path("timing"),
        &["--checkpoint-every", "50steps"],
    );
    let full = t0.elapsed().as_millis().max(50) as u64;

    let dir = sb.path("killed");
    let seed = kill_seed(0x5eed_u64);
    let mut rng = Lcg(seed);
    let mut kills = 0;
    let mut fresh = true;
    // Waits are drawn below this bound; halved whenever the run ends before
    // its first kill (the machine ran it faster than the timing run did).
    let mut bound = full * 2 / 3;
    loop {
        let mut child = next_attempt(fresh, &scen, &dir, "50steps");
        fresh = false;
        if kills < 4 {
            let wait = Duration::from_millis(rng.below(bound) + 5);
            let until = Instant::now() + wait;
            while Instant::now() < until {
                if child.try_wait().unwrap().is_some() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(2));
            }
            if child.try_wait().unwrap().is_none() {
                child.kill().unwrap(); // SIGKILL
                let _ = child.wait();
                kills += 1;
                continue;
            }
            if kills == 0 && bound > 1 {
                let _ = child.wait();
                bound /= 2;
                fresh = true;
                continue;
            }
        }
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(out.status.code(), Some(0), "seed {seed}: {err}");
        break;
    }
    assert!(kills > 0, "seed {seed}: the run was never killed");
    let (a, b) = (files(&straight), files(&dir));
    assert_eq!(a.len(), b.len(), "seed {seed}: frame counts differ");
    for ((na, fa), (nb, fb)) in a.iter().zip(&b) {
        assert_eq!(na, nb);
        assert!(fa == fb, "seed {seed}: {na} differs after {kills} kills");
    }
    assert_eq!(summary_state(&straight), summary_state(&dir));
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".grck"))
        .collect();
    assert!(left.len() <= 2, "more than two checkpoints kept: {left:?}");
}

#[test]
fn sigint_writes_a_checkpoint_and_says_how_to_resume() {
    let sb = Sandbox::new("int");
    let scen = sb.path("s.toml");
    std::fs::write(
        &scen,
        SCENARIO.replace("duration = 0.03", "duration = 10.0"),
    )
    .unwrap();
    let dir = sb.path("run");
    let child = grains()
        .args([
            "run",
            scen.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--quiet",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap()
        .success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("grains resume") && err.contains("checkpoint"),
        "{err}"
    );
    run_ok(&["resume", dir.to_str().unwrap(), "--steps", "20", "--quiet"]);
}

/// Runs 200 steps with checkpoints, returns the newest checkpoint's bytes.
fn one_checkpoint(sb: &Sandbox) -> (PathBuf, Vec<u8>) {
    let scen = sb.path("s.toml");
    std::fs::write(&scen, SCENARIO).unwrap();
    let dir = sb.path("run");
    run_quiet(
        &scen,
        &dir,
        &["--steps", "200", "--checkpoint-every", "100steps"],
    );
    let p = dir.join("checkpoint-000000000200.grck");
    let bytes = std::fs::read(&p).unwrap();
    for e in std::fs::read_dir(&dir).unwrap() {
        let e = e.unwrap();
        if e.file_name().to_string_lossy().ends_with(".grck") {
            std::fs::remove_file(e.path()).unwrap();
        }
    }
    (dir, bytes)
}

fn reseal(payload: &[u8]) -> Vec<u8> {
    grains::checkpoint::seal(payload)
}

#[test]
fn damaged_checkpoints_are_refused_with_exit_2() {
    let sb = Sandbox::new("bad");
    let (dir, good) = one_checkpoint(&sb);
    let target = dir.join("checkpoint-000000000200.grck");
    let payload = good[24..].to_vec();
    let mut wrong_version = good.clone();
    wrong_version[8] = 99;
    let mut flipped = good.clone();
    let mid = good.len() / 2;
    flipped[mid] ^= 0x10;
    // A scenario with one more grain, re-sealed with a valid checksum.
    let len = u64::from_le_bytes(payload[..8].try_into().unwrap()) as usize;
    let text = String::from_utf8(payload[8..8 + len].to_vec()).unwrap();
    let other = text.replace("count = 40", "count = 41");
    assert_ne!(text, other);
    let mut p2 = (other.len() as u64).to_le_bytes().to_vec();
    p2.extend_from_slice(other.as_bytes());
    p2.extend_from_slice(&payload[8 + len..]);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("truncated", good[..good.len() - 7].to_vec(), "truncated"),
        ("empty", Vec::new(), "truncated"),
        ("corrupted", flipped, "checksum"),
        ("wrong version", wrong_version, "version 99"),
        (
            "not a checkpoint",
            b"hello, world, this is text".to_vec(),
            "not a grains checkpoint",
        ),
        ("wrong scenario", reseal(&p2), "the scenario builds 41"),
    ];
    for (what, bytes, needle) in cases {
        std::fs::write(&target, &bytes).unwrap();
        let o = run(&["resume", dir.to_str().unwrap(), "--quiet"]);
        let err = stderr(&o);
        assert_eq!(code(&o), Some(2), "{what}: {err}");
        assert!(
            err.contains(needle) && err.contains("checkpoint-000000000200"),
            "{what}: {err}"
        );
    }
    // The good one resumes.
    std::fs::write(&target, &good).unwrap();
    run_ok(&["resume", dir.to_str().unwrap(), "--steps", "10", "--quiet"]);
}

#[test]
fn unusable_directories_and_options_exit_2() {
    let sb = Sandbox::new("dirs");
    let scen = sb.path("s.toml");
    std::fs::write(&scen, SCENARIO).unwrap();
    let file = sb.path("a-file");
    std::fs::write(&file, "x").unwrap();
    let under = file.join("out");
    let o = run(&[
        "run",
        scen.to_str().unwrap(),
        "--out",
        under.to_str().unwrap(),
        "--steps",
        "5",
    ]);
    assert_eq!(code(&o), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(under.to_str().unwrap()),
        "{}",
        stderr(&o)
    );
    let o = run(&["resume", sb.path("nothing-here").to_str().unwrap()]);
    assert_eq!(code(&o), Some(2), "{}", stderr(&o));
    let o = run(&["resume", sb.0.to_str().unwrap()]);
    assert_eq!(code(&o), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no checkpoint"), "{}", stderr(&o));
    let o = run(&[
        "run",
        scen.to_str().unwrap(),
        "--checkpoint-every",
        "0steps",
    ]);
    assert_eq!(code(&o), Some(2), "{}", stderr(&o));
}

/// Every plain file of a run directory (measurement CSVs and pictures
/// included) but summary.json and the checkpoints, by name.
fn all_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .filter(|n| n != "summary.json" && !n.ends_with(".grck"))
        .map(|n| {
            let b = std::fs::read(dir.join(&n)).unwrap();
            (n, b)
        })
        .collect();
    v.sort();
    v
}

fn summary_measurements(dir: &Path) -> String {
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let keys = [
        "convection_center_vz",
        "convection_edge_vz",
        "convection_strength",
        "tracer_rms",
        "transport_velocity",
    ];
    keys.iter()
        .map(|k| {
            assert!(!s[*k].is_null(), "summary.json lacks {k}");
            format!("{k}={} ", s[*k])
        })
        .collect()
}

#[test]
fn measurements_survive_sigint_and_resume_bit_for_bit() {
    let sb = Sandbox::new("measure");
    let scen = sb.path("s.toml");
    let text = SCENARIO.replace("duration = 0.03", "duration = 0.03\nrelax = 0.004")
        + r#"
[measure]
displacement = true
convection = { band = 0.3 }
tracer = { id = 7 }
profiles = { bin = 1.0 }
phases = { phases = [0.0, 1.5], displacement_after = 0.004 }
trajectories = { every = 40, cycles = 0.5 }
"#;
    std::fs::write(&scen, text).unwrap();
    let straight = sb.path("straight");
    let t0 = Instant::now();
    run_quiet(&scen, &straight, &[]);
    let full = t0.elapsed().as_millis().max(60) as u64;

    let dir = sb.path("stopped");
    let seed = kill_seed(0xc0ffee_u64);
    let mut rng = Lcg(seed);
    let (mut stops, mut started) = (0, false);
    // The signal comes within the first half of the straight run's time;
    // a run that ends before it (faster than the straight run, which shared
    // the cores with the other tests) starts again, signalled sooner.
    let (mut span, mut floor, mut fresh) = (full / 2, 30, 0);
    loop {
        let child = next_attempt(!started, &scen, &dir, "700steps");
        started = true;
        if stops < 4 {
            let wait = Duration::from_millis(rng.below(span.max(1)) + floor);
            std::thread::sleep(wait);
            let _ = Command::new("kill")
                .args(["-INT", &child.id().to_string()])
                .status();
        }
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "seed {seed}: {err}");
        match out.status.code() {
            Some(0) if stops == 0 && fresh < 6 => {
                (started, span, floor, fresh) = (false, span / 2, floor / 2, fresh + 1);
            }
            Some(0) => break,
            // Stopped with a checkpoint, or killed before the handler was set.
            Some(130) | None => stops += 1,
            c => panic!("seed {seed}: exit {c:?}: {err}"),
        }
    }
    assert!(stops > 0, "seed {seed}: the run was never stopped");
    let (a, b) = (all_files(&straight), all_files(&dir));
    let names = |v: &[(String, Vec<u8>)]| v.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b), "seed {seed}");
    for name in [
        "displacement.csv",
        "tracer.csv",
        "profiles.csv",
        "phase_0.csv",
        "phase_1.csv",
        "phase_displacement.csv",
        "trajectories.csv",
    ] {
        assert!(names(&a).iter().any(|n| n == name), "no {name}");
    }
    for ((na, fa), (_, fb)) in a.iter().zip(&b) {
        assert!(fa == fb, "seed {seed}: {na} differs after {stops} stops");
    }
    assert_eq!(files(&straight), files(&dir), "seed {seed}");
    assert_eq!(summary_state(&straight), summary_state(&dir));
    assert_eq!(summary_measurements(&straight), summary_measurements(&dir));
}
