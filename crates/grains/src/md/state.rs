//! The complete dynamic state of an MD engine, as a checkpoint carries it
//! ([`super::Md::export_state`], [`super::Md::import_state`]; encoded by
//! `checkpoint::state`).

use crate::dim::Dim;
use crate::neighbors::ListState;
use crate::particles::Particles;
use glam::DVec3;

/// The complete dynamic state of an [`super::Md`]: with the same scenario
/// (settings, walls, domain) it continues bit for bit like the run it came
/// from. Walls need no state of their own: their motion (a mesh's pose
/// included), phase and removal are functions of `time`.
#[derive(Clone, Debug)]
pub struct MdState<D: Dim> {
    pub time: f64,
    pub step: u64,
    /// Owned particles in store order, forces and Gear history included.
    pub particles: Particles<D>,
    pub list: ListState<D>,
    /// Tangential springs aligned with `list.pairs`.
    pub springs: Vec<D::V>,
    /// Grain–wall springs, `walls.max(1)` per grain in store order.
    pub wall_springs: Vec<D::V>,
    /// Rolling springs aligned with `list.pairs`, and the grain–wall ones
    /// laid out as `wall_springs`; both empty unless the law keeps them.
    pub rolling: Vec<D::V>,
    pub wall_rolling: Vec<D::V>,
    /// Mesh walls' tangential springs, one per (grain in store order,
    /// wall, flat patch) that is stretched, in key order.
    pub mesh_springs: Vec<((u32, u32, u32), D::V)>,
    /// Each wall's load (force, moment about the origin) at the last force
    /// evaluation, and that evaluation's time; empty unless a wall is a
    /// mesh (what `walls.csv` reports).
    pub wall_loads: (Vec<[DVec3; 2]>, f64),
    pub rebuilds_since_sort: u32,
    /// Statistics of the last force evaluation (reported in thermo rows).
    pub contacts: u64,
    pub max_overlap: f64,
    pub max_overlap_fraction: f64,
    pub worst_pair: (u64, Option<u64>),
}
