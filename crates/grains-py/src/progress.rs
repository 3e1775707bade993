//! The progress bar of `Simulation.run(..., progress=True)`: one line on
//! Python's `sys.stderr` (so that notebooks and pytest see it too), drawn
//! again in place (`\r`) whenever the run comes back for Python's signals
//! (every fifth of a second or so), ended with a newline.

use pyo3::prelude::*;
use std::time::Instant;

/// Characters of the bar between its brackets.
const WIDTH: usize = 30;

/// A bar for a run of `total` steps, begun now.
pub struct Bar {
    total: u64,
    started: Instant,
}

impl Bar {
    pub fn new(total: u64) -> Self {
        Self {
            total,
            started: Instant::now(),
        }
    }

    /// Draws the bar at `done` of the steps, at simulated time `time` (s).
    pub fn draw(&self, py: Python<'_>, done: u64, time: f64) -> PyResult<()> {
        let elapsed = self.started.elapsed().as_secs_f64();
        write(py, &format!("\r{}", line(done, self.total, time, elapsed)))
    }

    /// Ends the bar's line.
    pub fn end(&self, py: Python<'_>) -> PyResult<()> {
        write(py, "\n")
    }
}

/// The bar's text: `[#####.....]  50% 500/1000 steps  t = 1.0000e-2 s  ETA 3 s`.
fn line(done: u64, total: u64, time: f64, elapsed: f64) -> String {
    let frac = if total == 0 {
        1.0
    } else {
        done as f64 / total as f64
    };
    let filled = ((frac * WIDTH as f64).round() as usize).min(WIDTH);
    let eta = if done == 0 {
        "?".to_string()
    } else {
        format!("{:.0} s", elapsed * (total - done) as f64 / done as f64)
    };
    format!(
        "[{}{}] {:3.0}% {done}/{total} steps  t = {time:.4e} s  ETA {eta}",
        "#".repeat(filled),
        ".".repeat(WIDTH - filled),
        100.0 * frac
    )
}

fn write(py: Python<'_>, text: &str) -> PyResult<()> {
    let err = py.import("sys")?.getattr("stderr")?;
    err.call_method1("write", (text,))?;
    err.call_method0("flush")?;
    Ok(())
}
