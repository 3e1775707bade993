//! The files a scenario read, as a checkpoint records them: each one's
//! absolute path, length and CRC-32, so that a resumed run finds them from
//! any folder and refuses, by name, one that changed since.
//!
//! CRC-32 with the length tells an edited or replaced file from the one the
//! run read; it is no defence against a file made to collide on purpose.

use crate::codec::{Dec, Enc};
use crate::error::{Error, Result};
use crate::scenario::schema::{Placement, ShapeSpec};
use crate::scenario::Loaded;
use std::path::{Path, PathBuf};

/// One file the scenario read, as it was when the run started.
#[derive(Clone, Debug, PartialEq)]
pub struct InputFile {
    /// The scenario key that names the file (`particles.file`, `walls.2.shape.file`).
    pub key: String,
    /// Its absolute path.
    pub path: PathBuf,
    pub len: u64,
    pub crc: u32,
}

impl InputFile {
    /// The file at `path` as it is now.
    fn read(key: String, path: PathBuf) -> Result<Self> {
        let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
        Ok(Self {
            key,
            path,
            len: bytes.len() as u64,
            crc: super::crc32(&bytes),
        })
    }
}

/// The scenario keys that name files, with the paths they resolve to.
fn named_files(loaded: &Loaded) -> Vec<(String, PathBuf)> {
    let s = &loaded.scenario;
    let mut out = Vec::new();
    if let (Placement::File, Some(f)) = (&s.particles.placement, &s.particles.file) {
        out.push(("particles.file".to_string(), loaded.path(f)));
    }
    for (i, w) in s.walls.iter().enumerate() {
        if let ShapeSpec::Mesh { file, .. } = &w.shape {
            out.push((format!("walls.{i}.shape.file"), loaded.path(file)));
        }
    }
    out
}

/// The files `loaded` reads, each with its absolute path and its content now.
pub fn of_scenario(loaded: &Loaded) -> Result<Vec<InputFile>> {
    named_files(loaded)
        .into_iter()
        .map(|(key, p)| InputFile::read(key, absolute(&p)))
        .collect()
}

/// `p` made absolute against the current folder (not resolving links).
pub fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Checks that every recorded file still reads as it did; `origin` names
/// the checkpoint. A changed or missing file is an input error naming the
/// key and the file, unless `allow_changed`, when it is only reported in
/// the returned notes.
pub fn verify(inputs: &[InputFile], origin: &str, allow_changed: bool) -> Result<Vec<String>> {
    let mut notes = Vec::new();
    for f in inputs {
        let problem = match InputFile::read(f.key.clone(), f.path.clone()) {
            Ok(now) if now.len == f.len && now.crc == f.crc => continue,
            Ok(now) => format!(
                "{} = {} changed since the run read it ({} bytes, CRC-32 {:08x}; now {} bytes, {:08x})",
                f.key,
                f.path.display(),
                f.len,
                f.crc,
                now.len,
                now.crc
            ),
            Err(e) => format!("{} = {} cannot be read: {e}", f.key, f.path.display()),
        };
        if !allow_changed {
            return Err(Error::input(format!(
                "checkpoint {origin}: {problem}; restore the file, or resume with \
                 --allow-changed-inputs to use it as it is now"
            )));
        }
        notes.push(problem);
    }
    Ok(notes)
}

pub(crate) fn encode(e: &mut Enc, inputs: &[InputFile]) {
    e.len(inputs.len());
    for f in inputs {
        e.str(&f.key);
        e.str(&f.path.to_string_lossy());
        e.u64(f.len);
        e.u32(f.crc);
    }
}

pub(crate) fn decode(d: &mut Dec) -> std::result::Result<Vec<InputFile>, String> {
    let n = d.len(16, "input file count")?;
    let mut v = Vec::with_capacity(n);
    for _ in 0..n {
        v.push(InputFile {
            key: d.str("input file key")?,
            path: PathBuf::from(d.str("input file path")?),
            len: d.u64("input file length")?,
            crc: d.u32("input file CRC")?,
        });
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_changed_file_is_refused_by_key_unless_allowed() {
        let dir = std::env::temp_dir().join(format!("grains-inputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("grains.data");
        std::fs::write(&p, "first").unwrap();
        let rec = vec![InputFile::read("particles.file".into(), p.clone()).unwrap()];
        assert!(verify(&rec, "c", false).unwrap().is_empty());
        std::fs::write(&p, "other").unwrap();
        let err = verify(&rec, "c", false).unwrap_err().to_string();
        assert!(
            err.contains("particles.file") && err.contains("changed"),
            "{err}"
        );
        assert!(err.contains("--allow-changed-inputs"), "{err}");
        assert_eq!(verify(&rec, "c", true).unwrap().len(), 1);
        std::fs::remove_file(&p).unwrap();
        let err = verify(&rec, "c", false).unwrap_err().to_string();
        assert!(err.contains("cannot be read"), "{err}");
    }

    #[test]
    fn the_record_reads_back() {
        let rec = vec![InputFile {
            key: "walls.1.shape.file".into(),
            path: PathBuf::from("/x/cone.stl"),
            len: 84,
            crc: 0xdead_beef,
        }];
        let mut e = Enc::default();
        encode(&mut e, &rec);
        let mut d = Dec::new(&e.buf);
        assert_eq!(decode(&mut d).unwrap(), rec);
        assert_eq!(d.remaining(), 0);
    }
}
