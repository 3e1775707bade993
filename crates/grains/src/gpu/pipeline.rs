//! What a scenario run needs of the GPU pipeline, wherever it runs: on the
//! device ([`super::cuda::Cuda`], feature `cuda`) or as loops on the CPU
//! ([`Mirror`]).

use super::mirror::Mirror;
use crate::dim::D3;
use crate::domain::Domain;
use crate::error::Result;
use crate::io::Frame;
use crate::md::{Md, MdState};

/// The GPU pipeline as the run loop drives it: steps, and the state copied
/// out at the steps a hook reads it.
pub trait Pipeline: Send + Sized {
    /// `run.device`'s value for this pipeline, for messages and summaries.
    const NAME: &'static str;
    /// The pipeline for `md` as it stands (its list built, its forces
    /// evaluated: as built from a scenario or restored from a checkpoint);
    /// `fma`: the kernels with fused multiply-add, where there are such.
    fn start(md: &Md<D3>, fma: bool) -> Result<Self>;
    /// Steps taken since step 0.
    fn step(&self) -> u64;
    /// Simulated time (s).
    fn time(&self) -> f64;
    /// Takes `n` steps, the same bits as the CPU engine's.
    fn advance(&mut self, n: u64) -> Result<()>;
    /// The state now as the CPU engine keeps it (copied from the device).
    fn state(&self) -> Result<MdState<D3>>;
    /// The grains now as a frame (copied from the device).
    fn frame(&self, domain: &Domain<D3>) -> Result<Frame>;
    /// Neighbour-list builds so far.
    fn builds(&self) -> u64;
    /// The device's memory in use and in all (bytes), where there is one.
    fn memory(&self) -> Option<(usize, usize)> {
        None
    }
}

impl Pipeline for Mirror {
    const NAME: &'static str = "mirror";
    fn start(md: &Md<D3>, _fma: bool) -> Result<Self> {
        Mirror::from_md(md)
    }
    fn step(&self) -> u64 {
        self.step
    }
    fn time(&self) -> f64 {
        self.time
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        Mirror::advance(self, n)
    }
    fn state(&self) -> Result<MdState<D3>> {
        Ok(self.to_state())
    }
    fn frame(&self, domain: &Domain<D3>) -> Result<Frame> {
        Ok(Mirror::frame(self, domain))
    }
    fn builds(&self) -> u64 {
        self.builds
    }
}

#[cfg(feature = "cuda")]
impl Pipeline for super::cuda::Cuda {
    const NAME: &'static str = "gpu";
    fn start(md: &Md<D3>, fma: bool) -> Result<Self> {
        let options = super::cuda::Options {
            fma,
            ..Default::default()
        };
        Self::with(Mirror::from_md(md)?, options)
    }
    fn step(&self) -> u64 {
        self.counters().step
    }
    fn time(&self) -> f64 {
        self.counters().time
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        Self::advance(self, n)
    }
    fn state(&self) -> Result<MdState<D3>> {
        Ok(self.host()?.to_state())
    }
    fn frame(&self, domain: &Domain<D3>) -> Result<Frame> {
        Ok(self.host()?.frame(domain))
    }
    fn builds(&self) -> u64 {
        self.counters().builds
    }
    fn memory(&self) -> Option<(usize, usize)> {
        Self::memory(self).ok()
    }
}
