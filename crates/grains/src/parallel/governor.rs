//! Chooses, slice by slice of a run, between all of the pool's threads and one.
//!
//! The engines' steps are a few short fork–join passes. On a machine whose
//! other cores run other programs (a laptop with a browser open, a shared
//! node, a sweep running jobs side by side), the kernel preempts a worker
//! for a time slice of milliseconds, and every join waits for it: two
//! threads then take several times as long as one. Which is faster depends
//! on the machine's load at that moment, which no setting knows, so the
//! governor times both and keeps the faster, looking at the other again
//! from time to time. The engines' results do not depend on the number of
//! threads (fixed chunks, joined in order), so the choice never changes a
//! bit of the result.

use std::time::Instant;

/// Wall time a slice of steps aims at: a fifth of the time to the next
/// probe, within these bounds. Long enough that a slice's own cost (its
/// predictor and corrector not fused with the neighbouring steps, the start
/// of the workers) is small, short enough to follow the load.
const SLICE_MIN: f64 = 0.02;
const SLICE_MAX: f64 = 0.2;
/// Wall time a probe of the other width aims at: what it costs when the
/// other width is the slower one.
const PROBE_SECONDS: f64 = 0.005;
/// Steps of the first slice, before anything is timed.
const FIRST_SLICE: u64 = 4;
/// Seconds run on the chosen width between two probes of the other: the
/// first interval, and the longest it grows to while probes keep confirming
/// the choice (doubling each time). A probe is [`PROBE_SECONDS`] at the
/// slower width, so once settled probing costs well under 1 %.
const PROBE_AFTER_MIN: f64 = 0.1;
const PROBE_AFTER_MAX: f64 = 10.0;
/// The other width must be this much faster to be chosen, so that noise
/// does not flip the choice.
const HYSTERESIS: f64 = 0.05;
/// Weight of a slice in its width's running estimate: small, because a
/// short slice is noisy (one preemption can double it).
const WEIGHT: f64 = 0.1;
/// The chosen width's estimate this much above its figure some slices after
/// it was chosen or confirmed (the load changed) brings the next probe
/// forward.
const SURPRISE: f64 = 1.5;
/// Slices after a choice or a confirmation before the estimate is taken as
/// the figure [`SURPRISE`] compares with.
const SETTLE: u32 = 16;

/// The two ways a slice can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Width {
    /// On the pool the call came from, all of its threads.
    Wide = 0,
    /// On the calling thread alone ([`super::serial`]).
    Narrow = 1,
}

impl Width {
    fn other(self) -> Self {
        match self {
            Width::Wide => Width::Narrow,
            Width::Narrow => Width::Wide,
        }
    }
}

/// Runs stretches of steps in slices, each on all the threads of the
/// current rayon pool or on the calling thread alone, whichever the recent
/// slices measured as faster per step.
#[derive(Default)]
pub struct Governor {
    /// Seconds per step of each width, `None` until timed.
    per_step: [Option<f64>; 2],
    choice: Option<Width>,
    /// The chosen width's estimate [`SETTLE`] slices after it was last
    /// chosen or confirmed, and the slices since then.
    baseline: f64,
    settled: u32,
    /// Seconds run since the last probe, and the seconds between probes.
    since_probe: f64,
    probe_after: f64,
    /// Steps run on each width, for the record.
    steps: [u64; 2],
}

impl Governor {
    /// Runs `steps` steps as `run(k)` calls (k steps each, in order) on the
    /// faster width, stopping at the first error. On a pool of one thread
    /// it is one call of `run(steps)`, untimed.
    pub fn run<E>(
        &mut self,
        steps: u64,
        mut run: impl FnMut(u64) -> Result<(), E>,
    ) -> Result<(), E> {
        if steps == 0 {
            return Ok(());
        }
        if rayon::current_num_threads() < 2 {
            self.steps[Width::Wide as usize] += steps;
            return run(steps);
        }
        let mut left = steps;
        while left > 0 {
            let (width, probe) = self.next_width();
            let len = self.slice_len(width, probe).min(left);
            let started = Instant::now();
            match width {
                Width::Narrow => super::serial(|| run(len))?,
                Width::Wide => run(len)?,
            }
            let seconds = started.elapsed().as_secs_f64();
            self.record(width, probe, seconds / len as f64);
            self.since_probe += seconds;
            self.steps[width as usize] += len;
            left -= len;
        }
        Ok(())
    }

    /// The steps run so far on all the pool's threads and on one thread.
    pub fn steps_wide_narrow(&self) -> (u64, u64) {
        (self.steps[0], self.steps[1])
    }

    /// The width of the next slice, and whether it is a probe of the width
    /// not chosen.
    fn next_width(&self) -> (Width, bool) {
        let Some(choice) = self.choice else {
            // Untimed: the wide width first (the pool the caller asked for).
            return (Width::Wide, false);
        };
        let other = choice.other();
        let probe = self.per_step[other as usize].is_none() || self.since_probe >= self.probe_after;
        (if probe { other } else { choice }, probe)
    }

    fn slice_len(&self, width: Width, probe: bool) -> u64 {
        // A width not timed yet is sized by the other's figure.
        let known = self.per_step[width as usize].or(self.per_step[width.other() as usize]);
        let Some(per_step) = known else {
            return FIRST_SLICE;
        };
        let seconds = if probe {
            PROBE_SECONDS
        } else {
            (self.probe_after / 5.0).clamp(SLICE_MIN, SLICE_MAX)
        };
        // At least one step; a step that cannot be timed (0 s) is cheap.
        (seconds / per_step.max(1e-9)).clamp(1.0, 1e9) as u64
    }

    fn record(&mut self, width: Width, probe: bool, per_step: f64) {
        let Some(choice) = self.choice else {
            self.per_step[width as usize] = Some(per_step);
            self.choice = Some(width);
            self.settled = 0;
            self.probe_after = PROBE_AFTER_MIN;
            return;
        };
        if probe {
            // The probed width's old figure is stale: replace it.
            self.per_step[width as usize] = Some(per_step);
            let kept = self.per_step[choice as usize].unwrap_or(f64::INFINITY);
            if per_step < kept * (1.0 - HYSTERESIS) {
                self.choice = Some(width);
                self.probe_after = PROBE_AFTER_MIN;
            } else {
                self.probe_after = (self.probe_after * 2.0).min(PROBE_AFTER_MAX);
            }
            self.settled = 0;
            self.since_probe = 0.0;
            return;
        }
        let estimate = self.per_step[width as usize].get_or_insert(per_step);
        *estimate += WEIGHT * (per_step - *estimate);
        self.settled += 1;
        if self.settled == SETTLE {
            self.baseline = *estimate;
        } else if self.settled > SETTLE && *estimate > self.baseline * SURPRISE {
            self.since_probe = self.probe_after;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::pool_of;
    use super::*;

    /// The slices cover the stretch exactly, in order, and an error stops
    /// the run at once.
    #[test]
    fn slices_cover_the_steps_in_order_and_stop_at_an_error() {
        pool_of(2).install(|| {
            let mut g = Governor::default();
            let mut done = 0u64;
            for n in [0, 1, 7, 1000, 33] {
                let before = done;
                g.run(n, |k| {
                    assert!(k >= 1);
                    done += k;
                    Ok::<(), ()>(())
                })
                .unwrap();
                assert_eq!(done - before, n);
            }
            let (wide, narrow) = g.steps_wide_narrow();
            assert_eq!(wide + narrow, 1041);
            // A fresh governor's first two slices are short: the error
            // comes in the second of several.
            let mut g = Governor::default();
            let mut calls = 0;
            let r = g.run(500, |_| {
                calls += 1;
                if calls == 2 {
                    Err("unstable")
                } else {
                    Ok(())
                }
            });
            assert_eq!((r, calls), (Err("unstable"), 2));
        });
    }

    /// On one thread there is one call and no timing.
    #[test]
    fn one_thread_is_one_call() {
        pool_of(1).install(|| {
            let mut g = Governor::default();
            let mut calls = Vec::new();
            g.run(12345, |k| {
                calls.push(k);
                Ok::<(), ()>(())
            })
            .unwrap();
            assert_eq!(calls, vec![12345]);
        });
    }

    /// A narrow slice runs serially and a wide one on the caller's pool; a
    /// width whose steps are four times as costly is left after its first
    /// timing and then only probed, on ever fewer slices.
    #[test]
    fn the_faster_width_is_kept_and_the_other_probed_rarely() {
        pool_of(3).install(|| {
            let mut g = Governor::default();
            // Wide steps cost 40 µs, narrow ones 10 µs (the machine's other
            // cores busy, say).
            let cost = |wide: bool| std::time::Duration::from_micros(if wide { 40 } else { 10 });
            let mut per_width = [0u64; 2];
            g.run(20_000, |k| {
                let wide = super::super::min_len(1) == 1;
                per_width[usize::from(!wide)] += k;
                std::thread::sleep(cost(wide) * k as u32);
                Ok::<(), ()>(())
            })
            .unwrap();
            assert_eq!(g.steps_wide_narrow(), (per_width[0], per_width[1]));
            assert_eq!(g.choice, Some(Width::Narrow));
            // Probes are 5 ms, the first 0.1 s apart and then ever more:
            // well under a tenth of the steps ran wide.
            assert!(
                per_width[0] * 10 < per_width[1],
                "wide {} narrow {}",
                per_width[0],
                per_width[1]
            );
        });
    }
}
