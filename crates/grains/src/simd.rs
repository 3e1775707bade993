//! Running a loop with the widest vector instructions the processor has.
//!
//! The binary is built for plain x86-64 (SSE2), so it runs anywhere; a hot
//! loop written as a [`Kernel`] is compiled again for AVX2 and AVX-512 and
//! [`run_widest`] picks the widest one at run time. Rust never fuses a
//! multiplication and an addition on its own, so every variant does the same
//! operations in the same order and gives the same bits.

/// A loop to compile once per instruction set.
pub trait Kernel {
    /// The loop; mark the implementation `#[inline(always)]` so that each
    /// variant below compiles its own copy.
    fn run(&mut self);
}

/// Runs `k` with AVX-512 or AVX2 where the processor has them.
#[inline]
pub fn run_widest<K: Kernel>(k: &mut K) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the processor has AVX-512F (checked just above).
        unsafe { run_avx512(k) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { run_avx2(k) };
        return;
    }
    k.run();
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn run_avx512<K: Kernel>(k: &mut K) {
    k.run();
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2<K: Kernel>(k: &mut K) {
    k.run();
}
