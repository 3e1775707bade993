//! The GPU engine's state between host and device.
//!
//! A mirror uploaded to device 0 (context, stream, the kernels loaded from
//! the PTX, every buffer allocated once), and the device's arrays
//! downloaded into a mirror.

use super::{Cuda, Dev3, DevList, GrainSet, Kernels, Options, Work, SCAN};
use crate::error::{Error, Result};
use crate::gpu::grain_kernels::{words, Soa3};
use crate::gpu::kernel_params::{gpu_err, load_ptx, up, zeros, MAX_WALLS, PTX, PTX_FMA};
use crate::gpu::mirror::Mirror;
use cudarc::driver::{CudaContext, CudaSlice};

impl Cuda {
    /// Uploads `m` to device 0 and loads the kernels `options` name.
    pub fn with(m: Mirror, options: Options) -> Result<Self> {
        if options.graph && options.sync_each_step {
            return Err(Error::input(
                "GPU engine: a graph of steps and a read after each step exclude each other",
            ));
        }
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
        let stream = if options.graph {
            ctx.new_stream().map_err(|e| gpu_err("stream", e))?
        } else {
            ctx.default_stream()
        };
        let mut modules = Vec::new();
        for (name, ptx) in if options.fma { PTX_FMA } else { PTX } {
            modules.push(load_ptx(&ctx, name, ptx)?);
        }
        let f = |m: usize, name: &str| {
            modules[m]
                .load_function(name)
                .map_err(|e| gpu_err(&format!("kernel {name}"), e))
        };
        let k = Kernels {
            step_begin: f(0, "step_begin")?,
            clear_halt: f(0, "clear_halt")?,
            build_end: f(0, "build_end")?,
            kick_drift: f(0, "kick_drift")?,
            wrap: f(0, "wrap_grains")?,
            move_grains: f(0, "move_grains")?,
            zero_u32: f(0, "zero_u32")?,
            copy_u32: f(0, "copy_u32")?,
            bin_count: f(1, "bin_count")?,
            scan_local: f(1, "scan_local")?,
            scan_sums: f(1, "scan_sums")?,
            scan_add: f(1, "scan_add")?,
            bin_fill: f(1, "bin_fill")?,
            bin_sort: f(1, "bin_sort")?,
            place_counts: f(1, "place_counts")?,
            sort_slots: f(1, "sort_slots")?,
            list_count: f(1, "list_count")?,
            list_fill: f(1, "list_fill")?,
            remap: f(1, "remap_springs")?,
            forces: f(2, "forces")?,
        };
        let n = m.len();
        let nw = m.params.walls.len();
        let up3 = |s: &Soa3| -> Result<Dev3> {
            Ok(Dev3([
                up(&stream, &s.x)?,
                up(&stream, &s.y)?,
                up(&stream, &s.z)?,
            ]))
        };
        let grains = GrainSet {
            pos: up3(&m.pos)?,
            vel: up3(&m.vel)?,
            omega: up3(&m.omega)?,
            force: up3(&m.force)?,
            torque: up3(&m.torque)?,
            radius: up(&stream, &m.radius)?,
            mass: up(&stream, &m.mass)?,
            inv_mass: up(&stream, &m.inv_mass)?,
            inv_inertia: up(&stream, &m.inv_inertia)?,
            frozen: up(&stream, &m.frozen)?,
            id: up(&stream, &m.id)?,
            origin: up(&stream, &m.origin)?,
            wall_springs: up3(&m.wall_springs)?,
        };
        let zeros3 = |len: usize| -> Result<Dev3> {
            Ok(Dev3([
                zeros(&stream, len)?,
                zeros(&stream, len)?,
                zeros(&stream, len)?,
            ]))
        };
        let scratch = GrainSet {
            pos: zeros3(n)?,
            vel: zeros3(n)?,
            omega: zeros3(n)?,
            force: zeros3(n)?,
            torque: zeros3(n)?,
            radius: zeros(&stream, n)?,
            mass: zeros(&stream, n)?,
            inv_mass: zeros(&stream, n)?,
            inv_inertia: zeros(&stream, n)?,
            frozen: zeros(&stream, n)?,
            id: zeros(&stream, n)?,
            origin: zeros(&stream, n)?,
            wall_springs: zeros3(n * nw)?,
        };
        // The current list goes in buffer builds % 2, the other is empty.
        let cur = (m.builds % 2) as usize;
        let list_of = |which: usize| -> Result<DevList> {
            let cap = m.capacity[which].max(m.list.partner.len());
            let mut l = DevList {
                start: zeros(&stream, n + 1)?,
                partner: zeros(&stream, cap)?,
                image: zeros(&stream, cap)?,
                springs: zeros3(cap)?,
            };
            if which == cur {
                let e = |e| gpu_err("upload", e);
                let total = m.list.partner.len();
                stream.memcpy_htod(&m.list.start, &mut l.start).map_err(e)?;
                if total > 0 {
                    let e = |e| gpu_err("upload", e);
                    stream
                        .memcpy_htod(&m.list.partner, &mut l.partner.slice_mut(..total))
                        .map_err(e)?;
                    stream
                        .memcpy_htod(&m.list.image, &mut l.image.slice_mut(..total))
                        .map_err(e)?;
                    for (d, h) in
                        l.springs
                            .0
                            .iter_mut()
                            .zip([&m.springs.x, &m.springs.y, &m.springs.z])
                    {
                        stream
                            .memcpy_htod(h, &mut d.slice_mut(..total))
                            .map_err(e)?;
                    }
                }
            }
            Ok(l)
        };
        let lists = [list_of(0)?, list_of(1)?];
        let mut host = m;
        host.capacity = [0, 1].map(|w| lists[w].partner.len());
        let p = &host.params;
        let cells = p.sort_grid.ncells().max(p.list_grid.ncells()) + 1;
        let longest = cells.max(n + 1);
        let work = Work {
            cell: zeros(&stream, n)?,
            start: zeros(&stream, cells)?,
            cursor: zeros(&stream, cells)?,
            members: zeros(&stream, n)?,
            order: zeros(&stream, n)?,
            counts: zeros(&stream, n + 1)?,
            places: up(&stream, &p.places)?,
            sums: zeros(&stream, longest.div_ceil(SCAN as usize) + 1)?,
        };
        let mut st0 = [0u64; words::LEN];
        st0[words::BUILDS] = host.builds;
        st0[words::SINCE_SORT] = host.rebuilds_since_sort as u64;
        st0[words::WALLS] = host.stats.contacts;
        st0[words::MAX_FRACTION] = host.stats.max_fraction.to_bits();
        st0[words::STEP] = host.step;
        let st = stream.clone_htod(&st0).map_err(|e| gpu_err("upload", e))?;
        Ok(Self {
            reference: up3(&host.reference)?,
            rank: up(&stream, &host.rank)?,
            rank_before: up(&stream, &host.rank)?,
            grains,
            scratch,
            lists,
            work,
            st,
            graph: None,
            host,
            options,
            stream,
            k,
        })
    }

    /// The state now, on the host (a copy of the device's arrays).
    pub fn host(&self) -> Result<Mirror> {
        let s = &self.stream;
        let e = |e| gpu_err("download", e);
        let down = |d: &CudaSlice<f64>| s.clone_dtoh(d).map_err(e);
        let down3 = |d: &Dev3| -> Result<Soa3> {
            Ok(Soa3 {
                x: down(&d.0[0])?,
                y: down(&d.0[1])?,
                z: down(&d.0[2])?,
            })
        };
        let mut m = self.host.clone();
        m.st = self.read_st()?;
        let g = &self.grains;
        m.pos = down3(&g.pos)?;
        m.vel = down3(&g.vel)?;
        m.omega = down3(&g.omega)?;
        m.force = down3(&g.force)?;
        m.torque = down3(&g.torque)?;
        m.reference = down3(&self.reference)?;
        m.radius = down(&g.radius)?;
        m.mass = down(&g.mass)?;
        m.inv_mass = down(&g.inv_mass)?;
        m.inv_inertia = down(&g.inv_inertia)?;
        m.frozen = s.clone_dtoh(&g.frozen).map_err(e)?;
        m.id = s.clone_dtoh(&g.id).map_err(e)?;
        m.origin = s.clone_dtoh(&g.origin).map_err(e)?;
        m.rank = s.clone_dtoh(&self.rank).map_err(e)?;
        let slots = m.len() * m.params.walls.len();
        m.wall_springs = down3(&g.wall_springs)?;
        for c in [
            &mut m.wall_springs.x,
            &mut m.wall_springs.y,
            &mut m.wall_springs.z,
        ] {
            c.truncate(slots);
        }
        let l = &self.lists[(m.st[words::BUILDS] % 2) as usize];
        m.list.start = s.clone_dtoh(&l.start).map_err(e)?;
        let total = m.list.start[m.len()] as usize;
        m.list.partner = s.clone_dtoh(&l.partner.slice(..total)).map_err(e)?;
        m.list.image = s.clone_dtoh(&l.image.slice(..total)).map_err(e)?;
        let sp = &l.springs.0;
        m.springs = Soa3 {
            x: down(&sp[0])?,
            y: down(&sp[1])?,
            z: down(&sp[2])?,
        };
        for c in [&mut m.springs.x, &mut m.springs.y, &mut m.springs.z] {
            c.truncate(total);
        }
        Ok(m)
    }
}
