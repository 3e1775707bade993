//! Whole runs of scenarios through the library's runner, serially or on
//! thread ranks, and reading their results.

use grains::comm::{Comm, ThreadComm};
use grains::runner::{distributed, RunOptions, Silent};
use grains::scenario::Loaded;

/// Runs a shipped scenario (scenarios/NAME.toml) through the library runner
/// with `sets` applied and no frames, pictures or movie; returns summary.json.
pub fn run_scenario(name: &str, tag: &str, sets: &[&str]) -> serde_json::Value {
    let (s, out) = run_scenario_kept(name, tag, sets);
    let _ = std::fs::remove_dir_all(&out);
    s
}

/// As [`run_scenario`], but keeps the output directory (returned) so that a
/// test can read the measurement files; the caller removes it.
pub fn run_scenario_kept(
    name: &str,
    tag: &str,
    sets: &[&str],
) -> (serde_json::Value, std::path::PathBuf) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("scenarios").join(format!("{name}.toml"));
    let mut all: Vec<String> = vec![
        "output.frames=false".into(),
        "output.picture=false".into(),
        "output.movie=false".into(),
    ];
    all.extend(sets.iter().map(|s| s.to_string()));
    let loaded = grains::scenario::load_file(&path, &all).expect("scenario loads");
    // The modules of one test binary share a process: each run its own
    // directory.
    static RUNS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let k = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let out = std::env::temp_dir().join(format!(
        "grains-test-{name}-{tag}-{}-{k}",
        std::process::id()
    ));
    let opts = RunOptions {
        out_dir: out.clone(),
        steps: None,
        ..Default::default()
    };
    let s = grains::runner::run(&loaded, &opts, &mut Silent).expect("run");
    (s, out)
}

/// Reads a CSV file with one header line into rows of numbers.
pub fn read_csv(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

/// The number `key` of a summary.
pub fn num(s: &serde_json::Value, key: &str) -> f64 {
    s[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {s}"))
}

/// `l` through the distributed runner with `opts` on `ranks` thread ranks:
/// rank 0's summary (the runner gives one on rank 0 only).
pub fn run_on_threads(l: &Loaded, opts: &RunOptions, ranks: usize) -> serde_json::Value {
    let out = ThreadComm::run(ranks, |c| {
        distributed::run(l, opts, &mut Silent, c as &dyn Comm).unwrap()
    });
    assert!(out[1..].iter().all(|v| v.is_null()), "a summary off rank 0");
    out.into_iter().next().unwrap()
}
