//! The GPU pipeline (the device, or the mirror's CPU loops) behind the
//! [`Engine`] contract: the host keeps the engine built from the scenario
//! and copies the pipeline's state into it only when it is read.

use super::pipeline::Pipeline;
use crate::dim::D3;
use crate::engine::Engine;
use crate::error::Result;
use crate::io::Frame;
use crate::md::Md;

/// The GPU pipeline behind the engine contract.
pub struct DeviceMd<P> {
    /// Built from the scenario: settings, walls, domain; its grains are the
    /// pipeline's as they stood at step `fresh`.
    pub(crate) md: Md<D3>,
    pub(crate) pipe: P,
    pub(crate) fresh: Option<u64>,
    /// `run.gpu_fma`, for a pipeline started again from a checkpoint.
    fma: bool,
}

impl<P: Pipeline> DeviceMd<P> {
    /// The pipeline started from `md`'s state; `fma`: `run.gpu_fma`.
    pub fn new(md: Md<D3>, fma: bool) -> Result<Self> {
        Ok(Self {
            pipe: P::start(&md, fma)?,
            fma,
            fresh: Some(md.step),
            md,
        })
    }

    /// The host engine with the pipeline's state now (copied at most once
    /// a step).
    pub(crate) fn copied(&mut self) -> Result<&Md<D3>> {
        let step = self.pipe.step();
        if self.fresh != Some(step) {
            self.md.import_state(self.pipe.state()?)?;
            self.fresh = Some(step);
        }
        Ok(&self.md)
    }
}

impl<P: Pipeline> Engine for DeviceMd<P> {
    fn dim(&self) -> usize {
        3
    }
    fn step_count(&self) -> u64 {
        self.pipe.step()
    }
    fn sim_time(&self) -> f64 {
        self.pipe.time()
    }
    fn time_step(&self) -> f64 {
        self.md.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        self.pipe.advance(n)
    }
    fn frame(&self) -> Result<Frame> {
        if self.fresh == Some(self.pipe.step()) {
            return Ok(self.md.frame());
        }
        self.pipe.frame(&self.md.domain)
    }
    fn export(&self) -> Result<Vec<u8>> {
        Ok(crate::md::contract::encode_state(
            &self.md,
            &self.pipe.state()?,
        ))
    }
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()> {
        Engine::import(&mut self.md, bytes, origin)?;
        self.pipe = P::start(&self.md, self.fma)?;
        self.fresh = Some(self.md.step);
        Ok(())
    }
}
