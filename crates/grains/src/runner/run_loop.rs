//! The run loop: advance the engine in fused stretches to the next step at
//! which some hook acts, then let every hook act there.
//!
//! A [`Hook`] says the next step at which it must see the engine
//! ([`Hook::next`]) and acts at the end of every stretch ([`Hook::act`],
//! which returns at once where it is not due). Outputs, each measurement,
//! the flow events, progress, the checkpoint interval and the signal stop
//! are hooks; a hook asks for a checkpoint or a stop through its
//! [`Control`], and the loop then gathers every hook's part of the
//! checkpoint ([`Hook::pack`]) and writes it. Between two such steps the
//! engine runs its fused pass ([`Engine::advance`]), the same bits as
//! single steps.

use super::checkpointer::Checkpointer;
pub(crate) use super::checkpointer::Saved;
use super::options::Progress;
use crate::engine::Engine;
use crate::error::Result;
use crate::output::Outputs;
use serde_json::Value;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The longest stretch the loop advances without letting its hooks look:
/// a stop request is honoured at most this many steps late.
pub(crate) const MAX_STRETCH: u64 = 256;

/// What a hook asks of the loop after acting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Control {
    Go,
    /// Write a checkpoint at this step.
    Save,
    /// Stop the run here (with a checkpoint when the run can take one).
    Stop,
}

/// Something that acts between the engine's steps.
pub(crate) trait Hook<E> {
    /// The first step after `now`, at most `horizon`, at which this hook
    /// must see the engine; `horizon` when none comes sooner.
    fn next(&self, now: u64, horizon: u64) -> u64;
    /// Called at the end of every stretch, at engine step `now`.
    fn act(&mut self, engine: &mut E, now: u64) -> Result<Control>;
    /// Adds this hook's state to a checkpoint.
    fn pack(&self, _saved: &mut Saved) -> Result<()> {
        Ok(())
    }
}

/// Advances `engine` to step `end`, the hooks acting at the end of every
/// stretch in their order. Returns the summary of an interrupted run when a
/// hook stopped it.
pub(crate) fn run_to<E: Engine>(
    engine: &mut E,
    end: u64,
    hooks: &mut [&mut dyn Hook<E>],
    ck: &Checkpointer,
) -> Result<Option<Value>> {
    while engine.step_count() < end {
        let now = engine.step_count();
        let horizon = end.min(now + MAX_STRETCH);
        let next = hooks
            .iter()
            .fold(horizon, |h, hook| hook.next(now, h).clamp(now + 1, h));
        engine.advance(next - now)?;
        let (mut save, mut stop) = (false, false);
        for h in hooks.iter_mut() {
            match h.act(engine, next)? {
                Control::Go => {}
                Control::Save => save = true,
                Control::Stop => stop = true,
            }
        }
        if save || stop {
            let mut saved = Saved::default();
            for h in hooks.iter() {
                h.pack(&mut saved)?;
            }
            if stop {
                return ck.interrupt(engine, &saved).map(Some);
            }
            ck.write(engine, &saved)?;
        }
    }
    Ok(None)
}

/// The steps `base + k·every` (k ≥ 1) of a phase, and its last step `end`
/// when given.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Every {
    pub base: u64,
    pub every: u64,
    pub end: Option<u64>,
}

impl Every {
    pub fn new(base: u64, every: u64, end: Option<u64>) -> Self {
        Self {
            base,
            every: every.max(1),
            end,
        }
    }

    pub fn due(&self, now: u64) -> bool {
        (now - self.base).is_multiple_of(self.every) || Some(now) == self.end
    }

    /// The next such step after `now`, at most `horizon`.
    pub fn next(&self, now: u64, horizon: u64) -> u64 {
        let k = (now - self.base) / self.every + 1;
        (self.base + k * self.every).min(horizon)
    }
}

/// What an output hook writes at its steps (rank 0 the files, every rank
/// its piece of a frame).
pub(crate) trait Recorder<E> {
    fn record(&mut self, outputs: Option<&mut Outputs>, engine: &mut E) -> Result<()>;
}

/// The output steps of a run (thermo rows, frames, …) at the steps of
/// `at`; while relaxing (`at` none) it never acts but says where the files
/// stand.
pub(crate) struct Record<'a, R> {
    pub outputs: Option<&'a mut Outputs>,
    pub at: Option<Every>,
    pub how: R,
}

impl<R> Record<'_, R> {
    /// Records the state now.
    pub fn now<E>(&mut self, engine: &mut E) -> Result<()>
    where
        R: Recorder<E>,
    {
        self.how.record(self.outputs.as_deref_mut(), engine)
    }
}

impl<E, R: Recorder<E>> Hook<E> for Record<'_, R> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        self.at.map_or(horizon, |a| a.next(now, horizon))
    }
    fn act(&mut self, engine: &mut E, now: u64) -> Result<Control> {
        if self.at.is_some_and(|a| a.due(now)) {
            self.now(engine)?;
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        if let Some(out) = &self.outputs {
            saved.outputs = Some(out.state()?);
        }
        Ok(())
    }
}

/// Progress reports every [`MAX_STRETCH`] steps of a phase and at its end.
pub(crate) struct Report<'a> {
    progress: &'a mut dyn Progress,
    at: Every,
}

impl<'a> Report<'a> {
    /// A phase whose step k is engine step `base + k`, ending at `end`.
    pub fn new(progress: &'a mut dyn Progress, base: u64, end: u64) -> Self {
        Self {
            progress,
            at: Every::new(base, MAX_STRETCH, Some(end)),
        }
    }
}

impl<E: Engine> Hook<E> for Report<'_> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        self.at.next(now, horizon)
    }
    fn act(&mut self, engine: &mut E, now: u64) -> Result<Control> {
        if self.at.due(now) {
            self.progress.advance(now - self.at.base, engine.sim_time());
        }
        Ok(Control::Go)
    }
}

/// A checkpoint at every multiple of the interval (engine steps).
pub(crate) struct Interval(pub Option<u64>);

impl<E> Hook<E> for Interval {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        match self.0 {
            Some(n) => Every::new(0, n, None).next(now, horizon),
            None => horizon,
        }
    }
    fn act(&mut self, _: &mut E, now: u64) -> Result<Control> {
        Ok(match self.0 {
            Some(n) if now.is_multiple_of(n) => Control::Save,
            _ => Control::Go,
        })
    }
}

/// Stops the run at the end of the stretch in which a signal handler set
/// the flag (on any rank: the ranks agree on the step).
pub(crate) struct StopFlag(pub Option<Arc<AtomicBool>>);

impl<E: Engine> Hook<E> for StopFlag {
    fn next(&self, _: u64, horizon: u64) -> u64 {
        horizon
    }
    fn act(&mut self, engine: &mut E, _: u64) -> Result<Control> {
        Ok(match &self.0 {
            Some(s) if engine.any_rank(s.load(Ordering::SeqCst)) => Control::Stop,
            _ => Control::Go,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Frame;

    /// An engine that only counts its steps and records its stretches.
    #[derive(Default)]
    struct Counter {
        step: u64,
        stretches: Vec<u64>,
    }

    impl Engine for Counter {
        fn dim(&self) -> usize {
            2
        }
        fn step_count(&self) -> u64 {
            self.step
        }
        fn sim_time(&self) -> f64 {
            self.step as f64
        }
        fn time_step(&self) -> f64 {
            1.0
        }
        fn advance(&mut self, n: u64) -> Result<()> {
            self.stretches.push(n);
            self.step += n;
            Ok(())
        }
        fn frame(&self) -> Result<Frame> {
            Ok(Frame::default())
        }
        fn export(&self) -> Result<Vec<u8>> {
            Ok(self.step.to_le_bytes().to_vec())
        }
        fn import(&mut self, _: &[u8], _: &str) -> Result<()> {
            Ok(())
        }
    }

    /// A hook that notes the steps it is due at, and whether it was
    /// called at a step it did not ask for.
    struct Seen {
        at: Every,
        seen: Vec<u64>,
    }

    impl Hook<Counter> for Seen {
        fn next(&self, now: u64, horizon: u64) -> u64 {
            self.at.next(now, horizon)
        }
        fn act(&mut self, _: &mut Counter, now: u64) -> Result<Control> {
            if self.at.due(now) {
                self.seen.push(now);
            }
            Ok(Control::Go)
        }
    }

    fn dir(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("grains-loop-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn every_counts_from_its_base_and_stops_at_the_end() {
        let e = Every::new(10, 4, Some(21));
        assert!(e.due(14) && e.due(18) && e.due(21) && !e.due(15));
        assert_eq!(e.next(10, 100), 14);
        assert_eq!(e.next(14, 100), 18);
        assert_eq!(e.next(15, 100), 18);
        assert_eq!(e.next(15, 16), 16);
    }

    #[test]
    fn stretches_end_exactly_where_some_hook_acts() {
        let d = dir("stretch");
        let ck = Checkpointer::in_dir(&d, None);
        let mut e = Counter::default();
        let mut a = Seen {
            at: Every::new(0, 7, None),
            seen: vec![],
        };
        let mut b = Seen {
            at: Every::new(3, 10, Some(600)),
            seen: vec![],
        };
        let mut hooks: [&mut dyn Hook<Counter>; 2] = [&mut a, &mut b];
        assert!(run_to(&mut e, 600, &mut hooks, &ck).unwrap().is_none());
        assert_eq!(e.step, 600);
        let want_a: Vec<u64> = (1..=85).map(|k| 7 * k).collect();
        let mut want_b: Vec<u64> = (1..=59).map(|k| 3 + 10 * k).collect();
        want_b.push(600);
        assert_eq!(a.seen, want_a);
        assert_eq!(b.seen, want_b);
        // The stretch ends are the union of both hooks' steps: no step
        // more, none less.
        let mut ends: Vec<u64> = want_a.iter().chain(&want_b).copied().collect();
        ends.sort_unstable();
        ends.dedup();
        let got: Vec<u64> = e
            .stretches
            .iter()
            .scan(0, |s, n| {
                *s += n;
                Some(*s)
            })
            .collect();
        assert_eq!(got, ends);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_lone_engine_stops_to_look_every_max_stretch_steps() {
        let d = dir("cap");
        let ck = Checkpointer::in_dir(&d, None);
        let mut e = Counter::default();
        let mut stop = StopFlag(None);
        let mut hooks: [&mut dyn Hook<Counter>; 1] = [&mut stop];
        run_to(&mut e, 1000, &mut hooks, &ck).unwrap();
        assert_eq!(e.stretches, vec![256, 256, 256, 232]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn checkpoints_at_the_interval_and_a_stop_with_one() {
        let d = dir("ck");
        let ck = Checkpointer::in_dir(&d, Some(40));
        let mut e = Counter::default();
        let flag = Arc::new(AtomicBool::new(false));
        let mut interval = Interval(Some(40));
        let mut stop = StopFlag(Some(flag.clone()));
        {
            let mut hooks: [&mut dyn Hook<Counter>; 2] = [&mut interval, &mut stop];
            assert!(run_to(&mut e, 100, &mut hooks, &ck).unwrap().is_none());
        }
        // Steps 40 and 80; the newest two are kept.
        let names: Vec<String> = crate::checkpoint::list(&d)
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                crate::checkpoint::file_name(80),
                crate::checkpoint::file_name(40)
            ]
        );
        flag.store(true, Ordering::SeqCst);
        let mut hooks: [&mut dyn Hook<Counter>; 2] = [&mut interval, &mut stop];
        let summary = run_to(&mut e, 1000, &mut hooks, &ck).unwrap().unwrap();
        // The stop comes at the end of the first stretch (the interval's
        // next step), with a checkpoint there.
        assert_eq!(e.step, 120);
        assert_eq!(summary["interrupted"], true);
        assert_eq!(summary["step"], 120);
        assert!(d.join(crate::checkpoint::file_name(120)).is_file());
        let _ = std::fs::remove_dir_all(&d);
    }
}
