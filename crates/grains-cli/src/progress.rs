//! Progress reporting: a bar on a terminal, periodic log lines otherwise.

use grains::runner::{Progress, Silent};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Picks the reporter for this process's standard error.
pub fn for_terminal(quiet: bool) -> Box<dyn Progress> {
    if quiet {
        Box::new(Silent)
    } else if std::io::stderr().is_terminal() {
        Box::new(Bar { bar: None })
    } else {
        Box::new(LogLines::default())
    }
}

struct Bar {
    bar: Option<ProgressBar>,
}

impl Progress for Bar {
    fn phase(&mut self, name: &str, total: u64) {
        if let Some(b) = self.bar.take() {
            b.finish();
        }
        let b = ProgressBar::new(total);
        b.set_style(
            ProgressStyle::with_template(
                "{prefix:>6} [{bar:40}] {pos}/{len} steps  {msg}  {per_sec}  ETA {eta}",
            )
            .expect("static template")
            .progress_chars("=> "),
        );
        b.set_prefix(name.to_string());
        self.bar = Some(b);
    }

    fn advance(&mut self, done: u64, time: f64) {
        if let Some(b) = &self.bar {
            b.set_position(done);
            b.set_message(format!("t = {time:.4e} s"));
        }
    }

    fn finish(&mut self) {
        if let Some(b) = self.bar.take() {
            b.finish();
        }
    }
}

/// One line every few seconds, for logs and pipes.
struct LogLines {
    /// Put after "grains: " on each line (a sweep's variant), or empty.
    label: String,
    /// The least time between two lines of a phase (its last line aside).
    every: Duration,
    /// Whether a phase's start gets a line of its own.
    announce: bool,
    name: String,
    total: u64,
    started: Option<Instant>,
    last: Option<Instant>,
}

impl Default for LogLines {
    fn default() -> Self {
        Self {
            label: String::new(),
            every: Duration::from_secs(5),
            announce: true,
            name: String::new(),
            total: 0,
            started: None,
            last: None,
        }
    }
}

/// The reporter of one variant of `grains sweep`, named `variant`: a line
/// at most every `every` (and at the end of each phase), each naming the
/// variant, so that a long variant shows how far it got among the lines
/// of the others running beside it.
pub fn for_variant(variant: &str, every: Duration) -> Box<dyn Progress> {
    Box::new(LogLines {
        label: format!("[{variant}] "),
        every,
        announce: false,
        ..LogLines::default()
    })
}

impl Progress for LogLines {
    fn phase(&mut self, name: &str, total: u64) {
        self.name = name.to_string();
        self.total = total;
        self.started = Some(Instant::now());
        self.last = Some(Instant::now());
        if self.announce {
            eprintln!("grains: {}{name}: {total} steps", self.label);
        }
    }

    fn advance(&mut self, done: u64, time: f64) {
        let now = Instant::now();
        if self.last.is_some_and(|l| now - l < self.every) && done < self.total {
            return;
        }
        self.last = Some(now);
        let elapsed = self
            .started
            .map_or(0.0, |s| (now - s).as_secs_f64())
            .max(1e-9);
        let rate = done as f64 / elapsed;
        let eta = (self.total - done) as f64 / rate.max(1e-9);
        eprintln!(
            "grains: {}{}: step {done}/{} t = {time:.4e} s, {rate:.0} steps/s, ETA {eta:.0} s",
            self.label, self.name, self.total
        );
    }

    fn finish(&mut self) {}
}
