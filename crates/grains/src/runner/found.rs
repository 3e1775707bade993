//! What a checkpoint read back ([`crate::checkpoint::run::find`]) restores:
//! the engine and the measurements of a resumed MD run.

use crate::checkpoint::run::Found;
use crate::dim::Dim;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::measure::measurements::Measurements;
use crate::scenario::flow::FlowRun;
use crate::scenario::{build_md, Resolved};

/// What a resumed MD run starts from, every rank alike: the engine
/// restored from the checkpoint, the scenario's resolved settings, the step
/// plan, the measurement accumulators when the checkpoint lies inside
/// the measurement, and the flow run (a restart's begun afresh).
pub(crate) struct Restored<D: Dim> {
    pub md: Md<D>,
    pub resolved: crate::scenario::Resolved,
    pub plan: (u64, u64),
    pub measurements: Option<Measurements>,
    pub flow: FlowRun<D>,
}

impl Found {
    /// A fresh engine of the checkpoint's scenario with the checkpoint's MD
    /// state in it.
    pub fn restore_md<D: Dim>(&self) -> Result<Md<D>> {
        self.restore_built::<D>().map(|(md, ..)| md)
    }

    /// [`Found::restore_md`] with the scenario's resolved run parameters
    /// from the same build, and the flow run, whose changes to the engine
    /// (inserted and removed grains; tilted gravity, removed wall unless
    /// restarting) are in `md` before its state is restored and its
    /// fingerprint checked. A restart's flow run begins afresh, its inlets
    /// and outlets carried over.
    pub(crate) fn restore_built<D: Dim>(&self) -> Result<(Md<D>, Resolved, FlowRun<D>)> {
        // Refused by name before the scenario is built as MD (a DSMC
        // scenario has no contact law to build).
        if crate::dsmc::contract::is_dsmc(&self.engine) {
            return Err(Error::input(format!(
                "checkpoint {}: holds a DSMC engine state; it cannot be restored as MD",
                self.path.display()
            )));
        }
        let (mut md, resolved) = build_md::<D>(&self.loaded)?;
        let origin = self.path.display().to_string();
        let flow = match &self.restart {
            None => {
                let flow = FlowRun::restored(&self.loaded, &mut md, self.flow.as_deref(), &origin)?;
                md.import(&self.engine, &origin)?;
                flow
            }
            Some(_) => {
                let old = self.restarted_from.as_ref().unwrap_or(&self.loaded);
                let carried = FlowRun::carried_grains(old, &mut md, self.flow.as_deref(), &origin)?;
                crate::md::contract::restore_changed(&mut md, &self.engine)
                    .map_err(|e| Error::input(format!("{origin}: {e}")))?;
                let mut flow = FlowRun::begin(&self.loaded, &md)?;
                flow.carry(carried.as_deref(), &origin)?;
                flow
            }
        };
        if md.step != self.step {
            return Err(Error::input(format!(
                "checkpoint {}: header step {} but engine step {}",
                self.path.display(),
                self.step,
                md.step
            )));
        }
        Ok((md, resolved, flow))
    }

    /// Everything a resumed MD run needs, checked; `steps`: `--steps`. A
    /// restart begins a new run at the checkpoint's step: `steps` measured
    /// steps, or the changed scenario's relaxation and measurement, with
    /// fresh measurements.
    pub(crate) fn restore<D: Dim>(&self, steps: Option<u64>) -> Result<Restored<D>> {
        let loaded = &self.loaded;
        let (md, resolved, flow) = self.restore_built::<D>()?;
        if self.restart.is_some() {
            let at = md.step;
            let plan = match steps {
                Some(n) => (at, n),
                None => (
                    at.saturating_add(resolved.relax_steps),
                    resolved.measure_steps,
                ),
            };
            return Ok(Restored {
                md,
                resolved,
                plan,
                measurements: None,
                flow,
            });
        }
        let path = self.path.display();
        let (relax, measure) = self.resume_plan(md.step, steps)?;
        let measurements = match &self.measurements {
            Some(bytes) if md.step > relax => Some(
                Measurements::load(loaded, &md.view(), bytes)
                    .map_err(|e| Error::input(format!("checkpoint {path}: {e}")))?,
            ),
            Some(_) => {
                return Err(Error::input(format!(
                    "checkpoint {path}: measurement state at step {}, before the measurement begins",
                    md.step
                )))
            }
            None if md.step > relax => {
                return Err(Error::input(format!(
                    "checkpoint {path}: step {} lies in the measurement but carries no measurement state",
                    md.step
                )))
            }
            None => None,
        };
        Ok(Restored {
            md,
            resolved,
            plan: (relax, measure),
            measurements,
            flow,
        })
    }
}
