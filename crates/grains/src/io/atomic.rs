//! Atomic file replacement: readers never see a half-written file.
//!
//! The outputs are not synced to the disk before the rename: on a machine
//! whose disk is busy (a build beside the run, say) an fsync per frame cost
//! the default run a quarter of its time. A rename still never shows a
//! reader a partial file; only a power cut or a kernel crash can lose the
//! newest outputs, and the checkpoints, which a resumed run starts from,
//! are synced ([`write_durable`]).

use crate::error::{Error, Result};
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The temporary name used next to `path` while it is written.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".to_string());
    // Unique per process and per call, so concurrent writers never share one.
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.tmp{}-{n}", std::process::id()))
}

/// Writes `bytes` to `path` atomically: the bytes go to a temporary file in
/// the same directory, which is then renamed over `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut w = AtomicWriter::create(path)?;
    w.write_all(bytes).map_err(|e| Error::io(path, e))?;
    w.finish(false)
}

/// As [`write_atomic`], with the temporary file synced to the disk before
/// the rename: for checkpoints, which must survive a power cut.
pub fn write_durable(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut w = AtomicWriter::create(path)?;
    w.write_all(bytes).map_err(|e| Error::io(path, e))?;
    w.finish(true)
}

/// A file being written under a temporary name; [`AtomicWriter::commit`]
/// renames it into place. Dropping it without committing removes the
/// temporary file and leaves any existing file at the target untouched.
pub struct AtomicWriter {
    target: PathBuf,
    temp: PathBuf,
    file: Option<std::io::BufWriter<File>>,
}

impl AtomicWriter {
    pub fn create(path: &Path) -> Result<Self> {
        let temp = temp_path(path);
        let file = File::create(&temp).map_err(|e| Error::io(path, e))?;
        Ok(AtomicWriter {
            target: path.to_path_buf(),
            temp,
            file: Some(std::io::BufWriter::new(file)),
        })
    }

    /// Flushes and renames the temporary file to the target.
    pub fn commit(self) -> Result<()> {
        self.finish(false)
    }

    fn finish(mut self, sync: bool) -> Result<()> {
        let target = self.target.clone();
        let buf = self.file.take().expect("AtomicWriter already committed");
        let file = buf
            .into_inner()
            .map_err(|e| Error::io(&target, e.into_error()))?;
        if sync {
            file.sync_all().map_err(|e| Error::io(&target, e))?;
        }
        drop(file);
        std::fs::rename(&self.temp, &target).map_err(|e| Error::io(&target, e))
    }
}

impl Write for AtomicWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.file
            .as_mut()
            .expect("AtomicWriter already committed")
            .write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file
            .as_mut()
            .expect("AtomicWriter already committed")
            .flush()
    }
}

impl Drop for AtomicWriter {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A fresh empty directory under the system temp dir for one test.
    pub(crate) fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("grains-io-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_replaces_and_leaves_no_temp() {
        let dir = scratch_dir("atomic");
        let p = dir.join("a.txt");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(entries(&dir), vec!["a.txt".to_string()]);
    }

    #[test]
    fn dropped_writer_leaves_target_untouched() {
        let dir = scratch_dir("atomic-drop");
        let p = dir.join("b.txt");
        write_atomic(&p, b"keep").unwrap();
        {
            let mut w = AtomicWriter::create(&p).unwrap();
            w.write_all(b"partial").unwrap();
        }
        assert_eq!(std::fs::read(&p).unwrap(), b"keep");
        assert_eq!(entries(&dir), vec!["b.txt".to_string()]);
    }

    #[test]
    fn error_names_the_path() {
        let p = Path::new("/nonexistent-dir-grains/x.txt");
        let msg = write_atomic(p, b"x").unwrap_err().to_string();
        assert!(msg.contains("/nonexistent-dir-grains/x.txt"), "{msg}");
    }
}
