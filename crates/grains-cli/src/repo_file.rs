//! Files the benchmarks read from the repository: bench scenarios and the
//! clump benchmark's bodies, found from the working directory or the
//! source tree the binary was built from.

use grains::{Error, Result};
use std::path::PathBuf;

/// Finds `<dir>/<file>` from the working directory or the source tree;
/// `hint` ends the error's advice.
pub(crate) fn repo_file(dir: &str, file: &str, hint: &str) -> Result<PathBuf> {
    let here = PathBuf::from(dir).join(file);
    if here.exists() {
        return Ok(here);
    }
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(dir)
        .join(file);
    if source.exists() {
        return Ok(source);
    }
    Err(Error::input(format!(
        "cannot find {dir}/{file}: run `grains bench` from the repository root{hint}"
    )))
}
