//! The MD engine and its step pipeline.
//!
//! One step, each phase a method you can find by name:
//! 1. [`Md::predict`]: the integrator's part before the forces; within a
//!    step the same pass also measures every grain's displacement since the
//!    last neighbour build (the test of step 2);
//! 2. `Md::rebuild_neighbors`, when the predictor found a grain moved more
//!    than half the skin: wrap periodic positions, sort spatially (every few rebuilds),
//!    rebuild the Verlet list and carry the tangential springs over by grain
//!    identity;
//! 3. [`Md::compute_forces`]: pair contacts, wall contacts, gravity;
//! 4. [`Md::correct`]: the integrator's part after the forces;
//! 5. [`Md::check_stability`]: NaN/inf and excessive overlap stop the run.
//!
//! Measurements and output are not part of the step: the caller runs them
//! between steps (see the scenario runner).

pub mod barostat;
mod carry;
mod clumps;
pub mod codec;
pub mod contact_list;
pub mod contract;
pub mod decomp;
pub mod edit;
mod field_forces;
mod insert;
mod mesh_lists;
mod pair_forces;
mod pair_hash;
pub mod phase_times;
mod remove;
pub mod state;
mod view;
pub mod wall_contact_list;

pub use state::MdState;
mod wall_loads;
mod wall_springs;

use crate::boundary::Wall;
use crate::contact::binary::BinaryContact;
use crate::contact::hertz_mindlin::MaterialLaw;
use crate::contact::rolling::RollingModel;
use crate::contact::{ContactLaw, Law};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::integrate::{gear5, Integrator, SkinCheck};
use crate::io::Frame;
use crate::neighbors::{spatial_sort_order, NeighborList};
use crate::parallel::Governor;
use crate::particles::Particles;
pub use crate::view::MeshLoad;
use field_forces::{finish_fields, FieldInput};
use mesh_lists::MeshLists;
use pair_forces::{pair_forces, Deferred, PairBlocks, PairInput};
use phase_times::{add_since, PhaseTimes};
use rayon::prelude::*;
use std::time::Instant;
use wall_loads::WallLoad;
use wall_springs::{MeshKey, WallSprings};

/// Numerical settings of an MD run.
#[derive(Clone, Debug)]
pub struct MdSettings<D: Dim> {
    pub dt: f64,
    pub integrator: Integrator,
    /// The contact law, one value for every contact of the run.
    pub law: Law,
    pub gravity: D::V,
    /// Verlet-list skin (m).
    pub skin: f64,
    /// Sort grains spatially every this many neighbour-list rebuilds (0: never).
    pub sort_every: u32,
    /// Largest overlap allowed, as a fraction of the smaller radius.
    pub max_overlap_fraction: f64,
    /// Check positions for NaN/inf every this many steps.
    pub nan_check_every: u64,
    /// Constant pressure on a sheared box's gradient axis (`None`: the
    /// box keeps its volume).
    pub barostat: Option<barostat::Barostat>,
}

impl<D: Dim> MdSettings<D> {
    /// Settings for a run under the spring–dashpot law `contact` (Gear-5).
    pub fn new(dt: f64, contact: ContactLaw, skin: f64) -> Self {
        Self {
            dt,
            integrator: Integrator::Gear5,
            law: Law::SpringDashpot(contact),
            gravity: D::zero(),
            skin,
            sort_every: 20,
            max_overlap_fraction: 0.5,
            nan_check_every: 10,
            barostat: None,
        }
    }

    /// Settings for a run under the material law `law` (velocity Verlet),
    /// with a unit Hertz stand-in as its time-step estimate.
    pub fn with_materials(
        dt: f64,
        law: crate::contact::hertz_mindlin::HertzMindlin,
        skin: f64,
    ) -> Self {
        let stand_in = ContactLaw {
            kn: 1.0,
            beta: 1.5,
            gamma_n: 0.0,
            gamma_t: 0.0,
            kt: 0.0,
            mu: f64::INFINITY,
            scaling: crate::contact::mass_scaling::MassScaling::Reduced,
            rotation: law.rotation,
        };
        let law = Law::Materials(MaterialLaw {
            hertz: law,
            estimate: stand_in.clone(),
        });
        Self {
            integrator: Integrator::Verlet,
            law,
            ..Self::new(dt, stand_in, skin)
        }
    }
}

/// Counters a run reports.
#[derive(Clone, Debug, Default)]
pub struct MdStats {
    /// Grain–grain and grain–wall contacts in the last force evaluation.
    pub contacts: usize,
    /// Largest overlap (m) in the last force evaluation.
    pub max_overlap: f64,
    /// Largest overlap relative to the smaller radius, and its grains' ids
    /// (the partner is `None` for a wall).
    pub(crate) max_overlap_fraction: f64,
    pub(crate) worst_pair: (u64, Option<u64>),
}

/// An MD simulation of grains in dimension `D`.
pub struct Md<D: Dim> {
    pub particles: Particles<D>,
    pub domain: Domain<D>,
    pub walls: Vec<Wall<D>>,
    pub settings: MdSettings<D>,
    pub time: f64,
    pub step: u64,
    pub stats: MdStats,
    /// Wall time per phase of the step since the engine was built.
    pub timing: PhaseTimes,
    neighbors: NeighborList<D>,
    /// Tangential spring of each listed pair, aligned with `neighbors.pairs`,
    /// oriented as the displacement of the pair's first grain.
    springs: Vec<D::V>,
    /// Tangential springs of the grain–wall contacts that are stretched.
    wall_springs: WallSprings<D>,
    /// Those of mesh walls, one per grain, wall and flat patch.
    mesh_springs: WallSprings<D, MeshKey>,
    /// Each grain's candidate triangles of each mesh wall.
    mesh_lists: MeshLists,
    /// Rolling springs of the listed pairs, aligned like `springs`, and of
    /// the grain–wall contacts; empty unless the rolling resistance keeps
    /// them (`contact.rolling = "epsd"`); mesh walls' keyed as their
    /// tangential springs, by (grain, wall, patch).
    rolling: Vec<D::V>,
    wall_rolling: WallSprings<D>,
    mesh_rolling: WallSprings<D, MeshKey>,
    /// What the grains put on each wall at the last force evaluation
    /// (empty unless a wall is a mesh or a servo), and its time.
    wall_loads: (Vec<WallLoad>, f64),
    /// The pair list cut into blocks for the parallel force loop.
    blocks: PairBlocks,
    deferred: Deferred<D>,
    rebuilds_since_sort: u32,
    /// Runs [`Md::advance`]'s steps on all threads or one, as is faster.
    pub governor: Governor,
    /// Rigid clumps and their ties to the grains (none without clumps).
    clumps: Option<Box<clumps::Clumps>>,
}

impl<D: Dim> Md<D> {
    /// Sets up a run: validates the settings, builds the neighbour list and
    /// evaluates the forces at t = 0 (without advancing any spring). The
    /// initial state is not judged here: call [`Md::check_stability`] or
    /// inspect [`Md::worst_overlap`] before stepping.
    pub fn new(
        particles: Particles<D>,
        domain: Domain<D>,
        walls: Vec<Wall<D>>,
        settings: MdSettings<D>,
    ) -> Result<Self> {
        settings.law.estimate().validate("contact")?;
        if !(settings.dt.is_finite() && settings.dt > 0.0) {
            return Err(Error::input(format!(
                "dt = {}: must be a positive number of seconds",
                settings.dt
            )));
        }
        if !(settings.skin.is_finite() && settings.skin > 0.0) {
            return Err(Error::input(format!(
                "neighbor skin = {}: must be positive",
                settings.skin
            )));
        }
        settings.law.check(particles.max_radius(), settings.skin)?;
        let mut md = Self {
            particles,
            domain,
            walls,
            neighbors: NeighborList::new(settings.skin),
            settings,
            time: 0.0,
            step: 0,
            stats: MdStats::default(),
            timing: PhaseTimes::default(),
            springs: Vec::new(),
            wall_springs: WallSprings::default(),
            mesh_springs: WallSprings::default(),
            mesh_lists: MeshLists::default(),
            rolling: Vec::new(),
            wall_rolling: WallSprings::default(),
            mesh_rolling: WallSprings::default(),
            wall_loads: (Vec::new(), 0.0),
            blocks: PairBlocks::default(),
            deferred: Deferred::default(),
            rebuilds_since_sort: 0,
            governor: Governor::default(),
            clumps: None,
        };
        md.rebuild_neighbors()?;
        md.compute_forces(false);
        if md.settings.integrator == Integrator::Gear5 {
            gear5::initialize(&mut md.particles, md.settings.dt);
        }
        Ok(md)
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<()> {
        self.slide_to_next_step();
        let moved = self.predict_checked();
        self.time = (self.step + 1) as f64 * self.settings.dt;
        self.step += 1;
        if moved {
            self.rebuild_neighbors()?;
        }
        self.compute_forces(true);
        self.correct();
        self.check_stability()?;
        if self.barostat_due() {
            self.apply_barostat()?;
        }
        Ok(())
    }

    /// Advances `n` steps (on a worker of rayon's pool, see
    /// [`crate::parallel::on_pool`]), as [`Md::advance`].
    pub fn run(&mut self, n: u64) -> Result<()> {
        crate::parallel::on_pool(|| self.advance(n))
    }

    /// Advances `n` steps, the same bits as `n` calls of [`Md::step`], with
    /// the corrector of each step and the predictor of the next in one pass
    /// over the grains (they stream every grain's state and history, about
    /// 1 KB with Gear-5): for stretches where nothing reads or moves the
    /// grains between steps. When a step finds the state unstable the error
    /// is the one [`Md::step`] gives; a non-finite grain found by the fused
    /// pass leaves the grains already predicted one step further.
    ///
    /// The steps run in slices on all of the pool's threads or on one,
    /// whichever the governor measures as faster (see
    /// [`crate::parallel::Governor`]): the same bits either way.
    pub fn advance(&mut self, n: u64) -> Result<()> {
        let end = self.step + n;
        // A fixed-pressure box stops at each of the barostat's readings.
        while let Some(k) = self.steps_to_barostat() {
            if self.step + k > end {
                break;
            }
            self.advance_governed(k)?;
            self.apply_barostat()?;
        }
        self.advance_governed(end - self.step)
    }

    fn advance_governed(&mut self, n: u64) -> Result<()> {
        let mut governor = std::mem::take(&mut self.governor);
        let done = governor.run(n, |k| {
            // Worth keeping the pool's other workers awake for (a few
            // microseconds to start them spinning); on one thread it is
            // the plain call.
            if k >= 8 {
                crate::parallel::with_workers_awake(|| self.advance_steps(k))
            } else {
                self.advance_steps(k)
            }
        });
        self.governor = governor;
        done
    }

    fn advance_steps(&mut self, n: u64) -> Result<()> {
        if n == 0 {
            return Ok(());
        }
        self.slide_to_next_step();
        let mut moved = self.predict_checked();
        for left in (0..n).rev() {
            self.time = (self.step + 1) as f64 * self.settings.dt;
            self.step += 1;
            if moved {
                self.rebuild_neighbors()?;
            }
            self.compute_forces(true);
            if left == 0 {
                break;
            }
            if let Err(e) = self.check_overlap() {
                self.correct();
                return Err(e);
            }
            self.slide_to_next_step();
            moved = self.correct_predict_checked()?;
        }
        self.correct();
        self.check_stability()
    }

    /// Moves a sheared box's sliding images to the end of the next step,
    /// before the displacement test of the grains moved to it.
    fn slide_to_next_step(&mut self) {
        if self.domain.shear.is_some() {
            let t = (self.step + 1) as f64 * self.settings.dt;
            self.neighbors.set_time(t);
        }
    }

    /// The integrator's part before the forces.
    pub fn predict(&mut self) {
        let start = Instant::now();
        let (dt, rot) = (self.settings.dt, self.settings.law.rotation());
        self.predict_bodies();
        self.swap_held();
        self.settings
            .integrator
            .predict(&mut self.particles, dt, rot, None);
        self.swap_held();
        add_since(&mut self.timing.integrate, start);
    }

    /// [`Md::predict`] with the neighbour list's displacement test in the
    /// same pass over the grains: whether the list must be rebuilt (the
    /// answer of [`NeighborList::needs_rebuild`] after the move).
    fn predict_checked(&mut self) -> bool {
        self.predict_owned_checked() || self.ghosts_beyond_skin()
    }

    /// [`Md::predict_checked`] without the ghosts' test: a decomposed run
    /// tests its ghosts ([`Md::ghosts_beyond_skin`]) after their owners
    /// sent their new positions.
    pub(crate) fn predict_owned_checked(&mut self) -> bool {
        let (dt, rot) = (self.settings.dt, self.settings.law.rotation());
        let integrator = self.settings.integrator;
        let pass = |p: &mut Particles<D>, skin: Option<SkinCheck<D::V>>| {
            integrator.predict(p, dt, rot, skin)
        };
        self.predict_bodies();
        self.owned_beyond_skin(pass)
    }

    /// [`Md::correct`], the finite-state test of [`Md::check_stability`]
    /// (when due at this step) and [`Md::predict_checked`] of the next step
    /// in one pass over the grains.
    fn correct_predict_checked(&mut self) -> Result<bool> {
        let moved = self.correct_predict_owned_checked()?;
        Ok(moved || self.ghosts_beyond_skin())
    }

    /// [`Md::correct`], the finite-state test (when due) and the next
    /// step's [`Md::predict`] in one pass, with the displacement test of
    /// the owned grains only (as [`Md::predict_owned_checked`]).
    pub(crate) fn correct_predict_owned_checked(&mut self) -> Result<bool> {
        let (dt, rot) = (self.settings.dt, self.settings.law.rotation());
        let finite = self.finite_check_due();
        let integrator = self.settings.integrator;
        let mut non_finite = None;
        let pass = |p: &mut Particles<D>, skin: Option<SkinCheck<D::V>>| {
            let r = integrator.correct_predict(p, (dt, rot), skin, finite);
            non_finite = r.non_finite;
            r.far
        };
        self.kick_bodies();
        self.predict_bodies();
        let moved = self.owned_beyond_skin(pass);
        self.finite_or_error(non_finite).map(|()| moved)
    }

    fn finite_or_error(&self, non_finite: Option<usize>) -> Result<()> {
        match non_finite {
            Some(i) => Err(self.non_finite_error(i)),
            None => Ok(()),
        }
    }

    /// Runs `pass` (an integrator pass that moves the owned grains) with
    /// the displacement test of the neighbour list: whether one of them
    /// calls for a rebuild (always, when the list must be built anyway).
    /// Timed as integration.
    fn owned_beyond_skin(
        &mut self,
        pass: impl FnOnce(&mut Particles<D>, Option<SkinCheck<D::V>>) -> bool,
    ) -> bool {
        let start = Instant::now();
        // Sub-spheres were moved by their bodies: the pass leaves them.
        self.swap_held();
        let p = &mut self.particles;
        let n = p.n_owned();
        let moved = match self.neighbors.skin_reference(p.len()) {
            None => {
                pass(p, None);
                true
            }
            Some((reference, limit2)) => {
                let skin = SkinCheck {
                    reference: &reference[..n],
                    limit2,
                };
                pass(p, Some(skin))
            }
        };
        self.swap_held();
        add_since(&mut self.timing.integrate, start);
        moved
    }

    /// The displacement test of the ghosts: not integrated here, but their
    /// owner may have moved them (with [`Md::owned_beyond_skin`], the answer
    /// of [`NeighborList::needs_rebuild`]).
    pub(crate) fn ghosts_beyond_skin(&self) -> bool {
        let p = &self.particles;
        let n = p.n_owned();
        let Some((reference, limit2)) = self.neighbors.skin_reference(p.len()) else {
            return true;
        };
        p.pos[n..]
            .iter()
            .zip(&reference[n..])
            .any(|(&a, &b)| D::norm2(a - b) > limit2)
    }

    /// The integrator's part after the forces.
    pub fn correct(&mut self) {
        let start = Instant::now();
        let (dt, rot) = (self.settings.dt, self.settings.law.rotation());
        self.correct_bodies();
        self.swap_held();
        self.settings
            .integrator
            .correct(&mut self.particles, dt, rot);
        self.swap_held();
        add_since(&mut self.timing.integrate, start);
    }

    /// Number of neighbour-list builds so far.
    pub fn neighbor_builds(&self) -> u64 {
        self.neighbors.builds()
    }

    fn rebuild_neighbors(&mut self) -> Result<()> {
        let start = Instant::now();
        let built = self.rebuild_neighbors_untimed();
        add_since(&mut self.timing.neighbors, start);
        built
    }

    fn rebuild_neighbors_untimed(&mut self) -> Result<()> {
        let n = self.particles.n_owned();
        let domain = &self.domain;
        if domain.shear.is_some() {
            // Lees–Edwards: through the gradient boundary a grain's place
            // along x and its velocity change too.
            let (_, offset) = domain.shear_offset(self.time);
            let p = &mut self.particles;
            p.pos[..n]
                .par_iter_mut()
                .zip(p.vel[..n].par_iter_mut())
                .with_min_len(crate::parallel::min_len(1))
                .for_each(|(x, v)| domain.wrap_sheared(x, v, offset));
        } else {
            self.particles.pos[..n]
                .par_iter_mut()
                .with_min_len(crate::parallel::min_len(1))
                .for_each(|x| *x = domain.wrap(*x));
            self.wrap_bodies();
        }
        let saved = self.save_springs();
        let saved_rolling = self.save_rolling();
        let sort_every = self.settings.sort_every;
        if sort_every > 0 && self.rebuilds_since_sort.is_multiple_of(sort_every) {
            let cell = 2.0 * self.particles.max_radius() + self.settings.skin;
            let order = spatial_sort_order(&self.particles.pos[..n], &self.domain, cell);
            self.particles.permute(&order);
            self.wall_springs.permute(&order);
            self.mesh_springs.permute(&order);
            self.wall_rolling.permute(&order);
            self.mesh_rolling.permute(&order);
        }
        self.rebuilds_since_sort = self.rebuilds_since_sort.wrapping_add(1);
        self.refresh_clumps();
        let p = &self.particles;
        self.neighbors
            .build_at(&p.pos, &p.radius, &p.frozen, &self.domain, self.time)?;
        self.drop_pairs_within_bodies();
        let p = &self.particles;
        self.blocks = PairBlocks::build(&self.neighbors.pairs, p.len());
        self.restore_springs(saved);
        self.restore_rolling(saved_rolling);
        Ok(())
    }

    /// The rolling resistance of the contact law.
    fn rolling_model(&self) -> RollingModel {
        self.settings.law.rolling()
    }

    /// Whether contacts keep something in their rolling slots: epsd's
    /// rolling spring, or JKR's mark of a formed contact.
    pub(crate) fn rolling_history(&self) -> bool {
        self.settings.law.keeps_second_history()
    }

    /// Recomputes every force and torque (the pair loop starts the sums). `update_history` is
    /// false when no time has passed (the start of a run): springs are then
    /// read but not stretched.
    pub fn compute_forces(&mut self, update_history: bool) {
        self.stats.contacts = 0;
        self.stats.max_overlap = 0.0;
        self.stats.max_overlap_fraction = 0.0;
        let s = &self.settings;
        let pairs = PairInput {
            law: &s.law,
            dt: s.dt,
            update: update_history,
            neighbors: &self.neighbors,
            blocks: &self.blocks,
            mass: self.clumps.as_ref().map(|c| &c.contact_mass[..]),
        };
        // Each wall's pose (a sine, a rotation) once per evaluation.
        let walls: Vec<_> = self.walls.iter().map(|w| w.at(self.time)).collect();
        let lists_start = Instant::now();
        let build = self.neighbors.builds();
        self.mesh_lists
            .refresh(&walls, &self.particles, build, s.skin);
        add_since(&mut self.timing.fields, lists_start);
        let fields = FieldInput {
            law: &s.law,
            walls: &walls,
            gravity: s.gravity,
            weightless: self.clumps.as_ref().map(|c| &c.held[..]),
            dt: s.dt,
            update: update_history,
            mesh_springs: &self.mesh_springs,
            mesh_lists: self.mesh_lists.walls(),
            wall_rolling: &self.wall_rolling,
            mesh_rolling: &self.mesh_rolling,
        };
        // Walls and gravity are added block by block after the contacts.
        let (parts, fields_start) = pair_forces(
            &pairs,
            &mut self.particles,
            (&mut self.springs, &mut self.rolling),
            &mut self.deferred,
            (&mut self.stats, &mut self.timing.contacts),
            (&fields, &self.wall_springs),
        );
        let springs = (
            (&mut self.wall_springs, &mut self.mesh_springs),
            (&mut self.wall_rolling, &mut self.mesh_rolling),
        );
        finish_fields(parts, springs, &mut self.wall_loads.0, &mut self.stats);
        self.wall_loads.1 = self.time;
        self.gather_body_forces();
        if update_history {
            self.drive_servos();
        }
        add_since(&mut self.timing.fields, fields_start);
    }

    /// Moves each servo wall by the load the grains put on it at this
    /// force evaluation (summed in grain order: the same on any threads);
    /// only when time has passed, so a rebuilt or resumed engine's first
    /// evaluation does not move it.
    fn drive_servos(&mut self) {
        let loads = &self.wall_loads.0;
        for (w, wall) in self.walls.iter_mut().enumerate() {
            if wall.motion.is_servo() {
                let load = loads.get(w).map_or(glam::DVec3::ZERO, |l| l.force);
                wall.motion.servo_step(load, self.time, self.settings.dt);
            }
        }
    }

    /// Stops the run when a grain's state is not finite or two grains
    /// overlap by more than the allowed fraction of the smaller radius.
    pub fn check_stability(&self) -> Result<()> {
        self.check_overlap()?;
        if self.finite_check_due() {
            let p = &self.particles;
            // The first such grain, whatever the threads.
            if let Some(i) = (0..p.n_owned())
                .into_par_iter()
                .with_min_len(crate::parallel::min_len(4096))
                .find_first(|&i| !(D::is_finite(p.pos[i]) && D::is_finite(p.vel[i])))
            {
                return Err(self.non_finite_error(i));
            }
        }
        Ok(())
    }

    /// The overlap part of [`Md::check_stability`] (the last force
    /// evaluation's largest overlap).
    pub(crate) fn check_overlap(&self) -> Result<()> {
        let s = &self.stats;
        if s.max_overlap_fraction > self.settings.max_overlap_fraction {
            let (a, b) = s.worst_pair;
            let partner = b.map_or("a wall".to_string(), |b| format!("grain {b}"));
            return Err(Error::Unstable(format!(
                "at step {} (t = {:.6e} s) grain {a} overlaps {partner} by {:.1}% of the smaller radius \
                 (limit {:.0}%); the contacts are too soft or dt = {:.3e} s is too large: {}",
                self.step,
                self.time,
                100.0 * s.max_overlap_fraction,
                100.0 * self.settings.max_overlap_fraction,
                self.settings.dt,
                self.dt_advice()
            )));
        }
        Ok(())
    }

    /// Whether this step's stability check also tests for non-finite states.
    fn finite_check_due(&self) -> bool {
        self.step
            .is_multiple_of(self.settings.nan_check_every.max(1))
    }

    fn non_finite_error(&self, i: usize) -> Error {
        Error::Unstable(format!(
            "at step {} (t = {:.6e} s) grain {} has a non-finite position or velocity; {}",
            self.step,
            self.time,
            self.particles.id[i],
            self.dt_advice()
        ))
    }

    /// What the grains put on each mesh wall at the last force evaluation
    /// (walls that are not meshes are left out).
    pub fn mesh_loads(&self) -> Vec<MeshLoad> {
        let (loads, t) = &self.wall_loads;
        let placed = self.walls.iter().map(|w| w.at(*t));
        let points = placed
            .enumerate()
            .filter_map(|(w, p)| Some((w, p.load_point()?)));
        points
            .map(|(w, point)| {
                let l = loads.get(w).copied().unwrap_or_default();
                MeshLoad {
                    wall: w,
                    force: l.force,
                    torque: l.torque_about(point),
                    point,
                }
            })
            .collect()
    }

    /// The largest overlap of the last force evaluation as a fraction of the
    /// smaller radius, with the ids of the grains involved (`None`: a wall).
    pub fn worst_overlap(&self) -> (f64, u64, Option<u64>) {
        let s = &self.stats;
        (s.max_overlap_fraction, s.worst_pair.0, s.worst_pair.1)
    }

    /// A neutral snapshot of the grains for the writers (2D boxes get a unit
    /// z extent, as LAMMPS writes them).
    pub fn frame(&self) -> Frame {
        let mut f = self.view().frame();
        f.body = self.frame_bodies(f.len());
        f.orientation = self.frame_orientations(f.len());
        f
    }

    /// Contact time of two typical grains, for advice on dt.
    pub fn contact_time(&self) -> f64 {
        let p = &self.particles;
        let m = (0..p.n_owned())
            .filter(|&i| !p.frozen[i])
            .map(|i| p.mass[i])
            .fold(f64::INFINITY, f64::min);
        let m = if m.is_finite() { m } else { 1.0 };
        let vmax = (0..p.n_owned())
            .map(|i| D::norm(p.vel[i]))
            .fold(0.0, f64::max);
        let v = if vmax > 0.0 { vmax } else { 1.0 };
        BinaryContact::new(self.settings.law.estimate(), m, m).contact_time(v)
    }

    fn dt_advice(&self) -> String {
        let tc = self.contact_time();
        format!(
            "the binary contact time is {tc:.3e} s; try dt <= {:.3e} s (t_c/50) or stiffer contacts",
            tc / 50.0
        )
    }
}
