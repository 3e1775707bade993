//! The pipeline on an NVIDIA GPU (feature `cuda`): the mirror's passes as
//! launches of the kernels in `kernels/*.cu`, from the PTX checked in under
//! `kernels/ptx/` (`tools/make_ptx.py`), through `cudarc`, which loads
//! libcuda at run time.
//!
//! The host keeps the [`Mirror`] it started from (parameters, and what an
//! export needs); the grains live on the device and come back only when
//! asked ([`Cuda::host`]). One stream, in order; per step one read of a
//! few words (the rebuild flag, the statistics).

use super::grain_kernels::Plane;
use super::mirror::Mirror;
use crate::error::{Error, Result};
use cudarc::driver::{
    CudaContext, CudaFunction, CudaSlice, CudaStream, DevicePtr, DeviceRepr, LaunchConfig,
    PushKernelArg,
};
use cudarc::nvrtc::Ptx;
use std::sync::Arc;

/// The checked-in PTX, without fused multiply-add (the CPU engine's bits).
const PTX: [(&str, &str); 3] = [
    ("integrate", include_str!("kernels/ptx/integrate.ptx")),
    ("list", include_str!("kernels/ptx/list.ptx")),
    ("forces", include_str!("kernels/ptx/forces.ptx")),
];

/// Threads per block of the per-grain kernels (whole warps: the force
/// kernel reduces its statistics per warp).
const THREADS: u32 = 128;
/// The scan kernels' block (SCAN_BLOCK in list.cu).
const SCAN: u32 = 1024;
/// Walls a force launch carries (MAX_WALLS in common.cuh).
pub const MAX_WALLS: usize = 8;

fn gpu_err(what: &str, e: impl std::fmt::Debug) -> Error {
    Error::input(format!("GPU engine: {what}: {e:?}"))
}

// Kernel arguments, laid out as the structs of common.cuh and the .cu files.
#[repr(C)]
#[derive(Clone, Copy, Default)]
struct Soa3P {
    x: u64,
    y: u64,
    z: u64,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
struct GrainsP {
    pos: Soa3P,
    vel: Soa3P,
    omega: Soa3P,
    force: Soa3P,
    torque: Soa3P,
    reference: Soa3P,
    radius: u64,
    mass: u64,
    inv_mass: u64,
    inv_inertia: u64,
    frozen: u64,
    n: u32,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
struct ListP {
    start: u64,
    partner: u64,
    image: u64,
    springs: Soa3P,
}
#[repr(C)]
#[derive(Clone, Copy)]
struct HookeP {
    kn: f64,
    gamma_n: f64,
    gamma_t: f64,
    kt: f64,
    mu: f64,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
struct PlaneP {
    point: [f64; 3],
    normal: [f64; 3],
    gamma_n: f64,
}
#[repr(C)]
#[derive(Clone, Copy)]
struct ForceArgsP {
    law: HookeP,
    shifts: [[f64; 3]; 27],
    walls: [PlaneP; MAX_WALLS],
    n_walls: u32,
    gravity: [f64; 3],
    dt: f64,
    update: u32,
}
#[repr(C)]
#[derive(Clone, Copy)]
struct Box3P {
    lo: [f64; 3],
    length: [f64; 3],
    periodic: [u32; 3],
}
#[repr(C)]
#[derive(Clone, Copy)]
struct GridP {
    dims: [u64; 3],
    lo: [f64; 3],
    inv_width: [f64; 3],
}
#[repr(C)]
#[derive(Clone, Copy)]
struct ListArgsP {
    grid: GridP,
    start_cells: u64,
    members: u64,
    cell: u64,
    length: [f64; 3],
    shifts: [[f64; 3]; 27],
    skin: f64,
    periodic: [u32; 3],
    block: u32,
}

// SAFETY: plain #[repr(C)] data (numbers and device addresses), laid out
// as the kernels' parameter structs.
unsafe impl DeviceRepr for Soa3P {}
unsafe impl DeviceRepr for GrainsP {}
unsafe impl DeviceRepr for ListP {}
unsafe impl DeviceRepr for ForceArgsP {}
unsafe impl DeviceRepr for Box3P {}
unsafe impl DeviceRepr for GridP {}
unsafe impl DeviceRepr for ListArgsP {}

/// A vector per grain or entry on the device.
struct Dev3([CudaSlice<f64>; 3]);

/// The kernels by name.
struct Kernels {
    kick_drift: CudaFunction,
    wrap: CudaFunction,
    gather_f64: CudaFunction,
    gather_u64: CudaFunction,
    gather_u32: CudaFunction,
    gather_u8: CudaFunction,
    gather_slots: CudaFunction,
    bin_count: CudaFunction,
    scan_local: CudaFunction,
    scan_sums: CudaFunction,
    scan_add: CudaFunction,
    bin_fill: CudaFunction,
    bin_sort: CudaFunction,
    list_count: CudaFunction,
    list_fill: CudaFunction,
    remap: CudaFunction,
    forces: CudaFunction,
}

/// The device list: row starts, partners, image codes, springs.
struct DevList {
    start: CudaSlice<u32>,
    partner: CudaSlice<u32>,
    image: CudaSlice<u8>,
    springs: Dev3,
}

/// The pipeline's state on the device.
pub struct Cuda {
    /// The state uploaded from: parameters and what an export needs; its
    /// arrays are stale once the device runs.
    host: Mirror,
    stream: Arc<CudaStream>,
    k: Kernels,
    pos: Dev3,
    vel: Dev3,
    omega: Dev3,
    force: Dev3,
    torque: Dev3,
    reference: Dev3,
    radius: CudaSlice<f64>,
    mass: CudaSlice<f64>,
    inv_mass: CudaSlice<f64>,
    inv_inertia: CudaSlice<f64>,
    frozen: CudaSlice<u8>,
    id: CudaSlice<u64>,
    origin: CudaSlice<u32>,
    list: DevList,
    wall_springs: Dev3,
    /// Step flags and statistics (ST_* of common.cuh).
    st: CudaSlice<u64>,
    /// 0, 1, …, n − 1: the permutation of a rebuild without a re-sort.
    identity: CudaSlice<u32>,
}

/// Loads one PTX file. NVRTC 13.5 writes PTX ISA 9.5, which a driver older
/// than CUDA 13.5 refuses; the kernels use nothing newer than ISA 8.0
/// (CUDA 12.0), so on refusal the file is loaded again with its `.version`
/// lowered to what the driver reads (8.0 for 12.x, 9.0 for 13.x), with a
/// note on stderr.
fn load_ptx(
    ctx: &Arc<CudaContext>,
    name: &str,
    ptx: &str,
) -> Result<Arc<cudarc::driver::CudaModule>> {
    let first = match ctx.load_module(Ptx::from_src(ptx)) {
        Ok(m) => return Ok(m),
        Err(e) => e,
    };
    let mut driver = 0;
    // SAFETY: writes one int; the driver library is loaded (the context exists).
    unsafe { cudarc::driver::sys::cuDriverGetVersion(&mut driver) };
    let isa = if driver >= 13000 { "9.0" } else { "8.0" };
    let lowered: String = ptx
        .lines()
        .map(|l| {
            if l.starts_with(".version ") {
                format!(".version {isa}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    eprintln!(
        "grains: {name}.ptx refused by driver {driver} ({first:?}); loading it as PTX ISA {isa}"
    );
    ctx.load_module(Ptx::from_src(lowered)).map_err(|e| {
        gpu_err(
            &format!(
                "loading {name}.ptx (driver {driver}; also as PTX ISA {isa}): rebuild the PTX \
                 with an NVRTC no newer than the driver (tools/make_ptx.py)"
            ),
            e,
        )
    })
}

fn cfg(n: usize, threads: u32) -> LaunchConfig {
    LaunchConfig {
        grid_dim: ((n as u32).div_ceil(threads).max(1), 1, 1),
        block_dim: (threads, 1, 1),
        shared_mem_bytes: 0,
    }
}

impl Cuda {
    /// Uploads `m` to device 0 and loads the kernels.
    pub fn new(m: Mirror) -> Result<Self> {
        if m.params.walls.len() > MAX_WALLS {
            return Err(Error::input(format!(
                "run.device = \"gpu\": {} walls; the GPU engine takes at most {MAX_WALLS}",
                m.params.walls.len()
            )));
        }
        // SAFETY: only tries to open the driver library.
        if !unsafe { cudarc::driver::sys::is_culib_present() } {
            return Err(Error::input(
                "GPU engine: no CUDA driver (libcuda) on this machine",
            ));
        }
        let ctx = CudaContext::new(0).map_err(|e| gpu_err("no CUDA device", e))?;
        // One stream, launches in order: cudarc's per-buffer events would
        // only cost time.
        unsafe { ctx.disable_event_tracking() };
        let stream = ctx.default_stream();
        let mut modules = Vec::new();
        for (name, ptx) in PTX {
            modules.push(load_ptx(&ctx, name, ptx)?);
        }
        let f = |m: usize, name: &str| {
            modules[m]
                .load_function(name)
                .map_err(|e| gpu_err(&format!("kernel {name}"), e))
        };
        let k = Kernels {
            kick_drift: f(0, "kick_drift")?,
            wrap: f(0, "wrap_grains")?,
            gather_f64: f(0, "gather_f64")?,
            gather_u64: f(0, "gather_u64")?,
            gather_u32: f(0, "gather_u32")?,
            gather_u8: f(0, "gather_u8")?,
            gather_slots: f(0, "gather_slots")?,
            bin_count: f(1, "bin_count")?,
            scan_local: f(1, "scan_local")?,
            scan_sums: f(1, "scan_sums")?,
            scan_add: f(1, "scan_add")?,
            bin_fill: f(1, "bin_fill")?,
            bin_sort: f(1, "bin_sort")?,
            list_count: f(1, "list_count")?,
            list_fill: f(1, "list_fill")?,
            remap: f(1, "remap_springs")?,
            forces: f(2, "forces")?,
        };
        // Empty arrays (no walls, no pairs) get one entry: no buffer is
        // allocated empty.
        let up = |v: &[f64]| {
            let pad = [0.0];
            let v = if v.is_empty() { &pad[..] } else { v };
            stream.clone_htod(v).map_err(|e| gpu_err("upload", e))
        };
        let up3 = |s: &super::grain_kernels::Soa3| -> Result<Dev3> {
            Ok(Dev3([up(&s.x)?, up(&s.y)?, up(&s.z)?]))
        };
        let n = m.len();
        fn pad<T: Copy + Default>(v: &[T]) -> Vec<T> {
            if v.is_empty() {
                vec![T::default()]
            } else {
                v.to_vec()
            }
        }
        let list = DevList {
            start: stream
                .clone_htod(&m.list.start)
                .map_err(|e| gpu_err("upload", e))?,
            partner: stream
                .clone_htod(&pad(&m.list.partner))
                .map_err(|e| gpu_err("upload", e))?,
            image: stream
                .clone_htod(&pad(&m.list.image))
                .map_err(|e| gpu_err("upload", e))?,
            springs: up3(&m.springs)?,
        };
        let identity: Vec<u32> = (0..n as u32).collect();
        Ok(Self {
            pos: up3(&m.pos)?,
            vel: up3(&m.vel)?,
            omega: up3(&m.omega)?,
            force: up3(&m.force)?,
            torque: up3(&m.torque)?,
            reference: up3(&m.reference)?,
            radius: up(&m.radius)?,
            mass: up(&m.mass)?,
            inv_mass: up(&m.inv_mass)?,
            inv_inertia: up(&m.inv_inertia)?,
            frozen: stream
                .clone_htod(&m.frozen)
                .map_err(|e| gpu_err("upload", e))?,
            id: stream.clone_htod(&m.id).map_err(|e| gpu_err("upload", e))?,
            origin: stream
                .clone_htod(&m.origin)
                .map_err(|e| gpu_err("upload", e))?,
            list,
            wall_springs: up3(&m.wall_springs)?,
            st: stream
                .alloc_zeros::<u64>(8)
                .map_err(|e| gpu_err("alloc", e))?,
            identity: stream
                .clone_htod(&identity)
                .map_err(|e| gpu_err("upload", e))?,
            host: m,
            stream,
            k,
        })
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

    fn grains(&self) -> GrainsP {
        GrainsP {
            pos: self.soa(&self.pos),
            vel: self.soa(&self.vel),
            omega: self.soa(&self.omega),
            force: self.soa(&self.force),
            torque: self.soa(&self.torque),
            reference: self.soa(&self.reference),
            radius: self.ptr(&self.radius),
            mass: self.ptr(&self.mass),
            inv_mass: self.ptr(&self.inv_mass),
            inv_inertia: self.ptr(&self.inv_inertia),
            frozen: self.ptr(&self.frozen),
            n: self.host.len() as u32,
        }
    }

    fn list_p(&self, l: &DevList) -> ListP {
        ListP {
            start: self.ptr(&l.start),
            partner: self.ptr(&l.partner),
            image: self.ptr(&l.image),
            springs: self.soa(&l.springs),
        }
    }

    fn n(&self) -> usize {
        self.host.len()
    }

    fn zero_st(&mut self) -> Result<()> {
        self.stream
            .memset_zeros(&mut self.st)
            .map_err(|e| gpu_err("memset", e))
    }

    fn read_st(&self) -> Result<Vec<u64>> {
        self.stream
            .clone_dtoh(&self.st)
            .map_err(|e| gpu_err("read flags", e))
    }

    fn kick(&mut self, kicks: u32, drift: bool, check: bool) -> Result<()> {
        let g = self.grains();
        let p = &self.host.params;
        let (dt, limit2) = (p.dt, 0.25 * p.skin * p.skin);
        let (drift, check) = (drift as u32, check as u32);
        let mut b = self.stream.launch_builder(&self.k.kick_drift);
        b.arg(&g)
            .arg(&dt)
            .arg(&limit2)
            .arg(&kicks)
            .arg(&drift)
            .arg(&check)
            .arg(&self.st);
        unsafe { b.launch(cfg(self.n(), THREADS)) }
            .map(|_| ())
            .map_err(|e| gpu_err("kick_drift", e))
    }

    fn forces(&mut self, update: bool) -> Result<()> {
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
        let l = p.law;
        let args = ForceArgsP {
            law: HookeP {
                kn: l.kn,
                gamma_n: l.gamma_n,
                gamma_t: l.gamma_t,
                kt: l.kt,
                mu: l.mu,
            },
            shifts: self.host.shifts,
            walls,
            n_walls: p.walls.len() as u32,
            gravity: p.gravity,
            dt: p.dt,
            update: update as u32,
        };
        let (g, list, ws) = (
            self.grains(),
            self.list_p(&self.list),
            self.soa(&self.wall_springs),
        );
        let mut b = self.stream.launch_builder(&self.k.forces);
        b.arg(&g).arg(&list).arg(&ws).arg(&args).arg(&self.st);
        unsafe { b.launch(cfg(self.n(), THREADS)) }
            .map(|_| ())
            .map_err(|e| gpu_err("forces", e))
    }

    /// Checks the last force evaluation's overlap and the finiteness flag
    /// (`st` as read after a kick), as the mirror does.
    fn judge(&mut self, st: &[u64]) -> Result<()> {
        self.host.stats = super::mirror::Stats {
            contacts: st[2] / 2 + st[3],
            max_fraction: f64::from_bits(st[4]),
        };
        self.host.step_checks(st[1] != 0)
    }

    /// Advances `n` steps: the mirror's [`Mirror::advance`], on the device.
    pub fn advance(&mut self, n: u64) -> Result<()> {
        if n == 0 {
            return Ok(());
        }
        self.zero_st()?;
        self.kick(1, true, false)?;
        let mut far = self.read_st()?[0] != 0 || self.host.builds == 0;
        for left in (0..n).rev() {
            self.host.step += 1;
            self.host.time = self.host.step as f64 * self.host.params.dt;
            if far {
                self.rebuild()?;
            }
            self.zero_st()?;
            self.forces(true)?;
            if left == 0 {
                break;
            }
            let due = self.host.finite_check_due();
            self.kick(2, true, due)?;
            let st = self.read_st()?;
            self.judge(&st)?;
            far = st[0] != 0;
        }
        let due = self.host.finite_check_due();
        self.kick(1, false, due)?;
        let st = self.read_st()?;
        self.judge(&st)
    }

    fn launch_gather<T>(
        &self,
        f: &CudaFunction,
        src: &CudaSlice<T>,
        order: &CudaSlice<u32>,
    ) -> Result<CudaSlice<T>>
    where
        T: DeviceRepr + cudarc::driver::ValidAsZeroBits,
    {
        let n = self.n() as u64;
        let mut dst = self
            .stream
            .alloc_zeros::<T>(src.len())
            .map_err(|e| gpu_err("alloc", e))?;
        let mut b = self.stream.launch_builder(f);
        b.arg(src).arg(&mut dst).arg(order).arg(&n);
        unsafe { b.launch(cfg(self.n(), THREADS)) }.map_err(|e| gpu_err("gather", e))?;
        Ok(dst)
    }

    fn gather3(&self, d: &Dev3, order: &CudaSlice<u32>) -> Result<Dev3> {
        let f = &self.k.gather_f64;
        Ok(Dev3([
            self.launch_gather(f, &d.0[0], order)?,
            self.launch_gather(f, &d.0[1], order)?,
            self.launch_gather(f, &d.0[2], order)?,
        ]))
    }

    /// Puts the grains in `order` (entry k: old index of new grain k).
    fn permute(&mut self, order: &CudaSlice<u32>) -> Result<()> {
        self.pos = self.gather3(&self.pos, order)?;
        self.vel = self.gather3(&self.vel, order)?;
        self.omega = self.gather3(&self.omega, order)?;
        self.force = self.gather3(&self.force, order)?;
        self.torque = self.gather3(&self.torque, order)?;
        let f = &self.k.gather_f64;
        self.radius = self.launch_gather(f, &self.radius, order)?;
        self.mass = self.launch_gather(f, &self.mass, order)?;
        self.inv_mass = self.launch_gather(f, &self.inv_mass, order)?;
        self.inv_inertia = self.launch_gather(f, &self.inv_inertia, order)?;
        self.frozen = self.launch_gather(&self.k.gather_u8, &self.frozen, order)?;
        self.id = self.launch_gather(&self.k.gather_u64, &self.id, order)?;
        self.origin = self.launch_gather(&self.k.gather_u32, &self.origin, order)?;
        let slots = self.host.params.walls.len() as u32;
        if slots > 0 {
            let n = self.n() as u64;
            let gather = |c: &CudaSlice<f64>| -> Result<CudaSlice<f64>> {
                let mut dst = self
                    .stream
                    .alloc_zeros::<f64>(c.len())
                    .map_err(|e| gpu_err("alloc", e))?;
                let mut b = self.stream.launch_builder(&self.k.gather_slots);
                b.arg(c).arg(&mut dst).arg(order).arg(&n).arg(&slots);
                unsafe { b.launch(cfg(c.len(), THREADS)) }
                    .map_err(|e| gpu_err("gather_slots", e))?;
                Ok(dst)
            };
            let w = &self.wall_springs.0;
            let (x, y, z) = (gather(&w[0])?, gather(&w[1])?, gather(&w[2])?);
            self.wall_springs = Dev3([x, y, z]);
        }
        Ok(())
    }

    /// Exclusive sums of `data` in place (its last entry, a zero count,
    /// becomes the total); returns the total.
    fn scan(&self, data: &mut CudaSlice<u32>) -> Result<u32> {
        let len = data.len() as u64;
        let nb = (len as u32).div_ceil(SCAN) as u64;
        let mut sums = self
            .stream
            .alloc_zeros::<u32>(nb as usize + 1)
            .map_err(|e| gpu_err("alloc", e))?;
        let mut b = self.stream.launch_builder(&self.k.scan_local);
        b.arg(&mut *data).arg(&mut sums).arg(&len);
        unsafe { b.launch(cfg(len as usize, SCAN)) }.map_err(|e| gpu_err("scan", e))?;
        let mut b = self.stream.launch_builder(&self.k.scan_sums);
        b.arg(&mut sums).arg(&nb);
        unsafe { b.launch(cfg(1, SCAN)) }.map_err(|e| gpu_err("scan", e))?;
        let mut b = self.stream.launch_builder(&self.k.scan_add);
        b.arg(&mut *data).arg(&sums).arg(&len);
        unsafe { b.launch(cfg(len as usize, SCAN)) }.map_err(|e| gpu_err("scan", e))?;
        let total = self
            .stream
            .clone_dtoh(&sums.slice(nb as usize..))
            .map_err(|e| gpu_err("scan total", e))?;
        Ok(total[0])
    }

    /// Bins the grains into `grid`: (cell of each grain, cell starts,
    /// members ascending in each cell).
    fn bin(
        &self,
        grid: &super::grain_kernels::Grid,
    ) -> Result<(CudaSlice<u32>, CudaSlice<u32>, CudaSlice<u32>)> {
        let n = self.n();
        let ncells = grid.ncells();
        let gp = GridP {
            dims: grid.dims.map(|d| d as u64),
            lo: grid.lo,
            inv_width: grid.inv_width,
        };
        let alloc = |len: usize| {
            self.stream
                .alloc_zeros::<u32>(len)
                .map_err(|e| gpu_err("alloc", e))
        };
        let (mut cell, mut start, mut members) = (alloc(n)?, alloc(ncells + 1)?, alloc(n)?);
        let g = self.grains();
        let mut b = self.stream.launch_builder(&self.k.bin_count);
        b.arg(&g).arg(&gp).arg(&mut cell).arg(&mut start);
        unsafe { b.launch(cfg(n, THREADS)) }.map_err(|e| gpu_err("bin_count", e))?;
        self.scan(&mut start)?;
        let mut cursor = self
            .stream
            .clone_dtod(&start)
            .map_err(|e| gpu_err("copy", e))?;
        let n64 = n as u64;
        let mut b = self.stream.launch_builder(&self.k.bin_fill);
        b.arg(&cell).arg(&mut cursor).arg(&mut members).arg(&n64);
        unsafe { b.launch(cfg(n, THREADS)) }.map_err(|e| gpu_err("bin_fill", e))?;
        let nc = ncells as u64;
        let mut b = self.stream.launch_builder(&self.k.bin_sort);
        b.arg(&start).arg(&mut members).arg(&nc);
        unsafe { b.launch(cfg(ncells, THREADS)) }.map_err(|e| gpu_err("bin_sort", e))?;
        Ok((cell, start, members))
    }

    /// The mirror's [`Mirror::rebuild`] on the device.
    fn rebuild(&mut self) -> Result<()> {
        let n = self.n();
        let p = self.host.params.clone();
        let bx = Box3P {
            lo: p.bx.lo,
            length: p.bx.length,
            periodic: p.bx.periodic.map(|b| b as u32),
        };
        let g = self.grains();
        let mut b = self.stream.launch_builder(&self.k.wrap);
        b.arg(&g).arg(&bx);
        unsafe { b.launch(cfg(n, THREADS)) }.map_err(|e| gpu_err("wrap", e))?;
        let every = p.sort_every;
        let sorted = every > 0 && self.host.rebuilds_since_sort.is_multiple_of(every);
        let order = if sorted {
            let (_, _, members) = self.bin(&p.sort_grid)?;
            self.permute(&members)?;
            Some(members)
        } else {
            None
        };
        self.host.rebuilds_since_sort = self.host.rebuilds_since_sort.wrapping_add(1);
        let (cell, start_cells, members) = self.bin(&p.list_grid)?;
        let args = ListArgsP {
            grid: GridP {
                dims: p.list_grid.dims.map(|d| d as u64),
                lo: p.list_grid.lo,
                inv_width: p.list_grid.inv_width,
            },
            start_cells: self.ptr(&start_cells),
            members: self.ptr(&members),
            cell: self.ptr(&cell),
            length: p.bx.length,
            shifts: self.host.shifts,
            skin: p.skin,
            periodic: p.bx.periodic.map(|b| b as u32),
            block: p.block as u32,
        };
        let mut start = self
            .stream
            .alloc_zeros::<u32>(n + 1)
            .map_err(|e| gpu_err("alloc", e))?;
        let g = self.grains();
        let mut b = self.stream.launch_builder(&self.k.list_count);
        b.arg(&g).arg(&args).arg(&mut start);
        unsafe { b.launch(cfg(n, THREADS)) }.map_err(|e| gpu_err("list_count", e))?;
        let total = self.scan(&mut start)? as usize;
        let alloc_f = |len: usize| {
            self.stream
                .alloc_zeros::<f64>(len.max(1))
                .map_err(|e| gpu_err("alloc", e))
        };
        let list = DevList {
            start,
            partner: self
                .stream
                .alloc_zeros::<u32>(total.max(1))
                .map_err(|e| gpu_err("alloc", e))?,
            image: self
                .stream
                .alloc_zeros::<u8>(total.max(1))
                .map_err(|e| gpu_err("alloc", e))?,
            springs: Dev3([alloc_f(total)?, alloc_f(total)?, alloc_f(total)?]),
        };
        let lp = self.list_p(&list);
        let mut b = self.stream.launch_builder(&self.k.list_fill);
        b.arg(&g).arg(&args).arg(&lp);
        unsafe { b.launch(cfg(n, THREADS)) }.map_err(|e| gpu_err("list_fill", e))?;
        let old = self.list_p(&self.list);
        let old_of = order.as_ref().unwrap_or(&self.identity);
        let n32 = n as u32;
        let mut b = self.stream.launch_builder(&self.k.remap);
        b.arg(&n32).arg(&lp).arg(&old).arg(old_of);
        unsafe { b.launch(cfg(n, THREADS)) }.map_err(|e| gpu_err("remap_springs", e))?;
        self.list = list;
        for a in 0..3 {
            self.stream
                .memcpy_dtod(&self.pos.0[a], &mut self.reference.0[a])
                .map_err(|e| gpu_err("copy", e))?;
        }
        self.host.builds += 1;
        Ok(())
    }

    /// The state uploaded from: its arrays are stale, its counters (step,
    /// time, list builds) current.
    pub fn counters(&self) -> &Mirror {
        &self.host
    }

    /// The state now, on the host (a copy of the device's arrays).
    pub fn host(&self) -> Result<Mirror> {
        let s = &self.stream;
        let down = |d: &CudaSlice<f64>| s.clone_dtoh(d).map_err(|e| gpu_err("download", e));
        let down3 = |d: &Dev3| -> Result<super::grain_kernels::Soa3> {
            Ok(super::grain_kernels::Soa3 {
                x: down(&d.0[0])?,
                y: down(&d.0[1])?,
                z: down(&d.0[2])?,
            })
        };
        let mut m = self.host.clone();
        m.pos = down3(&self.pos)?;
        m.vel = down3(&self.vel)?;
        m.omega = down3(&self.omega)?;
        m.force = down3(&self.force)?;
        m.torque = down3(&self.torque)?;
        m.reference = down3(&self.reference)?;
        m.radius = down(&self.radius)?;
        m.mass = down(&self.mass)?;
        m.inv_mass = down(&self.inv_mass)?;
        m.inv_inertia = down(&self.inv_inertia)?;
        let e = |e| gpu_err("download", e);
        m.frozen = s.clone_dtoh(&self.frozen).map_err(e)?;
        m.id = s.clone_dtoh(&self.id).map_err(e)?;
        m.origin = s.clone_dtoh(&self.origin).map_err(e)?;
        m.list.start = s.clone_dtoh(&self.list.start).map_err(e)?;
        let total = m.list.start[m.len()] as usize;
        m.list.partner = s.clone_dtoh(&self.list.partner).map_err(e)?;
        m.list.image = s.clone_dtoh(&self.list.image).map_err(e)?;
        m.list.partner.truncate(total);
        m.list.image.truncate(total);
        let mut springs = down3(&self.list.springs)?;
        for c in [&mut springs.x, &mut springs.y, &mut springs.z] {
            c.truncate(total);
        }
        m.springs = springs;
        m.wall_springs = down3(&self.wall_springs)?;
        Ok(m)
    }
}
