//! Polyline files for 2D mesh walls: plain text, one point `x y` (or
//! `x, y`) per line, a blank line between separate polylines, `#` starting
//! a comment. A closed outline repeats its first point at its end.
//!
//! Written here rather than through a crate: the format is two numbers a
//! line, and the errors must name the file's line.

use crate::error::{Error, Result};
use std::path::Path;

/// One polyline: its points in order.
pub type Polyline = Vec<[f64; 2]>;

/// Reads every polyline of the file at `path`; errors name the file and
/// the line.
pub fn read_polylines(path: &Path) -> Result<Vec<Polyline>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::input(format!(
            "polyline file {}: cannot be read as text: {e}",
            path.display()
        ))
    })?;
    parse_polylines(&text)
        .map_err(|e| Error::input(format!("polyline file {}: {e}", path.display())))
}

/// [`read_polylines`] on a file's text; errors without the file name.
pub fn parse_polylines(text: &str) -> std::result::Result<Vec<Polyline>, String> {
    let mut out: Vec<Polyline> = Vec::new();
    let mut current: Polyline = Vec::new();
    let mut first_line = 0;
    let mut finish = |current: &mut Polyline, first_line: usize| match current.len() {
        0 => Ok(()),
        1 => Err(format!(
            "line {first_line}: a polyline needs at least two points, this one has one"
        )),
        _ => {
            out.push(std::mem::take(current));
            Ok(())
        }
    };
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            if raw.trim().is_empty() {
                finish(&mut current, first_line)?;
            }
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        let [x, y] = fields[..] else {
            return Err(format!(
                "line {line_no}: expected two numbers `x y`, found {} fields in {line:?}",
                fields.len()
            ));
        };
        let num = |f: &str| {
            f.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("line {line_no}: {f:?} is not a finite number"))
        };
        let p = [num(x)?, num(y)?];
        if current.last() == Some(&p) {
            return Err(format!(
                "line {line_no}: the point ({}, {}) repeats the one before (a segment of \
                 zero length)",
                p[0], p[1]
            ));
        }
        if current.is_empty() {
            first_line = line_no;
        }
        current.push(p);
    }
    finish(&mut current, first_line)?;
    if out.is_empty() {
        return Err("holds no polyline (no lines of two numbers)".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polylines_are_split_by_blank_lines_and_comments_are_skipped() {
        let text = "# a floor\n0 0\n1, 0 # end\n\n\n2 1\n3 2\n2 1\n";
        let lines = parse_polylines(text).unwrap();
        assert_eq!(
            lines,
            vec![
                vec![[0.0, 0.0], [1.0, 0.0]],
                vec![[2.0, 1.0], [3.0, 2.0], [2.0, 1.0]]
            ]
        );
    }

    #[test]
    fn bad_lines_are_named() {
        let err = |t: &str| parse_polylines(t).unwrap_err();
        assert!(err("0 0\n1 0 2\n").contains("line 2: expected two numbers"));
        assert!(err("0 0\n1 x\n").contains("line 2: \"x\" is not a finite number"));
        assert!(err("0 0\nNaN 1\n").contains("line 2"));
        assert!(err("0 0\n0 0\n").contains("line 2: the point (0, 0) repeats"));
        assert!(err("0 0\n\n1 1\n2 2\n").contains("line 1: a polyline needs at least two"));
        assert!(err("# nothing\n").contains("holds no polyline"));
        assert!(read_polylines(Path::new("/nonexistent/floor.txt"))
            .unwrap_err()
            .to_string()
            .contains("polyline file /nonexistent/floor.txt"));
    }
}
