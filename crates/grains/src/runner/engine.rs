//! The hooks' views of an engine: the MD and the gas hooks see one through
//! [`MdView`] and [`GasView`], the whole state, at hand in a serial engine
//! ([`Md`], [`Dsmc`], which meet the [`Engine`] contract in their own
//! modules), gathered on rank 0 in a decomposed one
//! ([`super::distributed_md`], [`super::distributed`]).

use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::dsmc::engine::Dsmc;
use crate::engine::Engine;
use crate::error::Result;
use crate::md::Md;
use crate::scenario::flow::FlowRun;
use serde_json::{Map, Value};

/// An MD engine as the MD hooks see it. Its methods that gather are
/// collective in a decomposed engine: every rank calls them at the same
/// steps.
pub(crate) trait MdView: Engine {
    /// The dimension.
    type D: Dim;
    /// The whole state now (gathered or copied from a device at most once
    /// a step); `None` on the ranks other than 0. Hooks read it and never
    /// change it: only the engine's steps and [`MdView::flow_events`] do,
    /// so an engine that keeps its state elsewhere never copies it back.
    fn whole(&mut self) -> Result<Option<&Md<Self::D>>>;
    /// The whole state now when `want` on some rank (rank 0 alone may
    /// know); else rank 0's whole engine with only its step and time
    /// current.
    fn whole_if(&mut self, want: bool) -> Result<Option<&Md<Self::D>>>;
    /// Whether the steps at which rank 0's measurements and flow events
    /// act are known to rank 0 alone, so that those hooks act at every
    /// step.
    fn lockstep(&self) -> bool {
        false
    }
    /// This rank's piece of the frame at an output step, when frames come
    /// in pieces from several ranks.
    fn write_piece(&self) -> Result<()> {
        Ok(())
    }
    /// The flow events after the step now (`flow` on rank 0).
    fn flow_events(&mut self, flow: Option<&mut FlowRun<Self::D>>) -> Result<()>;
    /// What the engine adds to summary.json after the common scalars
    /// (every rank calls this).
    fn summarize(&mut self, summary: &mut Map<String, Value>, wall_seconds: f64);
}

impl<D: Dim> MdView for Md<D> {
    type D = D;
    fn whole(&mut self) -> Result<Option<&Md<D>>> {
        Ok(Some(self))
    }
    fn whole_if(&mut self, _: bool) -> Result<Option<&Md<D>>> {
        Ok(Some(self))
    }
    fn flow_events(&mut self, flow: Option<&mut FlowRun<D>>) -> Result<()> {
        if let Some(f) = flow {
            f.after_step(self);
            f.outflow(self)?;
        }
        Ok(())
    }
    fn summarize(&mut self, summary: &mut Map<String, Value>, wall_seconds: f64) {
        crate::md::contract::scalars(self, summary, wall_seconds);
    }
}

/// A DSMC engine as the gas hooks see it (collective as [`MdView`]).
pub(crate) trait GasView: Engine {
    /// The dimension.
    type D: GasDim;
    /// The whole gas now (gathered at most once a step); `None` on the
    /// ranks other than 0.
    fn whole(&mut self) -> Option<&mut Dsmc<Self::D>>;
    /// This rank's piece of the frame at an output step.
    fn write_piece(&self) -> Result<()> {
        Ok(())
    }
    /// The collision tallies were read at an output step: the ranks of a
    /// decomposed engine start theirs again.
    fn tallies_read(&mut self) {}
    /// What the engine adds to summary.json (every rank calls this).
    fn summarize(&mut self, _summary: &mut Map<String, Value>) {}
}

impl<D: GasDim> GasView for Dsmc<D> {
    type D = D;
    fn whole(&mut self) -> Option<&mut Dsmc<D>> {
        Some(self)
    }
}
