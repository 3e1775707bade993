//! Where the engines' parallel loops run.

/// Runs `f` on a worker of rayon's pool. The engines' parallel loops then
/// start from a pool thread; called from any other thread, each loop would
/// hand its work over and wait, a context switch per loop per step (which
/// cost a small system like vib2d three quarters of its time).
pub fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}
