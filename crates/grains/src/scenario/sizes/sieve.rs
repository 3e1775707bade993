//! A laboratory's sieve curve: a CSV of rows `diameter (m), cumulative %
//! passing`, read into intervals between the sieves, each holding the
//! share of the curve's weight that passed its upper sieve but not its
//! lower one, spread evenly inside (linear interpolation of the CDF).

use crate::error::{Error, Result};
use std::path::Path;

/// The curve's intervals (edges, ascending) and their shares (summing to
/// 1), cut to `[lo, hi]` (the CDF interpolated there) without the empty
/// intervals at either end. `name` is the file as the scenario writes it.
pub(super) fn read(path: &Path, name: &str, (lo, hi): (f64, f64)) -> Result<(Vec<f64>, Vec<f64>)> {
    let at = |what: String| Error::input(format!("particles.size.file = \"{name}\": {what}"));
    let text = std::fs::read_to_string(path)
        .map_err(|e| at(format!("cannot read {}: {e}", path.display())))?;
    let mut rows: Vec<(f64, f64)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split([',', ';', '\t', ' '])
            .map(str::trim)
            .filter(|f| !f.is_empty())
            .collect();
        let numbers: Option<Vec<f64>> = fields.iter().map(|f| f.parse().ok()).collect();
        match numbers.as_deref() {
            Some(&[d, c]) => rows.push((d, c)),
            // A header line before the first row of numbers.
            None if rows.is_empty() => continue,
            _ => {
                return Err(at(format!(
                    "line {}: expected two numbers, diameter in m and cumulative % passing, \
                     got `{line}`",
                    n + 1
                )))
            }
        }
    }
    if rows.len() < 2 {
        return Err(at(format!(
            "{} rows; a sieve curve needs at least two (diameter in m, cumulative % passing)",
            rows.len()
        )));
    }
    for (i, &(d, c)) in rows.iter().enumerate() {
        if !(d.is_finite() && d > 0.0) {
            return Err(at(format!(
                "row {}: diameter {d} must be positive (m)",
                i + 1
            )));
        }
        if !(c.is_finite() && (0.0..=100.0).contains(&c)) {
            return Err(at(format!("row {}: {c} % is not within 0 to 100", i + 1)));
        }
    }
    for (i, w) in rows.windows(2).enumerate() {
        if w[1].0 <= w[0].0 {
            return Err(at(format!(
                "row {}: diameters must increase strictly ({} after {})",
                i + 2,
                w[1].0,
                w[0].0
            )));
        }
        if w[1].1 < w[0].1 {
            return Err(at(format!(
                "row {}: the cumulative % passing falls ({} after {}); it never decreases",
                i + 2,
                w[1].1,
                w[0].1
            )));
        }
    }
    let (first, last) = (rows[0].1, rows[rows.len() - 1].1);
    if first != 0.0 || last != 100.0 {
        return Err(at(format!(
            "the curve runs from {first} % to {last} %: it must start at 0 % (the smallest \
             size, as a row with 0) and end at 100 %"
        )));
    }
    // The CDF at x, linear between sieves.
    let cdf = |x: f64| -> f64 {
        let j = rows.partition_point(|r| r.0 <= x);
        if j == 0 {
            return 0.0;
        }
        if j == rows.len() {
            return 100.0;
        }
        let (a, b) = (rows[j - 1], rows[j]);
        a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
    };
    let mut edges = vec![lo.max(rows[0].0)];
    edges.extend(rows.iter().map(|r| r.0).filter(|&d| d > lo && d < hi));
    edges.push(hi.min(rows[rows.len() - 1].0));
    edges.dedup();
    let mut share: Vec<f64> = edges.windows(2).map(|e| cdf(e[1]) - cdf(e[0])).collect();
    // Empty intervals at the ends: the sizes no grain can have.
    while share.first() == Some(&0.0) {
        share.remove(0);
        edges.remove(0);
    }
    while share.last() == Some(&0.0) {
        share.pop();
        edges.pop();
    }
    let total: f64 = share.iter().sum();
    if share.is_empty() || total <= 0.0 {
        return Err(at(format!(
            "no part of the curve lies within particles.size.min = {lo} and max = {hi}"
        )));
    }
    share.iter_mut().for_each(|s| *s /= total);
    Ok((edges, share))
}
