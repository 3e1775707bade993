//! `--set KEY=VALUE` overrides: dotted paths into the scenario's TOML tree,
//! applied before the tree is checked against the schema, so an override is
//! validated exactly like the file itself. Array entries are addressed by
//! index (`walls.0.motion.frequency=60`).

use crate::error::{Error, Result};
use toml::Value;

/// Parses `KEY=VALUE`; VALUE is read as a TOML value (number, boolean,
/// array, inline table, quoted string) and as a bare string otherwise.
pub fn parse_assignment(text: &str) -> Result<(String, Value)> {
    let Some((key, raw)) = text.split_once('=') else {
        return Err(Error::input(format!(
            "--set {text}: expected KEY=VALUE, e.g. --set contact.mu=0.3"
        )));
    };
    let key = key.trim();
    if key.is_empty() || key.split('.').any(str::is_empty) {
        return Err(Error::input(format!(
            "--set {text}: the key must be a dotted path such as contact.mu"
        )));
    }
    let raw = raw.trim();
    let value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
        Ok(mut t) => t.remove("v").unwrap_or(Value::String(raw.to_string())),
        Err(_) => Value::String(raw.to_string()),
    };
    Ok((key.to_string(), value))
}

/// Sets `value` at the dotted `key` in `root`, creating tables on the way.
pub fn apply(root: &mut Value, key: &str, value: Value) -> Result<()> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut node = root;
    for (depth, part) in parts.iter().enumerate() {
        let last = depth + 1 == parts.len();
        let here = parts[..=depth].join(".");
        node = match node {
            Value::Table(t) => {
                if last {
                    t.insert(part.to_string(), value);
                    return Ok(());
                }
                t.entry(part.to_string())
                    .or_insert_with(|| Value::Table(Default::default()))
            }
            Value::Array(a) => {
                let idx: usize = part.parse().map_err(|_| {
                    Error::input(format!(
                        "--set {key}: `{here}` indexes a list; use a number such as 0"
                    ))
                })?;
                let len = a.len();
                let slot = a.get_mut(idx).ok_or_else(|| {
                    Error::input(format!(
                        "--set {key}: `{here}` is out of range (the list has {len} entries)"
                    ))
                })?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => {
                return Err(Error::input(format!(
                    "--set {key}: `{}` is a value, not a table",
                    parts[..depth].join(".")
                )))
            }
        };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_nested_keys_and_list_entries() {
        let mut v: Value =
            toml::from_str("[contact]\nmu = 0.5\n[[walls]]\nname = \"a\"\n").unwrap();
        let (k, x) = parse_assignment("contact.mu=0.3").unwrap();
        apply(&mut v, &k, x).unwrap();
        assert_eq!(v["contact"]["mu"].as_float(), Some(0.3));
        let (k, x) = parse_assignment("walls.0.name=bottom").unwrap();
        apply(&mut v, &k, x).unwrap();
        assert_eq!(v["walls"][0]["name"].as_str(), Some("bottom"));
        let (k, x) = parse_assignment("run.dt=auto").unwrap();
        apply(&mut v, &k, x).unwrap();
        assert_eq!(v["run"]["dt"].as_str(), Some("auto"));
    }

    #[test]
    fn clear_errors() {
        assert!(parse_assignment("contact.mu").is_err());
        assert!(parse_assignment("contact..mu=1").is_err());
        let mut v: Value = toml::from_str("[[walls]]\nname = \"a\"\n").unwrap();
        let e = apply(&mut v, "walls.3.name", Value::Integer(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("out of range"), "{e}");
        let e = apply(&mut v, "walls.x", Value::Integer(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("number"), "{e}");
    }
}
