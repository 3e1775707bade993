//! MD over the ranks of a [`Comm`]: a grid of boxes cut by grain count
//! ([`subdomains`]), ghost
//! shells refreshed every step, migration at neighbour rebuilds.
//!
//! Each rank runs an [`Md`] on its own grains followed by ghost copies of
//! its neighbours' grains within reach (see [`halo`]). A pair of an
//! owned grain and a ghost is evaluated on both ranks that hold it, and
//! each keeps only its own grain's force ("newton off" across ranks), so no
//! force is sent back. Pairs of two ghosts are dropped from the list. The
//! tangential spring of a pair is keyed by the ids of its grains, so both
//! ranks evolve the same spring, and a grain that changes rank carries its
//! pair springs (keyed by partner id) and wall springs with it, its Gear
//! history inside its record.
//!
//! One step on every rank:
//! 1. predict (owned grains), testing in the same pass whether one moved
//!    more than skin/2 since the last build;
//! 2. refresh the ghosts' position, velocity and spin from their owners;
//! 3. if any rank's grain (owned, or a ghost once refreshed) moved more
//!    than skin/2 (one all-reduce): wrap, migrate the grains
//!    that left the box; when the owned counts are out of balance (max/mean
//!    − 1 above `[parallel] rebalance`), cut the boxes again by count
//!    ([`balance`]) and migrate again; sort, send new ghost shells,
//!    rebuild the list;
//! 4. forces: pairs (owned and ghosts), walls and gravity (owned only, walls
//!    evaluated at the same time on every rank);
//! 5. correct (owned grains);
//! 6. stability statistics reduced over the ranks; all ranks stop together.
//!
//! On one rank this is [`Md::step`] itself. On several, the result agrees
//! with the serial run to rounding: forces on a grain are summed in another
//! order (the list order differs), never a different physics.

pub mod balance;
mod edit;
mod gather;
pub mod halo;
mod migrate;
pub mod subdomains;

pub use gather::index_by_id;

use super::{Md, MdStats};
use crate::comm::{Comm, Reader, Writer};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::neighbors::{spatial_sort_order, NeighborList};
use crate::settings::parallel::ParallelSpec;
use balance::imbalance;
use halo::Halo;
use std::collections::{HashMap, HashSet};
use std::time::Instant;
use subdomains::Subdomains;

/// Pair springs keyed by (smaller id, larger id), oriented as the smaller id's.
type PairSprings<D> = HashMap<(u64, u64), <D as Dim>::V, super::pair_hash::PairHash>;
/// One pair spring in a migration message.
type PairSpring<D> = ((u64, u64), <D as Dim>::V);

/// How evenly the grains were spread over the ranks (imbalance: max/mean
/// − 1 of the owned counts, measured at the start and after each global
/// neighbour rebuild), and how often the bounds moved.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Balance {
    /// Imbalance above which the bounds move (0: never).
    pub threshold: f64,
    pub initial: f64,
    pub max: f64,
    /// The latest measurement (after the move, when the bounds moved).
    pub last: f64,
    pub rebalances: u64,
}

impl Balance {
    /// The summary keys: `imbalance_initial`, `imbalance_max`,
    /// `imbalance_final`, `rebalances`.
    pub fn write(&self, out: &mut serde_json::Map<String, serde_json::Value>) {
        out.insert("imbalance_initial".into(), self.initial.into());
        out.insert("imbalance_max".into(), self.max.into());
        out.insert("imbalance_final".into(), self.last.into());
        out.insert("rebalances".into(), self.rebalances.into());
    }
}

/// One rank's part of a decomposed MD run.
pub struct DecomposedMd<'c, D: Dim> {
    /// This rank's engine: owned grains first, ghosts after.
    pub md: Md<D>,
    comm: &'c dyn Comm,
    sub: Subdomains,
    /// The whole box (the engine holds this rank's list box).
    global: Domain<D>,
    halo: Halo,
    /// Grains that changed rank, over the whole run (all ranks).
    pub migrations: u64,
    /// The load balance: threshold, imbalances seen, moves of the bounds.
    pub balance: Balance,
    /// Seconds this rank spent in the per-step messages and collectives
    /// (ghost refresh, rebuild vote, statistics), waiting for others
    /// included: what the decomposition costs beyond the work itself.
    pub comm_seconds: f64,
    /// The springs by grain id (pairs, walls) of grains inserted or removed
    /// since the last step ([`Self::edit`]): the ghosts are gone and the
    /// list is stale, so the next step rebuilds from these.
    pending: Option<(PairSprings<D>, WallSpringsById<D>)>,
}

/// Wall springs as (grain id, wall, spring).
type WallSpringsById<D> = Vec<(u64, u32, <D as Dim>::V)>;

impl<'c, D: Dim> DecomposedMd<'c, D> {
    /// Splits a whole engine (the same on every rank, as built from the
    /// scenario at t = 0) into this rank's part, with the default
    /// `[parallel]` settings.
    pub fn new(full: Md<D>, comm: &'c dyn Comm) -> Result<Self> {
        Self::with_spec(full, comm, &ParallelSpec::default())
    }

    /// As [`Self::new`], split as `spec` says.
    pub fn with_spec(full: Md<D>, comm: &'c dyn Comm, spec: &ParallelSpec) -> Result<Self> {
        Self::with_inserts(full, comm, spec, 0.0)
    }

    /// As [`Self::with_spec`], for a run into which grains up to radius
    /// `inserted` will be inserted ([`Self::edit`]): the ghost shells reach
    /// far enough for them from the start.
    pub fn with_inserts(
        full: Md<D>,
        comm: &'c dyn Comm,
        spec: &ParallelSpec,
        inserted: f64,
    ) -> Result<Self> {
        if full.has_bodies() {
            return Err(Error::input(
                "[[shapes]]: rigid clumps do not run under mpirun: bodies would have to migrate \
                 whole across ranks (their sub-spheres and state together), which is not \
                 implemented; run on one process (--threads N)",
            ));
        }
        let mesh = full.walls.iter().find(|w| w.shape.kind() == "mesh");
        if let (Some(w), true) = (mesh, comm.size() > 1) {
            // Their springs, keyed by patch, do not migrate between ranks.
            return Err(Error::input(format!(
                "wall '{}' is a mesh: mesh walls do not run over several ranks yet; \
                 run on one process (--threads N)",
                w.name
            )));
        }
        let servo = full.walls.iter().find(|w| w.motion.is_servo());
        if let (Some(w), true) = (servo, comm.size() > 1) {
            // Its load would need a sum over the ranks at every step.
            return Err(Error::input(format!(
                "wall '{}' has motion type \"servo\": servo walls do not run over several \
                 ranks (mpirun) yet; run on one process (--threads N)",
                w.name
            )));
        }
        if full.domain.shear.is_some() {
            // Ghost shells do not slide with the Lees–Edwards images.
            return Err(Error::input(
                "domain.shear: a sheared box does not run under mpirun (over ranks) yet; \
                 run on one process (--threads N)",
            ));
        }
        if full.rolling_history() && comm.size() > 1 {
            // Rolling springs and JKR contact marks do not migrate between ranks.
            return Err(Error::input(
                "contact.rolling = \"epsd\" and contact.cohesion = \"jkr\" do not run over \
                 several ranks yet; run on one process (--threads N), or use contact.rolling = \
                 \"constant\" / contact.cohesion = \"dmt\"",
            ));
        }
        let global = full.domain.clone();
        let reach = 2.0 * full.particles.max_radius().max(inserted) + full.settings.skin;
        let n = full.particles.n_owned();
        let pos = &full.particles.pos[..n];
        let sub = Subdomains::by_count(&global, pos, comm.size(), reach, &spec.grid)?;
        let mut dec = Self {
            md: full,
            comm,
            sub,
            global,
            halo: Halo::default(),
            migrations: 0,
            balance: Balance {
                threshold: spec.rebalance,
                ..Balance::default()
            },
            comm_seconds: 0.0,
            pending: None,
        };
        if comm.size() > 1 {
            dec.split()?;
        }
        dec.balance.initial = dec.tally(0);
        Ok(dec)
    }

    /// Keeps this rank's grains of the whole engine, with their springs,
    /// then builds the ghosts and the list and evaluates the forces at t = 0
    /// again (the springs are read, not stretched, as at any start).
    fn split(&mut self) -> Result<()> {
        let saved = self.md.save_springs();
        let walls = self.wall_springs_by_id();
        let r = self.comm.rank();
        let p = &mut self.md.particles;
        for i in 0..p.n_owned() {
            p.pos[i] = self.global.wrap(p.pos[i]);
        }
        let keep: Vec<u32> = (0..p.n_owned() as u32)
            .filter(|&i| self.sub.owner(&D::to_xyz(p.pos[i as usize])) == r)
            .collect();
        p.retain_owned(&keep);
        let mine: HashSet<u64> = p.id.iter().copied().collect();
        let saved: PairSprings<D> = saved
            .into_iter()
            .filter(|((x, y), _)| mine.contains(x) || mine.contains(y))
            .collect();
        let walls: Vec<_> = walls
            .into_iter()
            .filter(|(id, _, _)| mine.contains(id))
            .collect();
        self.md.domain = self.sub.local_domain(&self.global, r);
        self.finish_rebuild(saved, walls, false)?;
        self.md.compute_forces(false);
        Ok(())
    }

    /// Advances one time step on every rank.
    pub fn step(&mut self) -> Result<()> {
        if self.comm.size() == 1 {
            return self.md.step();
        }
        let moved = self.md.predict_owned_checked();
        self.forces_after_predict(moved, None)?;
        self.md.correct();
        self.check_stability()
    }

    /// Advances `n` steps with the same bits as `n` calls of [`Self::step`],
    /// but one step's corrector and the next step's predictor are one pass
    /// over the owned grains ([`Md::advance`]'s fusion): for stretches where
    /// nothing reads the grains between steps (the benchmark).
    pub fn advance(&mut self, n: u64) -> Result<()> {
        if self.comm.size() == 1 {
            return self.md.advance(n);
        }
        if n == 0 {
            return Ok(());
        }
        let moved = self.md.predict_owned_checked();
        let mut agreed = None;
        for left in (0..n).rev() {
            self.forces_after_predict(moved, agreed)?;
            if left == 0 {
                break;
            }
            let local = self.md.check_overlap();
            let local = local.and_then(|()| self.md.correct_predict_owned_checked());
            // The next step's rebuild vote rides in this step's gather.
            let far = matches!(local, Ok(true)) || self.sent_beyond_skin();
            agreed = Some(self.reduce_stability(local.map(|_| ()), far)?);
        }
        self.md.correct();
        self.check_stability()
    }

    /// Steps 2–4 of a step: the clock, the ghosts, the rebuild vote (and
    /// rebuild), the forces. `agreed`: the vote when already reduced over
    /// the ranks (in the previous step's stability gather); else it is
    /// taken here: `moved` (the predictor's displacement test of the owned
    /// grains) or a refreshed ghost beyond skin/2 on some rank — together
    /// the list's `needs_rebuild`.
    fn forces_after_predict(&mut self, moved: bool, agreed: Option<bool>) -> Result<()> {
        self.md.time = (self.md.step + 1) as f64 * self.md.settings.dt;
        self.md.step += 1;
        let comm = self.comm;
        // After an edit (on every rank alike) the ghosts are gone: rebuild.
        let edited = self.pending.is_some();
        let t = Instant::now();
        if !edited {
            self.halo.refresh(&mut self.md.particles, comm);
        }
        self.comm_seconds += t.elapsed().as_secs_f64();
        let rebuild = match agreed {
            _ if edited => true,
            Some(vote) => vote,
            None => {
                let mut vote = [(moved || self.md.ghosts_beyond_skin()) as u64];
                let t = Instant::now();
                comm.sum_u64(&mut vote);
                self.comm_seconds += t.elapsed().as_secs_f64();
                vote[0] > 0
            }
        };
        if rebuild {
            self.rebuild()?;
        }
        self.md.compute_forces(true);
        Ok(())
    }

    /// Wall springs as (grain id, wall, spring).
    fn wall_springs_by_id(&self) -> Vec<(u64, u32, D::V)> {
        let id = &self.md.particles.id;
        self.md
            .wall_springs
            .entries()
            .map(|((g, w), s)| (id[g as usize], w, s))
            .collect()
    }

    /// Wraps, migrates, moves the bounds when the counts are out of
    /// balance (and migrates again), and rebuilds ghosts and list (step 3).
    fn rebuild(&mut self) -> Result<()> {
        let (mut saved, mut walls) = match self.pending.take() {
            Some(kept) => kept,
            None => (self.md.save_springs(), self.wall_springs_by_id()),
        };
        let p = &mut self.md.particles;
        p.clear_ghosts();
        for i in 0..p.n_owned() {
            p.pos[i] = self.global.wrap(p.pos[i]);
        }
        let arrived = self.migrate(&mut saved, &mut walls);
        let imbalance = self.tally(arrived);
        if self.balance.threshold > 0.0 && imbalance > self.balance.threshold {
            let p = &self.md.particles;
            let n = p.n_owned();
            self.sub
                .cut_by_count(self.comm, || p.pos[..n].iter().map(|&x| D::to_xyz(x)));
            self.md.domain = self.sub.local_domain(&self.global, self.comm.rank());
            let arrived = self.migrate(&mut saved, &mut walls);
            self.balance.rebalances += 1;
            self.tally(arrived);
        }
        self.finish_rebuild(saved, walls, true)
    }

    /// One all-reduce after a migration: the grains that changed rank
    /// (`arrived` here) added to [`Self::migrations`], and the owned grains
    /// per rank now, whose imbalance (max/mean − 1) is recorded in the
    /// report and returned.
    fn tally(&mut self, arrived: u64) -> f64 {
        let size = self.comm.size();
        let mut counts = vec![0u64; size + 1];
        counts[self.comm.rank()] = self.md.particles.n_owned() as u64;
        counts[size] = arrived;
        self.comm.sum_u64(&mut counts);
        self.migrations += counts[size];
        let x = imbalance(&counts[..size]);
        self.balance.last = x;
        self.balance.max = self.balance.max.max(x);
        x
    }

    /// With this rank's owned grains in place: sort (every few rebuilds),
    /// send the ghost shells, build the list without ghost–ghost pairs, and
    /// put the springs back by id.
    fn finish_rebuild(
        &mut self,
        saved: PairSprings<D>,
        walls: Vec<(u64, u32, D::V)>,
        count_rebuild: bool,
    ) -> Result<()> {
        let md = &mut self.md;
        let n = md.particles.n_owned();
        let sort_every = md.settings.sort_every;
        if sort_every > 0 && md.rebuilds_since_sort.is_multiple_of(sort_every) {
            let cell = 2.0 * md.particles.max_radius() + md.settings.skin;
            let order = spatial_sort_order(&md.particles.pos[..n], &md.domain, cell);
            md.particles.permute(&order);
        }
        if count_rebuild {
            md.rebuilds_since_sort = md.rebuilds_since_sort.wrapping_add(1);
        }
        let comm = self.comm;
        self.halo = Halo::build(&self.sub, comm.rank(), &mut md.particles, |out| {
            comm.exchange(out)
        });
        let p = &md.particles;
        let built = md.neighbors.build(&p.pos, &p.radius, &p.frozen, &md.domain);
        // Every rank stops when one cannot build (a NaN grain, say).
        let mut failed = [built.is_err() as u64];
        comm.sum_u64(&mut failed);
        if failed[0] > 0 {
            built?;
            return Err(Error::Unstable(
                "another rank could not build its neighbour list".into(),
            ));
        }
        drop_ghost_pairs(&mut md.neighbors, n);
        md.blocks = super::PairBlocks::build(&md.neighbors.pairs, p.len());
        md.restore_springs(saved);
        // Wall springs by index again (owned grains only have them).
        let wanted: HashMap<u64, Vec<(u32, D::V)>> =
            walls.into_iter().fold(HashMap::new(), |mut m, (id, w, s)| {
                m.entry(id).or_default().push((w, s));
                m
            });
        let mut entries = Vec::new();
        if !wanted.is_empty() {
            for (i, id) in md.particles.id[..n].iter().enumerate() {
                if let Some(list) = wanted.get(id) {
                    entries.extend(list.iter().map(|&(w, s)| ((i as u32, w), s)));
                }
            }
        }
        md.wall_springs = super::wall_springs::WallSprings::from_entries(entries);
        Ok(())
    }

    /// Reduces the step's contact statistics over the ranks and stops every
    /// rank when one of them finds the state unstable.
    fn check_stability(&mut self) -> Result<()> {
        let local = self.md.check_stability();
        self.reduce_stability(local, false).map(|_| ())
    }

    /// Whether a grain this rank sends as a ghost moved beyond skin/2 (the
    /// ghosts' displacement test of the receivers, see
    /// [`Halo::sent_beyond`]), with the positions as they will be sent.
    fn sent_beyond_skin(&self) -> bool {
        let p = &self.md.particles;
        match self.md.neighbors.skin_reference(p.len()) {
            Some((reference, limit2)) => self.halo.sent_beyond::<D>(&p.pos, reference, limit2),
            None => true,
        }
    }

    /// Sums the step's contact statistics over the ranks and turns any
    /// rank's `local` failure into every rank's error; `vote` (this rank's
    /// call for a rebuild at the next step) rides along: whether any rank
    /// called.
    fn reduce_stability(&mut self, local: Result<()>, vote: bool) -> Result<bool> {
        let s = &self.md.stats;
        let mut w = Writer::default();
        w.f64(s.max_overlap_fraction);
        w.u64(s.worst_pair.0);
        w.u64(s.worst_pair.1.map_or(u64::MAX, |b| b + 1));
        w.u64(s.contacts as u64);
        w.f64(s.max_overlap);
        w.u64(local.is_err() as u64);
        w.u64(vote as u64);
        // Fixed size: one collective per step; the messages travel only
        // when some rank failed.
        let t = Instant::now();
        let all = self.comm.all_gather_same(&w.buf);
        self.comm_seconds += t.elapsed().as_secs_f64();
        let mut total = MdStats::default();
        let mut failed = false;
        let mut rebuild = false;
        for blob in &all {
            let mut rd = Reader::new(blob);
            let frac = rd.f64();
            let (a, b) = (rd.u64(), rd.u64());
            total.contacts += rd.u64() as usize;
            total.max_overlap = total.max_overlap.max(rd.f64());
            if frac > total.max_overlap_fraction {
                total.max_overlap_fraction = frac;
                total.worst_pair = (a, b.checked_sub(1));
            }
            failed |= rd.u64() != 0;
            rebuild |= rd.u64() != 0;
        }
        self.md.stats = total;
        let failure = failed.then(|| {
            let mine = match &local {
                Ok(()) => String::new(),
                Err(Error::Unstable(m)) => m.clone(),
                Err(e) => e.to_string(),
            };
            let all = self.comm.all_gather_bytes(mine.as_bytes());
            let first = all.into_iter().find(|m| !m.is_empty()).unwrap_or_default();
            String::from_utf8_lossy(&first).into_owned()
        });
        match failure {
            // Every rank returns the first failing rank's message.
            Some(m) => Err(Error::Unstable(m)),
            None => Ok(rebuild),
        }
    }

    /// The owned grains' total kinetic energy ½Σmv², summed over ranks.
    pub fn kinetic_energy(&self) -> f64 {
        let mut e = [self.md.particles.kinetic_energy()];
        self.comm.sum_f64(&mut e);
        e[0]
    }

    /// Total momentum of the mobile grains, summed over ranks.
    pub fn momentum(&self) -> D::V {
        let m = D::to_xyz(self.md.particles.momentum());
        let mut v = m;
        self.comm.sum_f64(&mut v);
        D::from_xyz(v)
    }

    /// Grains owned by this rank.
    pub fn n_owned(&self) -> usize {
        self.md.particles.n_owned()
    }

    /// Ghost copies held by this rank.
    pub fn n_ghosts(&self) -> usize {
        self.halo.ghosts()
    }

    /// Neighbour-list builds so far (the same on every rank).
    pub fn neighbor_builds(&self) -> u64 {
        self.md.neighbor_builds()
    }

    /// The boxes of the ranks.
    pub fn subdomains(&self) -> &Subdomains {
        &self.sub
    }

    /// The ids of this rank's owned grains.
    pub fn owned_ids(&self) -> &[u64] {
        &self.md.particles.id[..self.n_owned()]
    }
}

/// Keeps only pairs with at least one owned grain (index < `owned`).
fn drop_ghost_pairs<D: Dim>(list: &mut NeighborList<D>, owned: usize) {
    let owned = owned as u32;
    let mut k = 0;
    for j in 0..list.pairs.len() {
        if list.pairs[j][0] < owned || list.pairs[j][1] < owned {
            list.pairs[k] = list.pairs[j];
            list.image[k] = list.image[j];
            k += 1;
        }
    }
    list.pairs.truncate(k);
    list.image.truncate(k);
}

/// A vector's `D::D` components.
pub(crate) fn put_vec<D: Dim>(w: &mut Writer, v: D::V) {
    D::to_xyz(v)[..D::D].iter().for_each(|&x| w.f64(x));
}

pub(crate) fn get_vec<D: Dim>(r: &mut Reader) -> D::V {
    let mut x = [0.0; 3];
    x.iter_mut().take(D::D).for_each(|c| *c = r.f64());
    D::from_xyz(x)
}

fn put_ang<D: Dim>(w: &mut Writer, a: D::A) {
    D::ang_to_xyz(a).iter().for_each(|&x| w.f64(x));
}

fn get_ang<D: Dim>(r: &mut Reader) -> D::A {
    D::ang_from_xyz([r.f64(), r.f64(), r.f64()])
}
