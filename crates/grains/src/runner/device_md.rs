//! An MD run whose steps run on the GPU pipeline (`run.device = "gpu"`, or
//! `"mirror"`: the same pipeline as loops on the CPU, the same bits): the
//! host keeps the engine built from the scenario and copies the pipeline's
//! state into it only at the steps a hook reads it ([`DeviceMd`], the
//! pipeline behind the engine contract, here seen by the MD hooks).

use super::engine::MdView;
use super::md_run::Start;
use super::options::{prepare_fresh, Progress, RunOptions};
use super::phases::run_phases;
use crate::dim::D3;
#[cfg(not(feature = "cuda"))]
use crate::error::Error;
use crate::error::Result;
use crate::gpu::engine::DeviceMd;
use crate::gpu::mirror::Mirror;
use crate::gpu::pipeline::Pipeline;
use crate::md::Md;
use crate::scenario::flow::FlowRun;
use crate::scenario::schema::Device;
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};

impl<P: Pipeline> MdView for DeviceMd<P> {
    type D = D3;
    fn whole(&mut self) -> Result<Option<&Md<D3>>> {
        self.copied().map(Some)
    }
    fn whole_if(&mut self, want: bool) -> Result<Option<&Md<D3>>> {
        if want {
            return self.whole();
        }
        (self.md.step, self.md.time) = (self.pipe.step(), self.pipe.time());
        Ok(Some(&self.md))
    }
    /// Nothing: scenarios whose flow events change the grains (a hopper's
    /// recycling, `run.events`) are refused before the run
    /// ([`crate::scenario::device::check_device`]).
    fn flow_events(&mut self, _: Option<&mut FlowRun<D3>>) -> Result<()> {
        Ok(())
    }
    fn summarize(&mut self, summary: &mut Map<String, Value>, _: f64) {
        summary.insert("neighbor_builds".into(), json!(self.pipe.builds()));
        let mut device = Map::new();
        device.insert("engine".into(), json!(P::NAME));
        if let Some((used, total)) = self.pipe.memory() {
            device.insert("memory_bytes".into(), json!(used));
            device.insert("memory_total_bytes".into(), json!(total));
        }
        summary.insert("device".into(), Value::Object(device));
    }
}

/// Runs a 3D MD scenario from step 0 on the pipeline `run.device` names.
pub(super) fn run_fresh(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare_fresh(opts)?;
    let start = super::md_run::begin::<D3>(loaded, opts)?;
    run(loaded, opts, start, progress)
}

/// Runs `start` (step 0 or a restored checkpoint) with its engine moved
/// onto the pipeline `run.device` names, through the same run loop and
/// hooks as a CPU run.
pub(super) fn run(
    loaded: &Loaded,
    opts: &RunOptions,
    start: Start<'_, D3>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    fn on<P: Pipeline>(
        loaded: &Loaded,
        opts: &RunOptions,
        start: Start<'_, D3>,
        progress: &mut dyn Progress,
    ) -> Result<Value> {
        let fma = loaded.scenario.run.gpu_fma;
        let start = start.with_engine(|md| DeviceMd::<P>::new(md, fma))?;
        run_phases(loaded, opts, start, progress)
    }
    match loaded.scenario.run.device {
        Device::Mirror => on::<Mirror>(loaded, opts, start, progress),
        #[cfg(feature = "cuda")]
        Device::Gpu => on::<crate::gpu::cuda::Cuda>(loaded, opts, start, progress),
        #[cfg(not(feature = "cuda"))]
        Device::Gpu => Err(Error::input(crate::gpu::NO_FEATURE)),
        Device::Cpu => run_phases(loaded, opts, start, progress),
    }
}
