//! Ranks as threads of one process, for tests of the decompositions
//! without MPI: every collective is an all-gather through shared slots
//! between two barriers. A rank that panics fails the barrier for all, so a
//! failing check ends the test instead of leaving the others waiting.

use super::Comm;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::{Arc, Condvar, Mutex};

/// Arrivals in this round, round number, whether a rank panicked.
struct Gate {
    state: Mutex<(usize, u64, bool)>,
    cv: Condvar,
    size: usize,
}

impl Gate {
    fn wait(&self) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        assert!(!s.2, "another rank panicked");
        s.0 += 1;
        if s.0 == self.size {
            s.0 = 0;
            s.1 += 1;
            self.cv.notify_all();
            return;
        }
        let round = s.1;
        while s.1 == round && !s.2 {
            s = self.cv.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        assert!(!s.2, "another rank panicked");
    }

    fn fail(&self) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).2 = true;
        self.cv.notify_all();
    }
}

struct Shared {
    slots: Mutex<Vec<Vec<u8>>>,
    gate: Gate,
}

/// One rank of a group of threads.
pub struct ThreadComm {
    rank: usize,
    size: usize,
    shared: Arc<Shared>,
}

impl ThreadComm {
    /// Runs `f` on `size` ranks, each on its own thread; returns their
    /// results in rank order. A panic on any rank is re-raised here.
    pub fn run<T: Send>(size: usize, f: impl Fn(&ThreadComm) -> T + Sync) -> Vec<T> {
        let shared = Arc::new(Shared {
            slots: Mutex::new(vec![Vec::new(); size]),
            gate: Gate {
                state: Mutex::new((0, 0, false)),
                cv: Condvar::new(),
                size,
            },
        });
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..size)
                .map(|rank| {
                    let c = ThreadComm {
                        rank,
                        size,
                        shared: shared.clone(),
                    };
                    let f = &f;
                    s.spawn(move || {
                        catch_unwind(AssertUnwindSafe(|| f(&c)))
                            .inspect_err(|_| c.shared.gate.fail())
                    })
                })
                .collect();
            let results: Vec<_> = handles
                .into_iter()
                .map(|h| h.join().expect("rank thread"))
                .collect();
            results
                .into_iter()
                .map(|r| r.unwrap_or_else(|e| resume_unwind(e)))
                .collect()
        })
    }
}

impl Comm for ThreadComm {
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.size
    }
    fn all_gather_bytes(&self, bytes: &[u8]) -> Vec<Vec<u8>> {
        self.shared.slots.lock().expect("slots")[self.rank] = bytes.to_vec();
        self.shared.gate.wait();
        let all = self.shared.slots.lock().expect("slots").clone();
        // Nobody overwrites a slot before everyone has read it.
        self.shared.gate.wait();
        all
    }
}
