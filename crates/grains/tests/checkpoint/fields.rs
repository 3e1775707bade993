//! Checkpoint and resume of the coarse-grained fields: a bed-fields-2d run
//! stopped inside its second averaging window and resumed writes the same
//! windows (fields/*.csv, *.vti, fields.pvd, fields.json) and summary as
//! the run straight through: the closed windows, the open one's sums and
//! the step the measurement began travel in the checkpoint.

use grains::runner::checkpointing::{find, resume};
use grains::runner::{run, Progress, RunOptions, Silent};
use grains::scenario::load_str;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Raises the stop flag once the measurement's progress reaches `at`
/// steps (reported every 256 steps; the run stops right after).
struct StopAt {
    flag: Arc<AtomicBool>,
    at: u64,
    on: bool,
}

impl Progress for StopAt {
    fn phase(&mut self, name: &str, _: u64) {
        self.on = name == "run";
    }
    fn advance(&mut self, done: u64, _: f64) {
        if self.on && done >= self.at {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
    fn finish(&mut self) {}
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-ck-fields-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn fields_windows_survive_a_resume() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bed-fields-2d.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    // 1,000 steps settling, 2,000 measured: a sample every 100 steps,
    // windows of 5 samples, so 4 windows.
    let sets: Vec<String> = [
        "run.dt=1e-5",
        "run.relax=0.01",
        "run.duration=0.02",
        "output.picture=false",
        "output.contacts=false",
        "measure.fields.every=100",
        "measure.fields.average=5",
    ]
    .map(String::from)
    .to_vec();
    let loaded = load_str(&text, "bed-fields-2d.toml", PathBuf::from("."), &sets).unwrap();
    let opts = |dir: &Path| RunOptions {
        out_dir: dir.to_path_buf(),
        ..RunOptions::default()
    };
    let plain = scratch("plain");
    let s0 = run(&loaded, &opts(&plain), &mut Silent).unwrap();
    assert_eq!(s0["fields_windows"], 4, "{s0}");

    // Stopped 768 steps into the measurement: 7 samples, the second
    // window open with 2.
    let dir = scratch("stopped");
    let flag = Arc::new(AtomicBool::new(false));
    let mut p = StopAt {
        flag: flag.clone(),
        at: 768,
        on: false,
    };
    let o = RunOptions {
        stop: Some(flag),
        ..opts(&dir)
    };
    let s = run(&loaded, &o, &mut p).unwrap();
    assert_eq!(s["interrupted"], true, "{s}");
    let (found, _) = find(&dir).unwrap();
    assert_eq!(found.step, 1768);
    let s1 = resume(found, None, RunOptions::default(), &mut Silent).unwrap();
    let mut files = vec!["fields.pvd".to_string(), "fields.json".to_string()];
    for k in 0..4 {
        files.push(format!("fields/fields_{k:05}.csv"));
        files.push(format!("fields/fields_{k:05}.vti"));
    }
    for f in &files {
        assert!(read(&plain.join(f)) == read(&dir.join(f)), "{f} differs");
    }
    for (k, v) in s0.as_object().unwrap() {
        if k.starts_with("fields") {
            assert_eq!(Some(v), s1.get(k), "summary {k}");
        }
    }
    let _ = std::fs::remove_dir_all(&plain);
    let _ = std::fs::remove_dir_all(&dir);
}
