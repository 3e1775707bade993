//! Where the engines' parallel loops run.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// Runs `f` on a worker of rayon's pool. The engines' parallel loops then
/// start from a pool thread; called from any other thread, each loop would
/// hand its work over and wait, a context switch per loop per step (which
/// cost a small system like vib2d three quarters of its time).
pub fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

/// Set while some call of [`with_workers_awake`] keeps workers busy.
static AWAKE: AtomicBool = AtomicBool::new(false);

/// What the spinners of one [`with_workers_awake`] call share.
#[derive(Default)]
struct Spinners {
    stop: AtomicBool,
    /// Spinners started and not yet returned.
    live: AtomicUsize,
}

/// Runs `f` (on a pool worker) while every other worker of the pool looks
/// for work in a loop instead of going to sleep when it finds none.
///
/// Why: a step is a few short parallel passes. A rayon worker with nothing
/// to do sleeps after some tens of microseconds, and waking it takes longer
/// than that on a virtual machine, so the short pass that adds the deferred
/// shares (about 0.1 ms on chute) ran on one thread whatever the pool's size.
/// The cost: the other workers spin while `f` runs its serial parts.
///
/// A spinner runs the jobs it finds on top of its own stack, so it must not
/// outlive the call: a job of a later call stolen by a stale spinner could
/// pick up that later call's spinner, which would then spin inside a job
/// its caller waits for. The call therefore returns only once every spinner
/// it started has returned (a spinner that starts later sees the stop flag
/// and returns at once). For the same reason only one call is active at a
/// time in the process; a call made while another is active (tests sharing
/// the global pool, nested calls) runs `f` plainly.
pub fn with_workers_awake<R>(f: impl FnOnce() -> R) -> R {
    let Some(me) = rayon::current_thread_index() else {
        return f();
    };
    if rayon::current_num_threads() < 2 || AWAKE.swap(true, Ordering::AcqRel) {
        return f();
    }
    let spinners = Arc::new(Spinners::default());
    let shared = Arc::clone(&spinners);
    rayon::spawn_broadcast(move |ctx| {
        if ctx.index() == me {
            return;
        }
        shared.live.fetch_add(1, Ordering::AcqRel);
        while !shared.stop.load(Ordering::Acquire) {
            if rayon::yield_now() == Some(rayon::Yield::Idle) {
                for _ in 0..16 {
                    std::hint::spin_loop();
                }
            }
        }
        shared.live.fetch_sub(1, Ordering::AcqRel);
    });
    /// Stops the spinners and waits for them when `f` returns or unwinds.
    struct Stop(Arc<Spinners>);
    impl Drop for Stop {
        fn drop(&mut self) {
            self.0.stop.store(true, Ordering::Release);
            while self.0.live.load(Ordering::Acquire) > 0 {
                std::hint::spin_loop();
            }
            AWAKE.store(false, Ordering::Release);
        }
    }
    let _stop = Stop(spinners);
    f()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn sum(n: u64) -> u64 {
        (0..n).into_par_iter().map(|k| k * k).sum()
    }

    /// Calls one after the other with parallel loops between them (as the
    /// scenario runner makes them), nested calls and concurrent calls all
    /// end, and their loops give the right sums. (The race that hung a
    /// chute run, a spinner outliving its call, is too narrow for this test
    /// to meet reliably; it is a check that the calls end, not a proof.)
    #[test]
    fn workers_awake_in_sequence_nested_and_concurrent_all_end() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let want = sum(20_000);
        pool.install(|| {
            for k in 0..5000 {
                assert_eq!(with_workers_awake(|| sum(20_000)), want);
                if k % 2 == 0 {
                    assert_eq!(sum(20_000), want);
                }
            }
        });
        let got: Vec<u64> = pool.install(|| {
            (0..64u64)
                .into_par_iter()
                .map(|_| with_workers_awake(|| with_workers_awake(|| sum(20_000))))
                .collect()
        });
        assert!(got.iter().all(|&s| s == want));
        // Outside any pool: runs plainly.
        assert_eq!(with_workers_awake(|| sum(1000)), sum(1000));
    }
}
