//! The variants of a parameter sweep (`grains sweep`, `grains.sweep` in
//! Python): the grid of values of the varied keys, each variant's `--set`
//! overrides and the name of its output directory.

/// Every combination of the values, the first key varying slowest.
pub fn grid(axes: &[(String, Vec<String>)]) -> Vec<Vec<String>> {
    let mut out = vec![Vec::new()];
    for (_, vals) in axes {
        out = out
            .into_iter()
            .flat_map(|row: Vec<String>| {
                vals.iter().map(move |v| {
                    let mut r = row.clone();
                    r.push(v.clone());
                    r
                })
            })
            .collect();
    }
    out
}

/// The `--set` overrides of one value of a varied key; `K1+K2+...` sets the
/// same value at every key (e.g. the frequency of all three vibrating walls
/// of a cell).
pub fn overrides(key: &str, value: &str) -> Vec<String> {
    key.split('+')
        .map(|k| format!("{}={value}", k.trim()))
        .collect()
}

/// The overrides of a whole variant: the fixed ones, then each varied
/// key's.
pub fn variant_sets(
    fixed: &[String],
    axes: &[(String, Vec<String>)],
    vals: &[String],
) -> Vec<String> {
    let mut sets = fixed.to_vec();
    sets.extend(
        axes.iter()
            .zip(vals)
            .flat_map(|((k, _), v)| overrides(k, v)),
    );
    sets
}

/// A directory name for a variant: key=value pairs joined by '_', with
/// characters unsafe in file names replaced.
pub fn variant_name(axes: &[(String, Vec<String>)], vals: &[String]) -> String {
    axes.iter()
        .zip(vals)
        .map(|((k, _), v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join("_")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "=._-+".contains(c) {
                c
            } else {
                '-'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_is_the_product_first_key_slowest() {
        let axes = vec![
            ("a".to_string(), vec!["1".to_string(), "2".to_string()]),
            ("b".to_string(), vec!["x".to_string(), "y".to_string()]),
        ];
        let g = grid(&axes);
        assert_eq!(g.len(), 4);
        assert_eq!(g[1], vec!["1".to_string(), "y".to_string()]);
        assert_eq!(variant_name(&axes, &g[2]), "a=2_b=x");
        assert_eq!(overrides("a + b", "3"), vec!["a=3", "b=3"]);
        assert_eq!(
            variant_sets(&["c=1".to_string()], &axes, &g[3]),
            vec!["c=1", "a=2", "b=y"]
        );
    }
}
