//! Property-test fuzzers for hostile input: the scenario parser with
//! `--set` paths (then the engine builder), the LAMMPS data reader, the
//! particle CSV reader and the checkpoint reader (then restore and a step).
//! Every input must end in `Ok` or an error, never a panic.
//!
//! Cases per target: 48 by default (CI); set `GRAINS_FUZZ_CASES=100000` (or
//! any number) for a long local run. Inputs that once crashed stay below as
//! plain regression tests.

use grains::checkpoint;
use grains::runner::checkpointing::{self, Every};
use grains::runner::{self, RunOptions, Silent};
use grains::scenario::load_str;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn cases() -> u32 {
    std::env::var("GRAINS_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48)
}

fn runner() -> TestRunner {
    TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    })
}

const SCENARIO: &str = r#"name = "fuzz"
dimension = "2d"
gravity = [0.0, -9.81]

[domain]
lo = [0.0, -0.002]
hi = [0.01, 0.02]
periodic = [true, false]

[particles]
placement = "lattice"
count = 12
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
duration = 0.0002

[output]
frames = false
picture = false
"#;

/// Keys a `--set` may name (real ones, and some that are not).
const KEYS: &[&str] = &[
    "name",
    "dimension",
    "method",
    "seed",
    "gravity",
    "domain.lo",
    "domain.hi",
    "domain.periodic",
    "domain.lo.0",
    "particles.count",
    "particles.d0",
    "particles.width",
    "particles.density",
    "particles.spacing",
    "particles.placement",
    "particles.random_velocity",
    "particles.region.lo",
    "particles.mass_model",
    "particles.file",
    "contact.preset",
    "contact.kn",
    "contact.beta",
    "contact.gamma_n",
    "contact.restitution",
    "contact.kt",
    "contact.mu",
    "contact.scaling",
    "walls.0.shape.normal",
    "walls.0.motion.frequency",
    "walls.0.remove_at",
    "walls.5.name",
    "run.dt",
    "run.dt_safety",
    "run.duration",
    "run.cycles",
    "run.skin",
    "run.max_overlap",
    "run.integrator",
    "output.every",
    "measure.displacement",
    "",
    ".",
    "a..b",
    "particles.count.x",
    "dsmc.cells",
];

const VALUES: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "1e308",
    "-1e308",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "-0.0",
    "18446744073709551615",
    "100000000000",
    "\"x\"",
    "\"file\"",
    "\"random\"",
    "\"3d\"",
    "\"dsmc\"",
    "\"verlet\"",
    "[]",
    "[0.0]",
    "[1e308, -1e308]",
    "[nan, 0.0]",
    "[0.0, 0.0, 0.0, 0.0]",
    "true",
    "{}",
    "{ lo = [0.0, 0.0], hi = [0.0, 0.0] }",
    "=",
    "",
    "\"auto\"",
];

/// Parses, and when that succeeds builds the engine (`grains check`).
fn parse_and_check(text: &str, sets: &[String]) {
    if let Ok(loaded) = load_str(text, "fuzz", PathBuf::from("/nonexistent-fuzz-dir"), sets) {
        let _ = runner::check(&loaded);
    }
}

/// Found by the fuzzer: a speed whose double overflows once panicked in the
/// random draw.
#[test]
fn regression_huge_random_velocity() {
    for v in ["1e308", "inf"] {
        let loaded = load_str(
            SCENARIO,
            "fuzz",
            PathBuf::from("."),
            &[format!("particles.random_velocity={v}")],
        )
        .unwrap();
        assert!(
            runner::check(&loaded).is_err(),
            "random_velocity = {v} accepted"
        );
    }
}

#[test]
fn fuzz_scenario_parser_and_set_paths() {
    let set = (
        prop::sample::select(KEYS),
        prop::sample::select(VALUES),
        "[a-z_.0-9=\\[\\]\" -]{0,12}",
    );
    let strategy = (
        prop::collection::vec(set, 0..4),
        any::<bool>(),
        0usize..SCENARIO.len(),
        0usize..40,
        "[\\x00-\\x7f]{0,8}",
    );
    runner()
        .run(&strategy, |(sets, raw, at, cut, insert)| {
            let sets: Vec<String> = sets
                .into_iter()
                .map(|(k, v, r)| if raw { r } else { format!("{k}={v}") })
                .collect();
            parse_and_check(SCENARIO, &sets);
            // Text damage: a cut and an insertion at a char boundary.
            let mut at = at;
            while !SCENARIO.is_char_boundary(at) {
                at -= 1;
            }
            let end = (at + cut).min(SCENARIO.len());
            let text = format!("{}{insert}{}", &SCENARIO[..at], &SCENARIO[end..]);
            parse_and_check(&text, &[]);
            Ok(())
        })
        .unwrap();
}

const DATA: &str = include_str!("../data/small_sphere.data");

const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1e308",
    "nan",
    "inf",
    "18446744073709551615",
    "99999999999999999999",
    "4294967296",
    "-0",
    "x",
    "",
    "Atoms",
    "Velocities",
    "Masses",
    "atoms",
    "atom types",
    "# sphere",
    "xlo xhi",
    "\n",
    "1e-320",
];

fn mutate_tokens(base: &str, edits: &[(usize, usize)]) -> String {
    let mut toks: Vec<String> = base
        .split_inclusive(char::is_whitespace)
        .map(str::to_string)
        .collect();
    for &(pos, t) in edits {
        if toks.is_empty() {
            break;
        }
        let k = pos % toks.len();
        match t % 3 {
            0 => toks[k] = format!("{} ", TOKENS[t % TOKENS.len()]),
            1 => {
                toks.remove(k);
            }
            _ => {
                let dup = toks[k].clone();
                toks.insert(k, dup);
            }
        }
    }
    toks.concat()
}

#[test]
fn fuzz_lammps_data_reader() {
    let strategy = (
        prop::collection::vec((any::<usize>(), any::<usize>()), 0..8),
        "[\\x00-\\x7f]{0,64}",
    );
    runner()
        .run(&strategy, |(edits, noise)| {
            let text = mutate_tokens(DATA, &edits);
            let _ = grains::io::parse_lammps_data(&text, "fuzz.data");
            let _ = grains::io::parse_lammps_data(&noise, "noise.data");
            Ok(())
        })
        .unwrap();
}

const CSV: &str = "id,x,y,z,radius,vx,vy,vz,type,frozen\n\
1,0.5,0.5,0.5,0.1,0,0,0,1,0\n\
2,1.5,0.5,0.5,0.2,1,0,0,2,1\n\
# a comment\n\
3,0.5,1.5,0.5,0.1,0,-1,0,1,false\n";

#[test]
fn fuzz_particle_csv_reader() {
    let strategy = (
        prop::collection::vec((any::<usize>(), any::<usize>()), 0..8),
        "[\\x00-\\x7f,]{0,64}",
        2usize..4,
    );
    runner()
        .run(&strategy, |(edits, noise, dim)| {
            let text = mutate_tokens(&CSV.replace(',', ", "), &edits).replace(", ", ",");
            let _ = grains::io::parse_particles_csv(&text, "fuzz.csv", dim);
            let _ = grains::io::parse_particles_csv(&noise, "noise.csv", dim);
            Ok(())
        })
        .unwrap();
}

/// A valid checkpoint of the fuzz scenario (written once per process).
fn good_checkpoint() -> &'static (PathBuf, Vec<u8>) {
    static GOOD: OnceLock<(PathBuf, Vec<u8>)> = OnceLock::new();
    GOOD.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("grains-fuzz-ckpt-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let loaded = load_str(SCENARIO, "fuzz", PathBuf::from("."), &[]).unwrap();
        let opts = RunOptions {
            out_dir: dir.clone(),
            steps: Some(40),
            checkpoint_every: Some(Every::Steps(40)),
            stop: None,
            overwrite: false,
        };
        runner::run(&loaded, &opts, &mut Silent).unwrap();
        let p = dir.join(checkpoint::file_name(40));
        let bytes = std::fs::read(&p).unwrap();
        (dir, bytes)
    })
}

/// Reads a checkpoint from `bytes`; when it decodes, resumes it for two
/// steps. Returns how far it got: 0 refused, 1 decoded, 2 resumed.
fn read_and_resume(dir: &Path, bytes: &[u8]) -> usize {
    // Tests run in parallel and share `dir` (its checkpoint and the outputs
    // a resume appends to): one case at a time.
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let p = dir.join("fuzz-case.grck");
    std::fs::write(&p, bytes).unwrap();
    match checkpointing::find(&p) {
        Ok((found, _)) => {
            let opts = RunOptions {
                checkpoint_every: None,
                ..RunOptions::default()
            };
            1 + checkpointing::resume(found, Some(2), opts, &mut Silent).is_ok() as usize
        }
        Err(_) => 0,
    }
}

#[test]
fn fuzz_checkpoint_reader() {
    let (dir, good) = good_checkpoint();
    let payload = checkpoint::unseal(good, Path::new("good"))
        .unwrap()
        .to_vec();
    let strategy = (
        prop::collection::vec((any::<usize>(), any::<u8>()), 1..6),
        any::<bool>(),
        any::<usize>(),
    );
    let reached = std::sync::Mutex::new([0usize; 3]);
    runner()
        .run(&strategy, |(edits, reseal, cut)| {
            // Damaged bytes under a valid checksum reach the decoder; damaged
            // sealed files must be caught by the header and the CRC.
            let mut b = if reseal {
                payload.clone()
            } else {
                good.clone()
            };
            for &(pos, byte) in &edits {
                let k = pos % b.len();
                b[k] = byte;
            }
            if cut % 5 == 0 {
                b.truncate(cut % (b.len() + 1));
            }
            let damaged = !reseal && b != *good;
            let sealed = if reseal { checkpoint::seal(&b) } else { b };
            let got = read_and_resume(dir, &sealed);
            // A CRC-32 misses a random change with probability 2⁻³², and
            // every change of the header or the length is checked directly.
            prop_assert!(!damaged || got == 0, "a damaged sealed file was read");
            reached.lock().unwrap()[got] += 1;
            Ok(())
        })
        .unwrap();
    let r = reached.into_inner().unwrap();
    eprintln!(
        "checkpoint fuzz: {} refused, {} decoded but refused on restore, {} resumed",
        r[0], r[1], r[2]
    );
}

#[test]
fn checkpoint_reader_regressions() {
    let (dir, good) = good_checkpoint();
    assert_eq!(read_and_resume(dir, good), 2);
    for bad in [&b""[..], b"GRAINSCK", &good[..30]] {
        assert_eq!(read_and_resume(dir, bad), 0);
    }
}
