//! Scenario files: the schema, presets, `--set` overrides, and the
//! builders that turn a scenario into a ready MD or DSMC engine.

pub mod build;
pub mod clumps;
pub mod device;
pub mod dsmc;
pub mod flow;
pub mod hopper;
pub mod inlet;
pub mod keys;
pub mod law_report;
pub mod materials;
pub mod memory;
mod mesh_wall;
pub mod outlet;
pub mod overrides;
pub mod packed;
pub mod placement;
pub mod resolve;
pub mod restart;
pub mod schema;
mod servo;
pub mod shapes;
pub mod shear;
pub mod sizes;
pub mod sweep;

pub use build::{build_md, build_md_parts, build_md_reporting};
pub use dsmc::build_dsmc;
pub use resolve::Resolved;
pub use schema::Scenario;

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// A scenario with the directory its relative paths are resolved against.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub scenario: Scenario,
    /// Where the scenario came from, for messages ("built-in default" if none).
    pub origin: String,
    /// Base directory for relative file paths in the scenario.
    pub base_dir: PathBuf,
}

impl Loaded {
    /// Resolves a path written in the scenario relative to its file.
    pub fn path(&self, p: &str) -> PathBuf {
        let p = Path::new(p);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }
}

/// Prefixes an input error with the scenario it was found in, unless the
/// message already names it.
pub fn in_scenario(e: Error, origin: &str) -> Error {
    match e {
        Error::Input(m) if !m.contains(origin) => Error::Input(format!("{origin}: {m}")),
        other => other,
    }
}

/// Reads a scenario file and applies `KEY=VALUE` overrides.
pub fn load_file(path: &Path, sets: &[String]) -> Result<Loaded> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let origin = path.display().to_string();
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    load_str(&text, &origin, base_dir, sets)
}

/// Parses scenario text; `origin` names it in messages.
pub fn load_str(text: &str, origin: &str, base_dir: PathBuf, sets: &[String]) -> Result<Loaded> {
    let mut tree: toml::Value =
        toml::from_str(text).map_err(|e| Error::input(format!("{origin}: {e}")))?;
    for s in sets {
        let (k, v) = overrides::parse_assignment(s)?;
        overrides::apply(&mut tree, &k, v)?;
    }
    let d0_given = tree.get("particles").and_then(|p| p.get("d0")).is_some();
    // Without overrides, read the text itself so schema errors keep their
    // line and column; overrides are applied to the parsed tree.
    let from_tree = |tree: toml::Value| -> std::result::Result<Scenario, String> {
        tree.try_into()
            .map_err(|e: toml::de::Error| e.to_string().trim_end().to_string())
    };
    let scenario = if sets.is_empty() {
        toml::from_str::<Scenario>(text).map_err(|e| {
            // The text parse knows the line; the tree parse names the key.
            let key = from_tree(tree).err().unwrap_or_default();
            Error::input(format!("{origin}: {}\n{key}", e.to_string().trim_end()))
        })?
    } else {
        from_tree(tree)
            .map_err(|e| Error::input(format!("{origin} (after --set overrides): {e}")))?
    };
    let mut scenario = scenario;
    scenario
        .parallel
        .validate(origin, scenario.dimension.axes())?;
    sizes::complete(&mut scenario, d0_given, &base_dir).map_err(|e| in_scenario(e, origin))?;
    shear::check(&scenario).map_err(|e| in_scenario(e, origin))?;
    clumps::check(&scenario).map_err(|e| in_scenario(e, origin))?;
    Ok(Loaded {
        scenario,
        origin: origin.to_string(),
        base_dir,
    })
}

/// The built-in default scenario: seed 002 Fig. 2 (convection from a
/// modulated amplitude). The same text ships as
/// `scenarios/seed-convection-modulated.toml`.
pub const DEFAULT_SCENARIO: &str =
    include_str!("../../../../scenarios/seed-convection-modulated.toml");

/// Loads the built-in default with overrides.
pub fn load_default(sets: &[String]) -> Result<Loaded> {
    load_str(
        DEFAULT_SCENARIO,
        "built-in default (seed-convection-modulated)",
        PathBuf::from("."),
        sets,
    )
}
