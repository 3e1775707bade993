//! How often a run writes a checkpoint: simulated seconds or a number of
//! steps, as `--checkpoint-every` gives it.

use crate::error::{Error, Result};

/// A checkpoint interval: simulated seconds or a number of steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Every {
    Seconds(f64),
    Steps(u64),
}

impl Every {
    /// Parses `0.01` (seconds) or `500steps` / `500 steps`.
    pub fn parse(text: &str) -> Result<Self> {
        let t = text.trim();
        let bad = || {
            Error::input(format!(
                "--checkpoint-every '{text}': give simulated seconds (e.g. 0.01) \
                 or a step count (e.g. 500steps)"
            ))
        };
        if let Some(n) = t.strip_suffix("steps").or_else(|| t.strip_suffix("step")) {
            let n: u64 = n.trim().parse().map_err(|_| bad())?;
            if n == 0 {
                return Err(bad());
            }
            return Ok(Every::Steps(n));
        }
        let s = t.strip_suffix('s').unwrap_or(t).trim();
        let v: f64 = s.parse().map_err(|_| bad())?;
        if !(v.is_finite() && v > 0.0) {
            return Err(bad());
        }
        Ok(Every::Seconds(v))
    }

    /// The interval in steps of `dt` (at least one).
    pub fn steps(self, dt: f64) -> u64 {
        match self {
            Every::Steps(n) => n.max(1),
            Every::Seconds(t) => {
                let n = (t / dt).round();
                if n >= 1.0 && n < u64::MAX as f64 {
                    n as u64
                } else {
                    1
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_parse() {
        assert_eq!(Every::parse("0.01").unwrap(), Every::Seconds(0.01));
        assert_eq!(Every::parse("500steps").unwrap(), Every::Steps(500));
        assert_eq!(Every::parse("20 steps").unwrap(), Every::Steps(20));
        assert_eq!(Every::Seconds(0.01).steps(1e-4), 100);
        for bad in ["", "0", "-1", "nan", "0steps", "xsteps", "inf"] {
            assert!(Every::parse(bad).is_err(), "{bad}");
        }
    }
}
