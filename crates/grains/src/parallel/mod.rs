//! Where the engines' parallel loops run, and on how many threads.

mod governor;

pub use governor::Governor;

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Runs `f` on a worker of rayon's pool. The engines' parallel loops then
/// start from a pool thread; called from any other thread, each loop would
/// hand its work over and wait, a context switch per loop per step (which
/// cost a small system like vib2d three quarters of its time).
pub fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

thread_local! {
    /// Set on a thread inside [`serial`].
    static SERIAL: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with the engines' parallel loops on this thread alone: each
/// loop is one piece ([`min_len`]), so no other worker is woken or waited
/// for. The loops' results do not depend on how they are cut.
pub fn serial<R>(f: impl FnOnce() -> R) -> R {
    /// Puts the flag back when `f` returns or unwinds.
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            SERIAL.set(self.0);
        }
    }
    let _restore = Restore(SERIAL.replace(true));
    f()
}

/// The least number of items a parallel loop of the engines gives one job:
/// `least`, or all of them inside [`serial`]. Every parallel loop of the
/// engines passes it to `with_min_len`.
pub fn min_len(least: usize) -> usize {
    if SERIAL.get() {
        usize::MAX
    } else {
        least
    }
}

/// Set while some call of [`with_workers_awake`] keeps workers busy.
static AWAKE: AtomicBool = AtomicBool::new(false);

/// How long a call waits for the other workers to start spinning before it
/// runs `f` anyway (a worker busy with other work starts too late and
/// returns at once). Waking a sleeping worker takes some tens of
/// microseconds on a virtual machine.
const START_WAIT: Duration = Duration::from_millis(1);

/// What the spinners of one [`with_workers_awake`] call share. Every access
/// is sequentially consistent: the call writes `began` or `stop` and then
/// reads `live`, while a spinner adds to `live` and then reads `began` and
/// `stop`; weaker orderings would let both read the old values.
#[derive(Default)]
struct Spinners {
    /// `f` has started: a spinner that starts now returns at once.
    began: AtomicBool,
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
/// A spinner runs the jobs it finds on top of its own stack, so it must
/// never run on top of a job of `f`: `f` could not end before that job,
/// nor the job before the spinner, nor the spinner before `f`. A worker
/// takes a waiting spinner while it waits inside a job, so a spinner may
/// spin only if it started before `f` did: the call waits for the spinners
/// to start (at most [`START_WAIT`]) before it runs `f`, and one that starts
/// later returns at once. Nor may a spinner outlive its call, where it
/// could take a job of a later call's `f` and, inside it, that call's
/// spinner: the call returns only once every spinner it started has
/// returned, and only one call is active at a time in the process (a call
/// made while another is active, as by tests sharing the global pool or a
/// nested call, runs `f` plainly).
pub fn with_workers_awake<R>(f: impl FnOnce() -> R) -> R {
    let Some(me) = rayon::current_thread_index() else {
        return f();
    };
    let others = rayon::current_num_threads() - 1;
    if others == 0 || SERIAL.get() || AWAKE.swap(true, Ordering::SeqCst) {
        return f();
    }
    /// Stops the spinners, waits for them and lets the next call start
    /// its own, when `f` returns or unwinds (or the broadcast fails). A
    /// spinner that starts after the stop returns at once.
    struct Stop(Arc<Spinners>);
    impl Drop for Stop {
        fn drop(&mut self) {
            self.0.stop.store(true, Ordering::SeqCst);
            // A spinner may be running a long job it took: help the pool
            // meanwhile instead of only spinning.
            run_pending_jobs_until(|| self.0.live.load(Ordering::SeqCst) == 0);
            AWAKE.store(false, Ordering::SeqCst);
        }
    }
    let stop = Stop(Arc::new(Spinners::default()));
    let shared = Arc::clone(&stop.0);
    rayon::spawn_broadcast(move |ctx| {
        if ctx.index() == me {
            return;
        }
        shared.live.fetch_add(1, Ordering::SeqCst);
        if !shared.began.load(Ordering::SeqCst) {
            run_pending_jobs_until(|| shared.stop.load(Ordering::SeqCst));
        }
        shared.live.fetch_sub(1, Ordering::SeqCst);
    });
    let start = Instant::now();
    while stop.0.live.load(Ordering::SeqCst) < others && start.elapsed() < START_WAIT {
        std::hint::spin_loop();
    }
    stop.0.began.store(true, Ordering::SeqCst);
    f()
}

/// Runs the pool's pending jobs on this worker, or spins briefly when there
/// are none, until `done`.
fn run_pending_jobs_until(done: impl Fn() -> bool) {
    while !done() {
        if rayon::yield_now() == Some(rayon::Yield::Idle) {
            for _ in 0..16 {
                std::hint::spin_loop();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;
    use std::sync::mpsc;

    fn sum(n: u64) -> u64 {
        (0..n).into_par_iter().map(|k| k * k).sum()
    }

    pub(super) fn pool_of(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// Runs `body` on a thread of its own and fails if it has not ended
    /// within a minute (a hang would otherwise stall the test run).
    /// Inside `serial` every item of a loop runs on the calling thread, and
    /// the flag is put back after the call, after a panic too.
    #[test]
    fn serial_keeps_the_loops_on_the_calling_thread() {
        pool_of(2).install(|| {
            let me = std::thread::current().id();
            let threads = || -> Vec<_> {
                (0..100_000)
                    .into_par_iter()
                    .with_min_len(min_len(1))
                    .map(|_| std::thread::current().id())
                    .collect()
            };
            assert!(serial(threads).iter().all(|&t| t == me));
            assert_eq!(serial(|| serial(|| min_len(1))), usize::MAX);
            assert_eq!(min_len(7), 7);
            let panicked = std::panic::catch_unwind(|| serial(|| panic!("in f")));
            assert!(panicked.is_err());
            assert_eq!(min_len(7), 7);
        });
    }

    fn ends_in_time(body: impl FnOnce() + Send + 'static) {
        let (done, ended) = mpsc::channel();
        let runner = std::thread::spawn(move || {
            body();
            let _ = done.send(());
        });
        match ended.recv_timeout(Duration::from_secs(60)) {
            Ok(()) => runner.join().unwrap(),
            // The body panicked: report its panic.
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                std::panic::resume_unwind(runner.join().unwrap_err())
            }
            Err(mpsc::RecvTimeoutError::Timeout) => panic!("with_workers_awake hung"),
        }
    }

    /// Calls one after the other with parallel loops between them (as the
    /// scenario runner makes them), nested calls, calls from parallel jobs
    /// and from several threads into one pool, a 1-thread pool and a call
    /// outside any pool all end, and their loops give the right sums. The
    /// races the design guards against (see [`with_workers_awake`]) are too
    /// narrow for a test to meet reliably: this checks that the calls end,
    /// it is not a proof.
    #[test]
    fn workers_awake_in_sequence_nested_and_concurrent_all_end() {
        ends_in_time(|| {
            let pool = Arc::new(pool_of(2));
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
            let callers: Vec<_> = (0..3)
                .map(|_| {
                    let pool = Arc::clone(&pool);
                    std::thread::spawn(move || {
                        pool.install(|| {
                            (0..500).all(|_| with_workers_awake(|| sum(20_000)) == want)
                        })
                    })
                })
                .collect();
            assert!(callers.into_iter().all(|c| c.join().unwrap()));
            assert_eq!(
                pool_of(1).install(|| with_workers_awake(|| sum(1000))),
                sum(1000)
            );
            // Outside any pool: runs plainly.
            assert_eq!(with_workers_awake(|| sum(1000)), sum(1000));
        });
    }

    /// A worker busy elsewhere when the call starts misses the start wait:
    /// the call runs `f` anyway, and the late spinner returns at once.
    #[test]
    fn workers_awake_with_a_busy_worker_ends() {
        ends_in_time(|| {
            let pool = pool_of(2);
            let want = sum(20_000);
            pool.install(|| {
                for _ in 0..20 {
                    let busy = AtomicBool::new(true);
                    let (_, got) = rayon::join(
                        // Keeps this worker from its spinner past START_WAIT.
                        || {
                            while busy.load(Ordering::SeqCst) {
                                std::hint::spin_loop();
                            }
                        },
                        || {
                            with_workers_awake(|| {
                                std::thread::sleep(2 * START_WAIT);
                                busy.store(false, Ordering::SeqCst);
                                sum(20_000)
                            })
                        },
                    );
                    assert_eq!(got, want);
                }
            });
        });
    }

    /// A panic in `f` reaches the caller through the guard that stops and
    /// waits for the spinners, and later calls still end with the right
    /// sums.
    #[test]
    fn workers_awake_after_a_panic() {
        ends_in_time(|| {
            let pool = pool_of(2);
            pool.install(|| {
                let caught = std::panic::catch_unwind(|| {
                    with_workers_awake(|| -> u64 { panic!("inside f") })
                });
                assert!(caught.is_err());
                assert_eq!(with_workers_awake(|| sum(20_000)), sum(20_000));
            });
        });
    }
}
