//! The output folder of a fresh run: never mixed with an earlier run's files.
//!
//! A folder holds a run when it has one of the files every run writes
//! ([`MARKERS`]: thermo.csv, summary.json, frames.pvd, frames/ or a
//! checkpoint). A fresh run refuses such a folder unless told to overwrite;
//! then it first removes every file and folder a run writes ([`RUN_FILES`],
//! frames/, checkpoints), so no frame of the old run is left beside the new
//! ones. Files that no run writes are left alone. Resuming a run reopens its
//! own folder and does not come here.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Files whose presence means the folder holds a run.
pub const MARKERS: &[&str] = &["thermo.csv", "summary.json", "frames.pvd", "frames"];

/// Every file a run (MD or DSMC) writes at the top of its folder, besides
/// frames/ and the checkpoints. A new output file belongs in this list.
pub const RUN_FILES: &[&str] = &[
    "thermo.csv",
    "summary.json",
    "frames.pvd",
    "dump.lammpstrj",
    "bodies.csv",
    "walls.csv",
    "final.png",
    "movie.gif",
    "movie.mp4",
    ".movie.gif.partial",
    "scene.json",
    "displacement.csv",
    "displacement.png",
    "convection_profile.csv",
    "convection_profile.png",
    "phase_displacement.csv",
    "phase_displacement.png",
    "tracer.csv",
    "tracer.png",
    "profiles.csv",
    "profile_density.png",
    "profile_velocity.png",
    "height_profile.png",
    "trajectories.csv",
    "trajectories.png",
    "surface.csv",
    "spacetime.csv",
    "spacetime.png",
    "flow_field.csv",
    "flow_field.png",
    "impacts.csv",
    "discharge.csv",
];

/// The folder of a run's frames (frame files, pieces and `.pvtp` lists).
const FRAMES_DIR: &str = "frames";

fn is_checkpoint(name: &str) -> bool {
    (name.starts_with("checkpoint-") || name.starts_with(".checkpoint-")) && name.contains(".grck")
}

/// Whether `dir` holds the files of a run.
pub fn holds_run(dir: &Path) -> bool {
    if MARKERS.iter().any(|m| dir.join(m).exists()) {
        return true;
    }
    std::fs::read_dir(dir).is_ok_and(|rd| {
        rd.flatten()
            .any(|e| is_checkpoint(&e.file_name().to_string_lossy()))
    })
}

/// Makes `dir` ready for a fresh run: a folder that holds another run is
/// refused (an input error naming it and both ways out) unless `overwrite`,
/// which removes that run's files first.
pub fn claim(dir: &Path, overwrite: bool) -> Result<()> {
    if !holds_run(dir) {
        return Ok(());
    }
    if !overwrite {
        return Err(Error::input(format!(
            "{}: holds the files of another run; give another --out, or --overwrite \
             to replace that run (its frames, tables, pictures and checkpoints are removed)",
            dir.display()
        )));
    }
    let frames = dir.join(FRAMES_DIR);
    if frames.is_dir() {
        std::fs::remove_dir_all(&frames).map_err(|e| Error::io(&frames, e))?;
    }
    let rd = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    for entry in rd.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        if (RUN_FILES.contains(&name.as_str()) || is_checkpoint(&name)) && path.is_file() {
            std::fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
        }
    }
    Ok(())
}

/// [`claim`] for several folders (the variants of a sweep): all are
/// checked before any is emptied, so a refusal leaves every one as it was.
pub fn claim_all(dirs: &[PathBuf], overwrite: bool) -> Result<()> {
    if !overwrite {
        dirs.iter().try_for_each(|d| claim(d, false))?;
    }
    dirs.iter().try_for_each(|d| claim(d, overwrite))
}

/// `base` when it holds no run, else the first of `base-2`, `base-3`, …
/// that holds none: where a run writes when no folder was named.
pub fn fresh(base: &Path) -> PathBuf {
    if !holds_run(base) {
        return base.to_path_buf();
    }
    let name = base.file_name().map(|n| n.to_string_lossy().into_owned());
    let name = name.unwrap_or_else(|| "run".to_string());
    (2u64..)
        .map(|k| base.with_file_name(format!("{name}-{k}")))
        .find(|p| !holds_run(p))
        .expect("some numbered folder is free")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("grains-run-dir-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn an_empty_or_foreign_folder_is_claimed_as_it_is() {
        let d = scratch("foreign");
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        claim(&d, false).unwrap();
        assert!(d.join("notes.txt").exists());
        assert_eq!(fresh(&d), d);
    }

    #[test]
    fn a_run_is_refused_or_removed_but_other_files_stay() {
        let d = scratch("run");
        std::fs::create_dir_all(d.join("frames")).unwrap();
        std::fs::write(d.join("frames/frame_000004.vtp"), "old").unwrap();
        std::fs::write(d.join("thermo.csv"), "old").unwrap();
        std::fs::write(d.join("checkpoint-000000000100.grck"), "old").unwrap();
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        let err = claim(&d, false).unwrap_err().to_string();
        assert!(
            err.contains("--overwrite") && err.contains("another run"),
            "{err}"
        );
        assert!(d.join("thermo.csv").exists());
        claim(&d, true).unwrap();
        assert!(!d.join("frames").exists());
        assert!(!d.join("thermo.csv").exists());
        assert!(!d.join("checkpoint-000000000100.grck").exists());
        assert!(d.join("notes.txt").exists());
        assert!(!holds_run(&d));
    }

    #[test]
    fn a_fresh_name_skips_folders_that_hold_runs() {
        let d = scratch("fresh");
        let base = d.join("convection");
        for p in [base.clone(), d.join("convection-2")] {
            std::fs::create_dir_all(&p).unwrap();
            std::fs::write(p.join("summary.json"), "{}").unwrap();
        }
        assert_eq!(fresh(&base), d.join("convection-3"));
    }
}
