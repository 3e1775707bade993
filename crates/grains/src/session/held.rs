//! What a session holds: the per-grain columns a script reads, the
//! contacts, and the [`Held`] engine (MD or DSMC) behind them.

use crate::engine::Engine;
use crate::error::Result;
use crate::io::contact_records::Snapshot;
use crate::io::BodyRow;
use crate::scenario::Loaded;
use serde_json::{Map, Value};

/// Grain–grain contacts as flat arrays (vectors as `dim` numbers each).
#[derive(Clone, Debug, Default)]
pub struct Contacts {
    pub ids: Vec<[u64; 2]>,
    pub overlap: Vec<f64>,
    pub normal: Vec<f64>,
    pub force: Vec<f64>,
}

/// A per-grain array of floats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Column {
    Positions,
    Velocities,
    /// One number per grain in 2D (the spin about z), three in 3D.
    AngularVelocities,
    Diameters,
    Masses,
}

impl Column {
    /// Numbers per grain in dimension `dim`.
    pub fn width(self, dim: usize) -> usize {
        match self {
            Column::Positions | Column::Velocities => dim,
            Column::AngularVelocities if dim == 2 => 1,
            Column::AngularVelocities => 3,
            Column::Diameters | Column::Masses => 1,
        }
    }
}

/// What a session holds: an engine, MD or DSMC, in 2D or 3D (driven
/// through the run loop's [`Engine`] contract), and what a script reads of
/// it. Arrays are flat (`dim` numbers per grain for vectors) and in
/// ascending id order.
pub(super) trait Held: Send + Sync {
    fn engine(&self) -> &dyn Engine;
    fn engine_mut(&mut self) -> &mut dyn Engine;
    fn len(&self) -> usize;
    fn thermo_columns(&self) -> &'static [&'static str];
    fn thermo_row(&self) -> Vec<f64>;
    /// After a thermo row (the DSMC validity window).
    fn after_output(&mut self) {}
    fn ids(&self) -> Vec<u64>;
    /// Writes `col` of every grain into `out` (its length checked by the
    /// caller: [`Column::width`] numbers per grain).
    fn fill(&self, col: Column, out: &mut [f64]);
    fn frozen(&self) -> Vec<bool>;
    fn set_state(&mut self, pos: Option<&[f64]>, vel: Option<&[f64]>) -> Result<()>;
    fn kinetic_energy(&self) -> f64;
    fn rotational_energy(&self) -> f64;
    fn granular_temperature(&self) -> f64;
    fn contacts(&self) -> Result<Contacts>;
    /// The summary.json scalars of the state now.
    fn summary(&self, loaded: &Loaded, stepped: u64, wall_seconds: f64) -> Map<String, Value>;
    /// The grains and their contacts now, for the coarse-grained fields
    /// (MD only).
    fn snapshot(&self) -> Option<Snapshot> {
        None
    }
    /// The measurement section of a checkpoint (DSMC's validity window and
    /// tallies), if the engine keeps one.
    fn measurements(&self) -> Option<Vec<u8>> {
        None
    }
    /// The rigid bodies now, as bodies.csv's rows (none without clumps).
    fn body_rows(&self) -> Vec<BodyRow> {
        Vec::new()
    }
}
