//! Which scenario keys a restart may change under a running state.
//!
//! A checkpointed state continues under a changed scenario (`grains resume
//! DIR --set …`, `grains run NEW.toml --from DIR`) when the changes leave the
//! state meaningful: the contact law and materials, gravity, the walls'
//! motions and removal times, the run's length and outputs, measurements.
//! What the state itself is made of cannot change: the dimension, the
//! method, the box, the grains, the walls' number, names and shapes, the
//! integrator (Gear-5 keeps its own history) and the neighbour skin (the
//! carried neighbour list was built with it). The time step may change
//! under velocity Verlet only; the engine checks that, since a default dt
//! follows from the contact law. [`Found::restart_with`] puts a checkpoint
//! under such a changed scenario.

use super::schema::Scenario;
use super::Loaded;
use crate::checkpoint::run::{scenario_text, Found};
use crate::dsmc::Method;
use crate::error::{Error, Result};
use toml::Value;

/// Top-level keys that may not change at all.
const FIXED: &[&str] = &[
    "dimension",
    "method",
    "domain",
    "particles",
    "hopper",
    "dsmc",
    "inlets",
    "outlets",
    "sensors",
];
/// Keys under `run` that may not change.
const FIXED_RUN: &[&str] = &["integrator", "skin", "device"];
/// Keys of a wall that may change; the others (name, shape) may not.
const WALL_FREE: &[&str] = &["motion", "remove_at", "material"];

/// The dotted keys where `a` and `b` differ, in key order.
fn diff(prefix: &str, a: Option<&Value>, b: Option<&Value>, out: &mut Vec<String>) {
    match (a, b) {
        (Some(Value::Table(x)), Some(Value::Table(y))) => {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                diff(&join(prefix, k), x.get(k), y.get(k), out);
            }
        }
        // Arrays of tables (walls, materials) by entry; vectors whole.
        (Some(Value::Array(x)), Some(Value::Array(y)))
            if x.len() == y.len() && x.iter().all(Value::is_table) =>
        {
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                diff(&join(prefix, &i.to_string()), Some(p), Some(q), out);
            }
        }
        (x, y) if x == y => {}
        _ => out.push(prefix.to_string()),
    }
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// Why `key` (dotted) may not change under a running state, if it may not.
fn refusal(key: &str) -> Option<&'static str> {
    let parts: Vec<&str> = key.split('.').collect();
    match parts.as_slice() {
        [top, ..] if FIXED.contains(top) => Some("the state is made of it"),
        ["run", k, ..] if FIXED_RUN.contains(k) => Some("the carried state was made with it"),
        ["walls"] => Some("the number of walls is part of the state"),
        ["walls", _, k, ..] if !WALL_FREE.contains(k) => Some(
            "a wall's name and shape are part of the state (its motion and removal may change)",
        ),
        ["walls", _] => Some("the number of walls is part of the state"),
        _ => None,
    }
}

/// The keys where `new` differs from `old` (the checkpoint's scenario), or
/// an input error naming the first that may not change and why; `what`
/// names the change in the message (`--set` overrides, a scenario file).
pub fn check_changes(old: &Scenario, new: &Scenario, what: &str) -> Result<Vec<String>> {
    let to_value = |s: &Scenario| {
        Value::try_from(s)
            .map_err(|e| Error::input(format!("restart: cannot compare the scenarios: {e}")))
    };
    let (a, b) = (to_value(old)?, to_value(new)?);
    let mut changed = Vec::new();
    diff("", Some(&a), Some(&b), &mut changed);
    for key in &changed {
        if let Some(why) = refusal(key) {
            return Err(Error::input(format!(
                "{what}: `{key}` cannot change under a running state ({why}); a restart \
                 may change contact, materials, material_pairs, gravity, walls.N.motion, \
                 walls.N.remove_at, walls.N.material, run (but not run.integrator, run.skin \
                 or run.device), output, measure, seed, name and description"
            )));
        }
    }
    changed.retain(|k| k != "name" && k != "description");
    Ok(changed)
}

impl Found {
    /// This checkpoint's state continued under `new`, a changed scenario
    /// (a restart): refused, naming the key, when a change would not leave
    /// the state meaningful ([`check_changes`]); `what` names the
    /// change in messages.
    pub fn restart_with(mut self, new: Loaded, what: &str) -> Result<Self> {
        if self.loaded.scenario.method == Method::Dsmc || new.scenario.method == Method::Dsmc {
            return Err(Error::input(format!(
                "{what}: a DSMC checkpoint resumes as it was; a restart with changes is for MD runs"
            )));
        }
        let changed = check_changes(&self.loaded.scenario, &new.scenario, what)?;
        self.restarted_from = Some(std::mem::replace(&mut self.loaded, new));
        self.restart = Some(changed);
        Ok(self)
    }

    /// [`Found::restart_with`] the checkpoint's own scenario with `sets`
    /// (`KEY=VALUE`) applied.
    pub fn restart_with_sets(self, sets: &[String]) -> Result<Self> {
        let text = scenario_text(&self.loaded.scenario)?;
        let base = self.loaded.base_dir.clone();
        let origin = format!(
            "{} (checkpoint {})",
            self.loaded.origin,
            self.path.display()
        );
        let new = super::load_str(&text, &origin, base, sets)?;
        self.restart_with(new, "--set")
    }

    /// The scenario keys a restart changed; `None` for a plain resume.
    pub fn changed_keys(&self) -> Option<&[String]> {
        self.restart.as_deref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::load_str;
    use std::path::PathBuf;

    fn scenario(sets: &[&str]) -> Scenario {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/repose-2d.toml"),
        )
        .unwrap();
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        load_str(&text, "repose-2d", PathBuf::from("."), &sets)
            .unwrap()
            .scenario
    }

    #[test]
    fn the_law_gravity_and_motions_may_change() {
        let old = scenario(&[]);
        let new = scenario(&[
            "contact.mu=0.123",
            "gravity=[1.0, -9.0]",
            "run.duration=0.5",
        ]);
        let changed = check_changes(&old, &new, "--set").unwrap();
        assert!(changed.contains(&"contact.mu".to_string()), "{changed:?}");
        assert!(
            changed.iter().any(|k| k.starts_with("gravity")),
            "{changed:?}"
        );
        assert!(changed.contains(&"run.duration".to_string()), "{changed:?}");
        assert!(check_changes(&old, &old, "--set").unwrap().is_empty());
    }

    #[test]
    fn the_state_keys_are_refused_by_name() {
        let old = scenario(&[]);
        for (set, key) in [
            ("particles.count=17", "particles.count"),
            ("domain.hi=[1.0, 1.0]", "domain.hi"),
            ("run.integrator=\"gear5\"", "run.integrator"),
            ("run.skin=0.9", "run.skin"),
            ("walls.0.name=\"other\"", "walls.0.name"),
        ] {
            let new = scenario(&[set]);
            let err = check_changes(&old, &new, "--set").unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}`")), "{set}: {err}");
        }
    }
}
