//! Running a loop with the widest vector instructions the processor has.
//!
//! The binary is built for plain x86-64 (SSE2), so it runs anywhere; a hot
//! loop written as a [`Kernel`] is compiled again for AVX2 and AVX-512 by
//! the `multiversion` crate, and [`run_widest`] picks the widest one at run
//! time. Rust never fuses a multiplication and an addition on its own, so
//! every variant does the same operations in the same order and gives the
//! same bits.

use multiversion::multiversion;

/// A loop to compile once per instruction set.
pub trait Kernel {
    /// The loop; mark the implementation `#[inline(always)]` so that each
    /// variant of [`run_widest`] compiles its own copy.
    fn run(&mut self);
}

/// Runs `k` with AVX-512 or AVX2 where the processor has them. A generic
/// function, so `multiversion` tests the processor's features at each call
/// (a cached flag in the standard library), as a hand-written `if` would.
#[multiversion(targets("x86_64+avx512f", "x86_64+avx2"))]
pub fn run_widest<K: Kernel>(k: &mut K) {
    k.run();
}
