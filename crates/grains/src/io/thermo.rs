//! A CSV table of scalar observables (thermodynamic output): one header line
//! naming the columns, then one row per call, flushed at once so the file
//! can be followed with `tail -f` while a run goes on.

use super::Num;
use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub struct ThermoWriter {
    path: PathBuf,
    columns: Vec<String>,
    out: BufWriter<File>,
    line: String,
}

impl ThermoWriter {
    /// Creates (or truncates) the file and writes the header.
    pub fn create(path: &Path, columns: &[&str]) -> Result<Self> {
        if let Some(bad) = columns
            .iter()
            .find(|c| c.is_empty() || c.contains([',', '\n', '"']))
        {
            return Err(Error::input(format!(
                "{}: thermo column name '{bad}' is not allowed: names must be non-empty, without commas, quotes or newlines",
                path.display()
            )));
        }
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut w = ThermoWriter {
            path: path.to_path_buf(),
            columns: columns.iter().map(|c| c.to_string()).collect(),
            out: BufWriter::new(file),
            line: String::new(),
        };
        let header = w.columns.join(",");
        w.emit(&header)?;
        Ok(w)
    }

    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes one row; `values` must have one entry per column. Numbers are
    /// written in Rust's shortest round-trip form (full precision).
    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        if values.len() != self.columns.len() {
            return Err(Error::input(format!(
                "{}: thermo row has {} values but the table has {} columns ({})",
                self.path.display(),
                values.len(),
                self.columns.len(),
                self.columns.join(", ")
            )));
        }
        let mut line = std::mem::take(&mut self.line);
        line.clear();
        for (k, v) in values.iter().enumerate() {
            if k > 0 {
                line.push(',');
            }
            use std::fmt::Write as _;
            let _ = write!(line, "{}", Num(*v));
        }
        let r = self.emit(&line);
        self.line = line;
        r
    }

    fn emit(&mut self, line: &str) -> Result<()> {
        let path = &self.path;
        writeln!(self.out, "{line}")
            .and_then(|_| self.out.flush())
            .map_err(|e| Error::io(path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;

    #[test]
    fn rows_are_flushed_and_round_trip() {
        let dir = scratch_dir("thermo");
        let path = dir.join("thermo.csv");
        let mut w = ThermoWriter::create(&path, &["step", "time", "ke"]).unwrap();
        w.write_row(&[0.0, 0.0, 1.0 / 3.0]).unwrap();
        w.write_row(&[100.0, 0.01, 1e-300]).unwrap();
        // Not dropped yet: the rows must already be on disk.
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "step,time,ke");
        let back: Vec<f64> = lines[1].split(',').map(|t| t.parse().unwrap()).collect();
        assert_eq!(back, vec![0.0, 0.0, 1.0 / 3.0]);
        assert_eq!(lines[2], "100,0.01,1e-300");
        let e = w.write_row(&[1.0]).unwrap_err().to_string();
        assert!(
            e.contains("thermo.csv") && e.contains("1 values but the table has 3 columns"),
            "{e}"
        );
    }

    #[test]
    fn bad_column_name_is_refused() {
        let dir = scratch_dir("thermo-bad");
        let e = ThermoWriter::create(&dir.join("t.csv"), &["a,b"])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("t.csv") && e.contains("'a,b'"), "{e}");
    }
}
