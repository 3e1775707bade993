//! `mpirun -np N grains run` (built with `--features mpi`, Open MPI's
//! `mpirun` on the PATH) against the plain single-process run: for DSMC
//! the files must be the same byte for byte on 1, 2 and 4 ranks (the
//! decomposition reproduces the serial engine exactly, see
//! `grains::dsmc::decomp`), in 2D with a vibrating plate and a lid under
//! gravity and in 3D in a periodic box. An MD scenario on several ranks is
//! refused with exit code 2 and a message naming the limitation.
#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GRAINS: &str = env!("CARGO_BIN_EXE_grains");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("grains-mpi-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `grains args...` on `ranks` MPI ranks (0: without mpirun).
fn grains(ranks: usize, args: &[&str]) -> Output {
    let mut c = if ranks == 0 {
        Command::new(GRAINS)
    } else {
        let mut c = Command::new("mpirun");
        // CI runs as root on a two-core machine.
        c.args(["--oversubscribe", "--allow-run-as-root", "-np"])
            .arg(ranks.to_string())
            .arg(GRAINS);
        c
    };
    c.args(args)
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .output()
        .expect("mpirun (Open MPI) must be installed")
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn same_files(a: &Path, b: &Path) {
    let mut names = vec![PathBuf::from("thermo.csv")];
    if a.join("profiles.csv").exists() {
        names.push("profiles.csv".into());
    }
    if a.join("frames").exists() {
        names.push("frames.pvd".into());
        for e in std::fs::read_dir(a.join("frames")).unwrap() {
            names.push(Path::new("frames").join(e.unwrap().file_name()));
        }
    }
    assert!(names.len() > 1, "nothing to compare in {}", a.display());
    for n in names {
        assert!(
            read(&a.join(&n)) == read(&b.join(&n)),
            "{} differs between {} and {}",
            n.display(),
            a.display(),
            b.display()
        );
    }
}

fn check(scenario: &str, sets: &[&str], steps: &str) {
    let path = repo().join("scenarios").join(scenario);
    let path = path.to_str().unwrap();
    let run = |ranks: usize| {
        let dir = scratch(&format!("{scenario}-{ranks}"));
        let mut args = vec!["run", path, "--steps", steps, "--quiet", "--out"];
        args.push(dir.to_str().unwrap());
        for s in sets {
            args.extend(["--set", s]);
        }
        let out = grains(ranks, &args);
        assert!(
            out.status.success(),
            "{ranks} ranks: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        dir
    };
    let serial = run(0);
    for ranks in [1, 2, 4] {
        let dir = run(ranks);
        same_files(&serial, &dir);
        let summary: serde_json::Value =
            serde_json::from_slice(&read(&dir.join("summary.json"))).unwrap();
        if ranks > 1 {
            assert_eq!(summary["ranks"], ranks);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&serial);
}

#[test]
fn dsmc_vibrated_2d_is_the_same_on_1_2_4_ranks() {
    check(
        "gas-vibrated-2d.toml",
        &["output.frames=true", "output.every=0.002"],
        "300",
    );
}

#[test]
fn dsmc_periodic_3d_is_the_same_on_1_2_4_ranks() {
    check(
        "gas-cooling-3d.toml",
        &[
            "particles.count=3000",
            "domain.hi=[0.08,0.08,0.08]",
            "dsmc.cell_size=0.01",
            "dsmc.profile_bins=4",
        ],
        "100",
    );
}

#[test]
fn more_ranks_than_cell_layers_is_refused_once() {
    let path = repo().join("scenarios/gas-vibrated-2d.toml");
    let dir = scratch("layers");
    let out = grains(
        4,
        &[
            "run",
            path.to_str().unwrap(),
            "--set",
            "dsmc.cell_size=0.1",
            "--steps",
            "10",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("4 ranks but only 3 layers"), "{err}");
    assert_eq!(err.matches("grains: error").count(), 1, "{err}");
}

#[test]
fn md_on_several_ranks_is_refused_clearly() {
    let path = repo().join("scenarios/bench-chute.toml");
    let dir = scratch("md");
    let out = grains(
        2,
        &[
            "run",
            path.to_str().unwrap(),
            "--steps",
            "10",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("method = \"md\""), "{err}");
}
