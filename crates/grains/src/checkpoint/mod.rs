//! Checkpoints: the complete state of a run in one file, so that a run
//! stopped at any moment continues bit for bit.
//!
//! A file is a fixed header and a payload:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `GRAINSCK` |
//! | 4 | format version (little endian), [`VERSION`] |
//! | 8 | payload length |
//! | 4 | CRC-32 of the payload |
//! | … | payload ([`run`]: the run's header and sections around the engine's bytes) |
//!
//! Files are written atomically (temporary file, fsync, rename) under names
//! `checkpoint-<step>.grck` that sort by step; the newest [`KEEP`] are kept.
//! See `docs/checkpoints.md`.

pub mod inputs;
pub mod interval;
pub mod run;

/// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320, as zip and PNG
/// use): the seal of a checkpoint file.
pub fn crc32(bytes: &[u8]) -> u32 {
    crc32fast::hash(bytes)
}

use crate::error::{Error, Result};
use crate::io::write_durable;
use std::path::{Path, PathBuf};

/// First bytes of every checkpoint file.
pub const MAGIC: &[u8; 8] = b"GRAINSCK";
/// Version of the layout; a file of another version is refused. Version 2
/// added the measurement section; version 3 dropped the DSMC index sort
/// (the DSMC store itself is kept in cell order) and added the convection
/// column profile; version 4 added the surface height per column; version
/// 5 moved a DSMC run's measurement state from the engine field into the
/// measurement section, as an MD run keeps it; version 6 added the
/// rolling springs of the MD state; version 7 added mesh walls' springs
/// and loads; version 8 made the base directory absolute and added the
/// scenario's input files (path, length, CRC-32); version 9 added the
/// flow section (an MD run's flow events and flow measurements).
pub const VERSION: u32 = 9;
/// Checkpoints kept in a run directory (older ones are deleted).
pub const KEEP: usize = 2;
const HEADER: usize = 8 + 4 + 8 + 4;
/// Largest payload accepted (a sanity bound against damaged headers).
const MAX_PAYLOAD: u64 = 1 << 40;

/// Wraps a payload in the header (magic, version, length, CRC).
pub fn seal(payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32(payload).to_le_bytes());
    out.extend_from_slice(payload);
    out
}

/// Checks the header of `bytes` (read from `origin`) and returns the payload.
/// Every failure is an input error naming the file and what is wrong.
pub fn unseal<'a>(bytes: &'a [u8], origin: &Path) -> Result<&'a [u8]> {
    let bad = |m: String| Error::input(format!("checkpoint {}: {m}", origin.display()));
    if bytes.len() < HEADER {
        return Err(bad(format!(
            "only {} bytes, shorter than the {HEADER}-byte header (truncated?)",
            bytes.len()
        )));
    }
    if &bytes[..8] != MAGIC {
        return Err(bad("not a grains checkpoint (wrong magic bytes)".into()));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(bad(format!(
            "format version {version}, but this grains reads version {VERSION} only"
        )));
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let crc = u32::from_le_bytes(bytes[20..24].try_into().expect("4 bytes"));
    let body = &bytes[HEADER..];
    if len > MAX_PAYLOAD || len != body.len() as u64 {
        return Err(bad(format!(
            "the header announces {len} bytes of state but {} follow (truncated or damaged)",
            body.len()
        )));
    }
    if crc32(body) != crc {
        return Err(bad(
            "checksum mismatch: the file is corrupted; use an older checkpoint".into(),
        ));
    }
    Ok(body)
}

/// The file name of the checkpoint at `step`.
pub fn file_name(step: u64) -> String {
    format!("checkpoint-{step:012}.grck")
}

/// Checkpoint files in `dir`, newest (highest step) first.
pub fn list(dir: &Path) -> Result<Vec<PathBuf>> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut v: Vec<(u64, PathBuf)> = rd
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let step = name
                .strip_prefix("checkpoint-")?
                .strip_suffix(".grck")?
                .parse()
                .ok()?;
            Some((step, e.path()))
        })
        .collect();
    v.sort_by_key(|e| std::cmp::Reverse(e.0));
    Ok(v.into_iter().map(|(_, p)| p).collect())
}

/// Writes a sealed checkpoint for `step` atomically into `dir` and deletes
/// all but the newest [`KEEP`]. Returns the path written.
pub fn write(dir: &Path, step: u64, payload: &[u8]) -> Result<PathBuf> {
    let path = dir.join(file_name(step));
    write_durable(&path, &seal(payload))?;
    // The rename is durable only once the directory itself is synced.
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    for old in list(dir)?.into_iter().skip(KEEP) {
        std::fs::remove_file(&old).map_err(|e| Error::io(&old, e))?;
    }
    Ok(path)
}

/// Writes a sealed checkpoint to `path` atomically: a file of its own,
/// outside the rotation of a run directory's checkpoints.
pub fn write_to(path: &Path, payload: &[u8]) -> Result<()> {
    crate::io::write_atomic(path, &seal(payload))
}

/// Removes temporary files of checkpoint writes that were interrupted (a
/// killed process leaves them; they are never read).
pub fn remove_stale_temporaries(dir: &Path) {
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with(".checkpoint-") && name.contains(".grck.tmp") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Reads and checks one checkpoint file; returns its payload.
pub fn read(path: &Path) -> Result<Vec<u8>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    Ok(unseal(&bytes, path)?.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seal_round_trips_and_damage_is_named() {
        let p = Path::new("x.grck");
        let sealed = seal(b"hello state");
        assert_eq!(unseal(&sealed, p).unwrap(), b"hello state");
        let e = unseal(&sealed[..sealed.len() - 1], p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.grck") && e.contains("truncated"), "{e}");
        let mut c = sealed.clone();
        *c.last_mut().unwrap() ^= 1;
        let e = unseal(&c, p).unwrap_err().to_string();
        assert!(e.contains("checksum"), "{e}");
        let mut v = sealed.clone();
        v[8] = 99;
        let e = unseal(&v, p).unwrap_err().to_string();
        assert!(e.contains("version 99"), "{e}");
        let e = unseal(b"short", p).unwrap_err().to_string();
        assert!(e.contains("header"), "{e}");
    }
}
