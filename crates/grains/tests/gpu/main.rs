//! The GPU engine without a GPU: its CPU mirror against the CPU engine, the
//! kernels against NVRTC, and (feature `cuda`, skipped without a device)
//! the CUDA engine against the mirror.

#[cfg(feature = "cuda")]
mod device;
mod mirror;
mod ptx;
mod scenario;
