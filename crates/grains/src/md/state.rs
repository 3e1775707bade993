//! The complete dynamic state of an MD engine, as a checkpoint carries it
//! ([`super::Md::export_state`], [`super::Md::import_state`]; encoded by
//! [`super::codec`]).

use super::pair_forces::{Deferred, PairBlocks};
use super::wall_loads::WallLoad;
use super::wall_springs::{MeshEntry, WallSprings};
use super::{Md, MdStats};
use crate::boundary::ServoState;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::neighbors::ListState;
use crate::particles::Particles;
use crate::rigid::bodies::Body;
use glam::DVec3;

/// The complete dynamic state of an [`super::Md`]: with the same scenario
/// (settings, walls, domain) it continues bit for bit like the run it came
/// from. Walls need no state of their own, but for servo walls: any other
/// motion (a mesh's pose included), phase and removal are functions of
/// `time`.
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
    /// Mesh walls' rolling springs, keyed and ordered as `mesh_springs`;
    /// empty unless the law keeps rolling springs (epsd).
    pub mesh_rolling: Vec<((u32, u32, u32), D::V)>,
    /// Each wall's load (force, moment about the origin) at the last force
    /// evaluation, and that evaluation's time; empty unless a wall is a
    /// mesh (what `walls.csv` reports).
    pub wall_loads: (Vec<[DVec3; 2]>, f64),
    /// Each servo wall's state in wall order (offset, speed, pressure:
    /// [`crate::boundary::ServoState`]); empty without servo walls.
    pub servo: Vec<[f64; 3]>,
    pub rebuilds_since_sort: u32,
    /// Statistics of the last force evaluation (reported in thermo rows).
    pub contacts: u64,
    pub max_overlap: f64,
    pub max_overlap_fraction: f64,
    pub worst_pair: (u64, Option<u64>),
    /// A fixed-pressure box along its gradient axis (upper bound, slide
    /// origin t_0 and Δ_0); `None` at constant volume.
    pub pressure_box: Option<[f64; 3]>,
    /// The rigid bodies' states in body order (empty without clumps); the
    /// grains' ties to them follow from the ids, as the scenario made them.
    pub bodies: Vec<Body>,
}

/// Export and import of the state, beside the state: the engine packs itself.
impl<D: Dim> Md<D> {
    /// The complete dynamic state, for a checkpoint: with the same scenario,
    /// [`Md::import_state`] on a freshly built engine continues bit for bit.
    /// Fails when ghosts are present (a single process has none).
    pub fn export_state(&self) -> Result<MdState<D>> {
        let p = &self.particles;
        if p.n_owned() != p.len() {
            return Err(Error::input(
                "checkpoint: ghost particles present; checkpoints hold owned grains only",
            ));
        }
        Ok(MdState {
            time: self.time,
            step: self.step,
            particles: p.clone(),
            list: self.neighbors.export_state(),
            springs: self.springs.clone(),
            wall_springs: self.wall_springs.to_dense(p.len(), self.walls.len().max(1)),
            rolling: self.rolling.clone(),
            wall_rolling: if self.rolling_history() {
                self.wall_rolling.to_dense(p.len(), self.walls.len().max(1))
            } else {
                Vec::new()
            },
            mesh_springs: self.mesh_springs.entries().collect(),
            mesh_rolling: self.mesh_rolling.entries().collect(),
            wall_loads: (
                self.wall_loads
                    .0
                    .iter()
                    .map(|l| [l.force, l.moment])
                    .collect(),
                self.wall_loads.1,
            ),
            servo: self
                .walls
                .iter()
                .filter_map(|w| w.motion.servo_state())
                .map(|s| s.to_array())
                .collect(),
            rebuilds_since_sort: self.rebuilds_since_sort,
            contacts: self.stats.contacts as u64,
            max_overlap: self.stats.max_overlap,
            max_overlap_fraction: self.stats.max_overlap_fraction,
            worst_pair: self.stats.worst_pair,
            pressure_box: self.pressure_box(),
            bodies: self.bodies().map_or(Vec::new(), |b| b.bodies.clone()),
        })
    }

    /// Checks keyed mesh springs (`what`) of a saved state of `n` grains:
    /// each on a mesh wall's patch, of a grain that exists, in key order.
    fn check_mesh_keys(&self, what: &str, entries: &[MeshEntry<D::V>], n: usize) -> Result<()> {
        let bad = |m: String| Err(Error::input(format!("checkpoint state: {m}")));
        let mut last = None;
        for &((g, w, patch), _) in entries {
            let patches = self
                .walls
                .get(w as usize)
                .and_then(|wall| match &wall.shape {
                    crate::boundary::Shape::Mesh(m) => Some(m.patches()),
                    _ => None,
                });
            let Some(patches) = patches else {
                return bad(format!("a {what} on wall {w}, which is not a mesh"));
            };
            if g as usize >= n || patch as usize >= patches {
                return bad(format!(
                    "a {what} of grain {g} on patch {patch} of wall {w}, \
                     but there are {n} grains and {patches} patches"
                ));
            }
            if last.is_some_and(|l| l >= (g, w, patch)) {
                return bad(format!("{what}s out of order"));
            }
            last = Some((g, w, patch));
        }
        Ok(())
    }

    /// Replaces the dynamic state by a saved one. The engine must have been
    /// built from the same scenario: the grains (by id), the wall count and
    /// the integrator's history must match, every array length and index is
    /// checked, and nothing is changed on error.
    pub fn import_state(&mut self, s: MdState<D>) -> Result<()> {
        let bad = |m: String| Err(Error::input(format!("checkpoint state: {m}")));
        let n = s.particles.len();
        let p = &s.particles;
        if n != self.particles.len() {
            return bad(format!(
                "{n} grains, but the scenario builds {}",
                self.particles.len()
            ));
        }
        let lens = [
            p.vel.len(),
            p.force.len(),
            p.omega.len(),
            p.torque.len(),
            p.radius.len(),
            p.mass.len(),
            p.inv_mass.len(),
            p.inv_inertia.len(),
            p.inertia.len(),
            p.id.len(),
            p.kind.len(),
            p.frozen.len(),
        ];
        if p.n_owned() != n
            || lens.iter().any(|&l| l != n)
            || p.gear.iter().any(|g| g.len() != n)
            || p.gear_ang.iter().any(|g| g.len() != n)
        {
            return bad("particle arrays of unequal length".into());
        }
        let orders = match self.settings.integrator {
            Integrator::Gear5 => (4, 4),
            Integrator::Verlet => (self.particles.gear.len(), self.particles.gear_ang.len()),
        };
        if (p.gear.len(), p.gear_ang.len()) != orders {
            return bad(format!(
                "{} and {} Gear derivative arrays, but the {} integrator keeps {} and {}",
                p.gear.len(),
                p.gear_ang.len(),
                self.settings.integrator.name(),
                orders.0,
                orders.1
            ));
        }
        self.check_bodies_state(&s.bodies)?;
        let mut ids = p.id.clone();
        let mut mine = self.particles.id.clone();
        ids.sort_unstable();
        mine.sort_unstable();
        if ids != mine {
            return bad("its grain ids differ from the scenario's".into());
        }
        if s.springs.len() != s.list.pairs.len() {
            return bad(format!(
                "{} tangential springs for {} listed pairs",
                s.springs.len(),
                s.list.pairs.len()
            ));
        }
        let nw = self.walls.len().max(1);
        if s.wall_springs.len() != n * nw {
            return bad(format!(
                "{} wall springs, but {n} grains and {} walls need {}",
                s.wall_springs.len(),
                self.walls.len(),
                n * nw
            ));
        }
        let history = self.rolling_history();
        let want = |len: usize| if history { len } else { 0 };
        if s.rolling.len() != want(s.list.pairs.len()) || s.wall_rolling.len() != want(n * nw) {
            return bad(format!(
                "{} pair and {} wall rolling springs (or JKR contact marks), but contact.rolling = \
                 \"{}\" with contact.cohesion = \"{}\" keeps {} and {}",
                s.rolling.len(),
                s.wall_rolling.len(),
                self.rolling_model().name(),
                self.settings.law.cohesion().name(),
                want(s.list.pairs.len()),
                want(n * nw)
            ));
        }
        self.check_mesh_keys("mesh spring", &s.mesh_springs, n)?;
        if !history && !s.mesh_rolling.is_empty() {
            return bad(format!(
                "{} mesh rolling springs, but contact.rolling = \"{}\" keeps none",
                s.mesh_rolling.len(),
                self.rolling_model().name()
            ));
        }
        self.check_mesh_keys("mesh rolling spring", &s.mesh_rolling, n)?;
        if !s.wall_loads.0.is_empty() && s.wall_loads.0.len() != self.walls.len() {
            return bad(format!(
                "{} wall loads for {} walls",
                s.wall_loads.0.len(),
                self.walls.len()
            ));
        }
        if let Some(b) = s.pressure_box {
            self.check_pressure_box(b)?;
        }
        // A state without servo states under servo walls is a restart that
        // made a wall a servo: it starts at rest from its reference
        // position.
        let servos = self.walls.iter().filter(|w| w.motion.is_servo()).count();
        if !s.servo.is_empty() && s.servo.len() != servos {
            return bad(format!(
                "{} servo wall states for {servos} servo walls (a restart may make walls \
                 servos, not change servo walls into others)",
                s.servo.len()
            ));
        }
        let mut list = self.neighbors.clone();
        list.import_state(s.list, n)
            .map_err(|e| Error::input(format!("checkpoint state: {e}")))?;
        self.neighbors = list;
        self.particles = s.particles;
        self.time = s.time;
        self.step = s.step;
        self.springs = s.springs;
        self.wall_springs = WallSprings::from_dense(&s.wall_springs, nw);
        self.rolling = s.rolling;
        self.wall_rolling = WallSprings::from_dense(&s.wall_rolling, nw);
        self.mesh_springs = WallSprings::from_entries(s.mesh_springs);
        self.mesh_rolling = WallSprings::from_entries(s.mesh_rolling);
        self.wall_loads = (
            s.wall_loads
                .0
                .iter()
                .map(|&[force, moment]| WallLoad { force, moment })
                .collect(),
            s.wall_loads.1,
        );
        let servo_walls = self.walls.iter_mut().filter(|w| w.motion.is_servo());
        for (wall, &state) in servo_walls.zip(&s.servo) {
            wall.motion.set_servo_state(ServoState::from_array(state));
        }
        self.rebuilds_since_sort = s.rebuilds_since_sort;
        self.stats = MdStats {
            contacts: s.contacts as usize,
            max_overlap: s.max_overlap,
            max_overlap_fraction: s.max_overlap_fraction,
            worst_pair: s.worst_pair,
        };
        self.blocks = PairBlocks::build(&self.neighbors.pairs, self.particles.len());
        self.deferred = Deferred::default();
        if let Some(b) = s.pressure_box {
            self.set_pressure_box(b);
        }
        self.set_bodies_state(s.bodies);
        Ok(())
    }
}
