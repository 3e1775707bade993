//! The pipeline on an NVIDIA GPU (feature `cuda`): the mirror's passes as
//! launches of the kernels in `kernels/*.cu`, from the PTX checked in under
//! `kernels/ptx/` (`tools/make_ptx.py`), through `cudarc`, which loads
//! libcuda at run time.
//!
//! The host keeps the [`Mirror`] it started from (parameters, and what an
//! export needs); the grains live on the device and come back only when
//! asked ([`Cuda::host`]). One stream, in order. The rebuild is decided on
//! the device (the step words, [`super::grain_kernels::words`]): a stretch
//! of steps is launched without a look at the device, every rebuild kernel
//! gated on the words, and the host reads the twelve words once, when the
//! stretch ends ([`Mirror::finish`]).

mod transfer;

use super::grain_kernels::{list_capacity, words, Grid, Plane};
use super::kernel_params::*;
use super::mirror::Mirror;
use crate::error::Result;
use cudarc::driver::{CudaFunction, CudaGraph, CudaSlice, CudaStream, DevicePtr, PushKernelArg};
use std::sync::Arc;

/// How the engine runs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Options {
    /// Load the PTX with fused multiply-add (`run.gpu_fma`, `--fma`).
    pub fma: bool,
    /// Read the step words after every step and launch the rebuild's
    /// kernels only at the steps that rebuild (`--sync-each-step`): one
    /// synchronisation per step instead of some twenty gated launches; the
    /// same bits either way. For measuring which costs less.
    pub sync_each_step: bool,
    /// Launch the steps of a stretch by sixteen as one CUDA graph
    /// (`--graph`): one launch instead of some four hundred, on a stream
    /// of its own (the legacy default stream cannot be captured); the
    /// same bits. Not with `sync_each_step`.
    pub graph: bool,
}

/// Threads per block of the per-grain kernels (whole warps: the force
/// kernel reduces its statistics per warp).
const THREADS: u32 = 128;
/// The scan kernels' block (SCAN_BLOCK in list.cu).
const SCAN: u32 = 1024;
pub use super::kernel_params::MAX_WALLS;

/// A vector per grain or entry on the device.
struct Dev3([CudaSlice<f64>; 3]);

/// The kernels by name.
struct Kernels {
    step_begin: CudaFunction,
    clear_halt: CudaFunction,
    build_end: CudaFunction,
    kick_drift: CudaFunction,
    wrap: CudaFunction,
    move_grains: CudaFunction,
    zero_u32: CudaFunction,
    copy_u32: CudaFunction,
    bin_count: CudaFunction,
    scan_local: CudaFunction,
    scan_sums: CudaFunction,
    scan_add: CudaFunction,
    bin_fill: CudaFunction,
    bin_sort: CudaFunction,
    place_counts: CudaFunction,
    sort_slots: CudaFunction,
    list_count: CudaFunction,
    list_fill: CudaFunction,
    remap: CudaFunction,
    forces: CudaFunction,
}

/// One list buffer: row starts, partners, image codes, springs.
struct DevList {
    start: CudaSlice<u32>,
    partner: CudaSlice<u32>,
    image: CudaSlice<u8>,
    springs: Dev3,
}

/// Everything that moves with a grain in a re-sort.
struct GrainSet {
    pos: Dev3,
    vel: Dev3,
    omega: Dev3,
    force: Dev3,
    torque: Dev3,
    radius: CudaSlice<f64>,
    mass: CudaSlice<f64>,
    inv_mass: CudaSlice<f64>,
    inv_inertia: CudaSlice<f64>,
    frozen: CudaSlice<u8>,
    id: CudaSlice<u64>,
    origin: CudaSlice<u32>,
    /// `walls` entries per grain (one padding entry without walls).
    wall_springs: Dev3,
}

/// The bins and prefix sums of a rebuild, allocated once.
struct Work {
    /// Cell of each grain; cell starts and fill cursors (the larger
    /// grid's cells + 1); members of the list grid's cells; the re-sort's
    /// permutation (members of the sort grid's cells).
    cell: CudaSlice<u32>,
    start: CudaSlice<u32>,
    cursor: CudaSlice<u32>,
    members: CudaSlice<u32>,
    order: CudaSlice<u32>,
    /// Partners per grain, scanned into the new list's row starts; the
    /// re-sort's new ranks.
    counts: CudaSlice<u32>,
    /// The sort grid's cells' places in the stored order.
    places: CudaSlice<u32>,
    /// The scans' block totals.
    sums: CudaSlice<u32>,
}

/// The pipeline's state on the device.
pub struct Cuda {
    /// The state uploaded from: parameters and what an export needs; its
    /// arrays are stale once the device runs, its counters current after
    /// each [`Cuda::advance`].
    host: Mirror,
    options: Options,
    stream: Arc<CudaStream>,
    k: Kernels,
    grains: GrainSet,
    /// Where a re-sort gathers to before copying back.
    scratch: GrainSet,
    reference: Dev3,
    /// Each grain's index in the CPU engine's order, and by old index
    /// before the last re-sort.
    rank: CudaSlice<u32>,
    rank_before: CudaSlice<u32>,
    lists: [DevList; 2],
    work: Work,
    /// The step words ([`words`]).
    st: CudaSlice<u64>,
    /// [`GRAPH_STEPS`] steps captured ([`Options::graph`]).
    graph: Option<Graph>,
}

/// A captured graph, owned by one engine.
struct Graph(CudaGraph);

// SAFETY: CUDA graph objects are not internally synchronised and must not
// be used from two threads at once; a Graph is reached only through its
// engine's `&mut self`, so moving the engine to another thread keeps every
// use serialised.
unsafe impl Send for Graph {}

/// Steps in one graph launch.
pub const GRAPH_STEPS: u64 = 16;

/// The gate arguments of the rebuild's kernels (GATE_* and ST_* of
/// common.cuh).
const ON_BUILD: u32 = words::BUILD as u32;
const ON_SORT: u32 = words::SORT as u32;

/// Launches `f` with `cfg` and the arguments (references to locals).
macro_rules! launch {
    ($self:ident, $f:ident, $cfg:expr; $($a:expr),* $(,)?) => {{
        let mut b = $self.stream.launch_builder(&$self.k.$f);
        $( b.arg($a); )*
        // SAFETY: the arguments are laid out as the kernel's parameters
        // (common.cuh and the .cu files), the buffers sized as it reads them.
        unsafe { b.launch($cfg) }
            .map(|_| ())
            .map_err(|e| gpu_err(stringify!($f), e))
    }};
}

impl Cuda {
    /// Uploads `m` to device 0 and loads the kernels without fused
    /// multiply-add.
    pub fn new(m: Mirror) -> Result<Self> {
        Self::with(m, Options::default())
    }

    /// The device's memory in use and in all (bytes).
    pub fn memory(&self) -> Result<(usize, usize)> {
        let (free, total) = self
            .stream
            .context()
            .mem_get_info()
            .map_err(|e| gpu_err("memory", e))?;
        Ok((total - free, total))
    }

    fn ptr<T>(&self, s: &CudaSlice<T>) -> u64 {
        s.device_ptr(&self.stream).0
    }

    fn soa(&self, d: &Dev3) -> Soa3P {
        Soa3P {
            x: self.ptr(&d.0[0]),
            y: self.ptr(&d.0[1]),
            z: self.ptr(&d.0[2]),
        }
    }

    fn grains_p(&self, s: &GrainSet) -> GrainsP {
        GrainsP {
            pos: self.soa(&s.pos),
            vel: self.soa(&s.vel),
            omega: self.soa(&s.omega),
            force: self.soa(&s.force),
            torque: self.soa(&s.torque),
            reference: self.soa(&self.reference),
            radius: self.ptr(&s.radius),
            mass: self.ptr(&s.mass),
            inv_mass: self.ptr(&s.inv_mass),
            inv_inertia: self.ptr(&s.inv_inertia),
            frozen: self.ptr(&s.frozen),
            rank: self.ptr(&self.rank),
            n: self.n() as u32,
        }
    }

    fn extra_p(&self, s: &GrainSet) -> ExtraP {
        ExtraP {
            id: self.ptr(&s.id),
            origin: self.ptr(&s.origin),
            wall_springs: self.soa(&s.wall_springs),
        }
    }

    fn lists_p(&self) -> ListsP {
        let l = |d: &DevList| ListP {
            start: self.ptr(&d.start),
            partner: self.ptr(&d.partner),
            image: self.ptr(&d.image),
            springs: self.soa(&d.springs),
        };
        ListsP {
            l: [l(&self.lists[0]), l(&self.lists[1])],
            cap: [0, 1].map(|w| self.lists[w].partner.len() as u64),
        }
    }

    fn n(&self) -> usize {
        self.host.len()
    }

    fn read_st(&self) -> Result<[u64; words::LEN]> {
        let v = self
            .stream
            .clone_dtoh(&self.st)
            .map_err(|e| gpu_err("read the step words", e))?;
        let mut st = [0; words::LEN];
        st.copy_from_slice(&v);
        Ok(st)
    }

    /// The integration kernel (see [`Mirror::advance`]'s kick pass).
    fn kick(&self, kicks: u32, drift: bool, check_every: u64, limit: f64) -> Result<()> {
        let g = self.grains_p(&self.grains);
        let p = &self.host.params;
        let (dt, limit2) = (p.dt, 0.25 * p.skin * p.skin);
        let (drift, st) = (drift as u32, self.ptr(&self.st));
        launch!(self, kick_drift, cfg(self.n(), THREADS);
            &g, &dt, &limit2, &kicks, &drift, &check_every, &limit, &st)
    }

    fn forces(&self) -> Result<()> {
        let p = &self.host.params;
        let mut walls = [PlaneP::default(); MAX_WALLS];
        for (
            w,
            &Plane {
                point,
                normal,
                gamma_n,
            },
        ) in walls.iter_mut().zip(&p.walls)
        {
            *w = PlaneP {
                point,
                normal,
                gamma_n,
            };
        }
        let args = ForceArgsP {
            law: p.law,
            shifts: self.host.shifts,
            walls,
            n_walls: p.walls.len() as u32,
            gravity: p.gravity,
            dt: p.dt,
            update: 1,
        };
        let (g, lists, ws, st) = (
            self.grains_p(&self.grains),
            self.lists_p(),
            self.soa(&self.grains.wall_springs),
            self.ptr(&self.st),
        );
        launch!(self, forces, cfg(self.n(), THREADS); &g, &lists, &ws, &args, &st)
    }

    /// Advances `n` steps: the mirror's [`Mirror::advance`], on the device.
    pub fn advance(&mut self, n: u64) -> Result<()> {
        if n == 0 {
            return Ok(());
        }
        let target = self.host.step + n;
        let st = self.ptr(&self.st);
        let step = self.host.step;
        launch!(self, clear_halt, ONE; &st, &step)?;
        self.kick(1, true, 0, f64::INFINITY)?;
        let mut resume = false;
        loop {
            self.enqueue(target, resume)?;
            self.host.st = self.read_st()?;
            match self.host.finish(target)? {
                Some(next) => {
                    self.grow(next, list_capacity(self.host.st[words::NEED] as usize))?;
                    // The halted step has begun: its count stands.
                    let step = self.host.step + 1;
                    launch!(self, clear_halt, ONE; &st, &step)?;
                    resume = true;
                }
                None => return Ok(()),
            }
        }
    }

    /// One step's launches after the first (none is the stretch's last):
    /// the same every step, all decisions on the step words.
    fn plain_step(&self) -> Result<()> {
        let p = &self.host.params;
        let (st, sort_every) = (self.ptr(&self.st), p.sort_every);
        launch!(self, step_begin, ONE; &st, &sort_every)?;
        self.wrap_sort(true)?;
        self.list_build()?;
        self.forces()?;
        self.kick(2, true, p.nan_check_every, p.max_overlap_fraction)
    }

    /// [`GRAPH_STEPS`] plain steps as a CUDA graph, captured at first use
    /// (and again after a list buffer moved).
    fn graph(&mut self) -> Result<&CudaGraph> {
        if self.graph.is_none() {
            let mode =
                cudarc::driver::sys::CUstreamCaptureMode::CU_STREAM_CAPTURE_MODE_THREAD_LOCAL;
            self.stream
                .begin_capture(mode)
                .map_err(|e| gpu_err("graph capture", e))?;
            let mut captured = Ok(());
            for _ in 0..GRAPH_STEPS {
                captured = captured.and_then(|_| self.plain_step());
            }
            let flags = cudarc::driver::sys::CUgraphInstantiate_flags(0);
            let graph = self
                .stream
                .end_capture(flags)
                .map_err(|e| gpu_err("graph capture", e))?;
            captured?;
            let graph = graph.ok_or_else(|| gpu_err("graph capture", "empty graph"))?;
            graph.upload().map_err(|e| gpu_err("graph upload", e))?;
            self.graph = Some(Graph(graph));
        }
        Ok(&self.graph.as_ref().expect("captured above").0)
    }

    /// The mirror's `enqueue`: the launches of the steps up to `target`.
    /// With [`Options::sync_each_step`] the host reads the words after
    /// each step and leaves out the launches that the words would gate off;
    /// with [`Options::graph`] the steps between the first and the last go
    /// by [`GRAPH_STEPS`] as one graph launch.
    fn enqueue(&mut self, target: u64, resume: bool) -> Result<()> {
        let p = self.host.params.clone();
        let (limit, every) = (p.max_overlap_fraction, p.nan_check_every);
        let st = self.ptr(&self.st);
        let (mut build, mut sort) = (true, true);
        let mut step = self.host.step;
        let mut first = true;
        loop {
            if !first && self.options.graph && target - step > GRAPH_STEPS {
                self.graph()?
                    .launch()
                    .map_err(|e| gpu_err("graph launch", e))?;
                step += GRAPH_STEPS;
                continue;
            }
            step += 1;
            let resumed = first && resume;
            first = false;
            if !resumed {
                let sort_every = p.sort_every;
                launch!(self, step_begin, ONE; &st, &sort_every)?;
                if build {
                    self.wrap_sort(sort)?;
                }
            }
            if build || resumed {
                self.list_build()?;
            }
            self.forces()?;
            if step == target {
                break;
            }
            self.kick(2, true, every, limit)?;
            if self.options.sync_each_step {
                let w = self.read_st()?;
                if w[words::HALT] != 0 {
                    break;
                }
                build = w[words::FAR] != 0 || w[words::BUILDS] == 0 || w[words::NONFINITE] != 0;
                let since = w[words::SINCE_SORT] as u32;
                sort = build && p.sort_every > 0 && since.is_multiple_of(p.sort_every);
            }
        }
        self.kick(1, false, every, limit)
    }

    /// Exclusive sums of `data` (`len` entries, the last a zero count that
    /// becomes the total) in place, gated on `word`.
    fn scan(&self, data: u64, len: usize, word: u32) -> Result<()> {
        let (st, sums) = (self.ptr(&self.st), self.ptr(&self.work.sums));
        let (len64, nb) = (len as u64, len.div_ceil(SCAN as usize) as u64);
        launch!(self, scan_local, cfg(len, SCAN); &data, &sums, &len64, &st, &word)?;
        launch!(self, scan_sums, cfg(1, SCAN); &sums, &nb, &st, &word)?;
        launch!(self, scan_add, cfg(len, SCAN); &data, &sums, &len64, &st, &word)
    }

    /// Bins the grains into `grid`, gated on `word`: the cell of each
    /// grain and the cell starts in the work arrays, the members (by rank
    /// in each cell) in `members`.
    fn bin(&self, grid: &Grid, members: u64, word: u32) -> Result<()> {
        let w = &self.work;
        let (st, cell, start, cursor) = (
            self.ptr(&self.st),
            self.ptr(&w.cell),
            self.ptr(&w.start),
            self.ptr(&w.cursor),
        );
        let (n, ncells) = (self.n(), grid.ncells());
        let (n64, nc, len) = (n as u64, ncells as u64, (ncells + 1) as u64);
        let g = self.grains_p(&self.grains);
        let gp = grid_p(grid);
        launch!(self, zero_u32, cfg(ncells + 1, THREADS); &start, &len, &st, &word)?;
        launch!(self, bin_count, cfg(n, THREADS); &g, &gp, &cell, &start, &st, &word)?;
        self.scan(start, ncells + 1, word)?;
        launch!(self, copy_u32, cfg(ncells + 1, THREADS); &start, &cursor, &len, &st, &word)?;
        launch!(self, bin_fill, cfg(n, THREADS); &cell, &cursor, &members, &n64, &st, &word)?;
        let rank = self.ptr(&self.rank);
        launch!(self, bin_sort, cfg(ncells, THREADS); &start, &members, &nc, &rank, &st, &word)
    }

    /// The rebuild's first part (gated on BUILD): the wrap, and on SORT
    /// the re-sort (the mirror's `sort_slots`), gathered into the scratch
    /// arrays and copied back, the new ranks copied in. With `sort` false
    /// the re-sort's launches are left out (the host knows none is due).
    fn wrap_sort(&self, sort: bool) -> Result<()> {
        let p = &self.host.params;
        let bx = Box3P {
            lo: p.bx.lo,
            length: p.bx.length,
            periodic: p.bx.periodic.map(|b| b as u32),
        };
        let g = self.grains_p(&self.grains);
        let st = self.ptr(&self.st);
        launch!(self, wrap, cfg(self.n(), THREADS); &g, &bx, &st)?;
        if !sort {
            return Ok(());
        }
        let w = &self.work;
        let (members, order, cell, start, first, new_rank) = (
            self.ptr(&w.members),
            self.ptr(&w.order),
            self.ptr(&w.cell),
            self.ptr(&w.start),
            self.ptr(&w.cursor),
            self.ptr(&w.counts),
        );
        let (places, rank, before) = (
            self.ptr(&w.places),
            self.ptr(&self.rank),
            self.ptr(&self.rank_before),
        );
        let ncells = p.sort_grid.ncells();
        let (n, nc) = (self.n() as u64, ncells as u64);
        self.bin(&p.sort_grid, members, ON_SORT)?;
        launch!(self, place_counts, cfg(ncells, THREADS); &start, &places, &first, &nc, &st)?;
        self.scan(first, ncells + 1, ON_SORT)?;
        launch!(self, sort_slots, cfg(self.n(), THREADS);
            &members, &cell, &start, &places, &first, &rank, &before, &order, &new_rank, &n, &st)?;
        let (xg, s, xs) = (
            self.extra_p(&self.grains),
            self.grains_p(&self.scratch),
            self.extra_p(&self.scratch),
        );
        let slots = p.walls.len() as u32;
        let none = 0u64;
        launch!(self, move_grains, cfg(self.n(), THREADS); &g, &xg, &s, &xs, &order, &slots, &st)?;
        launch!(self, move_grains, cfg(self.n(), THREADS); &s, &xs, &g, &xg, &none, &slots, &st)?;
        launch!(self, copy_u32, cfg(self.n(), THREADS); &new_rank, &rank, &n, &st, &ON_SORT)
    }

    /// The rebuild's second part (gated on BUILD): bins of the list grid,
    /// the rows counted and scanned, filled into the other list buffer (or
    /// a halt when they do not fit), the springs remapped, the build
    /// counted.
    fn list_build(&self) -> Result<()> {
        let p = &self.host.params;
        let n = self.n();
        let members = self.ptr(&self.work.members);
        self.bin(&p.list_grid, members, ON_BUILD)?;
        let args = ListArgsP {
            grid: grid_p(&p.list_grid),
            start_cells: self.ptr(&self.work.start),
            members,
            cell: self.ptr(&self.work.cell),
            length: p.bx.length,
            shifts: self.host.shifts,
            skin: p.skin,
            periodic: p.bx.periodic.map(|b| b as u32),
            block: p.block as u32,
        };
        let (g, lists, st) = (
            self.grains_p(&self.grains),
            self.lists_p(),
            self.ptr(&self.st),
        );
        let counts = self.ptr(&self.work.counts);
        launch!(self, list_count, cfg(n, THREADS); &g, &args, &counts, &st)?;
        self.scan(counts, n + 1, ON_BUILD)?;
        launch!(self, list_fill, cfg(n, THREADS); &g, &args, &lists, &counts, &st)?;
        let (order, before) = (self.ptr(&self.work.order), self.ptr(&self.rank_before));
        launch!(self, remap, cfg(n, THREADS); &g, &lists, &order, &before, &st)?;
        launch!(self, build_end, ONE; &st)
    }

    /// List buffer `which` reallocated for `cap` entries (it holds no list
    /// now: the stretch halted before filling it).
    fn grow(&mut self, which: usize, cap: usize) -> Result<()> {
        let s = &self.stream;
        let l = &mut self.lists[which];
        l.partner = zeros(s, cap)?;
        l.image = zeros(s, cap)?;
        l.springs = Dev3([zeros(s, cap)?, zeros(s, cap)?, zeros(s, cap)?]);
        self.host.capacity[which] = cap;
        // The graph holds the old buffer's addresses.
        self.graph = None;
        Ok(())
    }

    /// The state uploaded from: its arrays are stale, its counters (step,
    /// time, list builds) current.
    pub fn counters(&self) -> &Mirror {
        &self.host
    }
}
