//! What the host hands the CUDA kernels (feature `cuda`): their PTX,
//! checked in and loaded by the driver; their parameter structs, laid out
//! as the structs of `kernels/common.cuh` and the `.cu` files (plain
//! `#[repr(C)]` numbers and device addresses, passed by value); launch
//! shapes and buffers.

use super::grain_kernels::Grid;
use crate::error::{Error, Result};
use cudarc::driver::{CudaContext, CudaSlice, CudaStream, DeviceRepr, LaunchConfig};
use cudarc::nvrtc::Ptx;
use std::sync::Arc;

/// The checked-in PTX, without fused multiply-add (the CPU engine's bits).
pub(super) const PTX: [(&str, &str); 3] = [
    ("integrate", include_str!("kernels/ptx/integrate.ptx")),
    ("list", include_str!("kernels/ptx/list.ptx")),
    ("forces", include_str!("kernels/ptx/forces.ptx")),
];

/// The same kernels with fused multiply-add (`--fmad=true`): faster, the
/// same bits for any launch, not the CPU engine's bits (docs/gpu.md).
pub(super) const PTX_FMA: [(&str, &str); 3] = [
    (
        "integrate.fma",
        include_str!("kernels/ptx/integrate.fma.ptx"),
    ),
    ("list.fma", include_str!("kernels/ptx/list.fma.ptx")),
    ("forces.fma", include_str!("kernels/ptx/forces.fma.ptx")),
];

/// Loads one PTX file. NVRTC 13.5 writes PTX ISA 9.5, which a driver older
/// than CUDA 13.5 refuses; the kernels use nothing newer than ISA 8.0
/// (CUDA 12.0), so on refusal the file is loaded again with its `.version`
/// lowered to what the driver reads (8.0 for 12.x, 9.0 for 13.x), with a
/// note on stderr.
pub(super) fn load_ptx(
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

pub(super) fn gpu_err(what: &str, e: impl std::fmt::Debug) -> Error {
    Error::input(format!("GPU engine: {what}: {e:?}"))
}

/// Walls a force launch carries (MAX_WALLS in common.cuh).
pub const MAX_WALLS: usize = 8;

#[repr(C)]
#[derive(Clone, Copy, Default)]
pub(super) struct Soa3P {
    pub(super) x: u64,
    pub(super) y: u64,
    pub(super) z: u64,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub(super) struct GrainsP {
    pub(super) pos: Soa3P,
    pub(super) vel: Soa3P,
    pub(super) omega: Soa3P,
    pub(super) force: Soa3P,
    pub(super) torque: Soa3P,
    pub(super) reference: Soa3P,
    pub(super) radius: u64,
    pub(super) mass: u64,
    pub(super) inv_mass: u64,
    pub(super) inv_inertia: u64,
    pub(super) frozen: u64,
    pub(super) rank: u64,
    pub(super) n: u32,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub(super) struct ListP {
    pub(super) start: u64,
    pub(super) partner: u64,
    pub(super) image: u64,
    pub(super) springs: Soa3P,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub(super) struct ListsP {
    pub(super) l: [ListP; 2],
    pub(super) cap: [u64; 2],
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub(super) struct ExtraP {
    pub(super) id: u64,
    pub(super) origin: u64,
    pub(super) wall_springs: Soa3P,
}
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub(super) struct PlaneP {
    pub(super) point: [f64; 3],
    pub(super) normal: [f64; 3],
    pub(super) gamma_n: f64,
}
#[repr(C)]
#[derive(Clone, Copy)]
pub(super) struct ForceArgsP {
    /// The run's law as the CPU engine's kernel holds it (`#[repr(C)]`).
    pub(super) law: super::grain_kernels::Hooke,
    pub(super) shifts: [[f64; 3]; 27],
    pub(super) walls: [PlaneP; MAX_WALLS],
    pub(super) n_walls: u32,
    pub(super) gravity: [f64; 3],
    pub(super) dt: f64,
    pub(super) update: u32,
}
#[repr(C)]
#[derive(Clone, Copy)]
pub(super) struct Box3P {
    pub(super) lo: [f64; 3],
    pub(super) length: [f64; 3],
    pub(super) periodic: [u32; 3],
}
#[repr(C)]
#[derive(Clone, Copy)]
pub(super) struct GridP {
    pub(super) dims: [u64; 3],
    pub(super) lo: [f64; 3],
    pub(super) inv_width: [f64; 3],
}
#[repr(C)]
#[derive(Clone, Copy)]
pub(super) struct ListArgsP {
    pub(super) grid: GridP,
    pub(super) start_cells: u64,
    pub(super) members: u64,
    pub(super) cell: u64,
    pub(super) length: [f64; 3],
    pub(super) shifts: [[f64; 3]; 27],
    pub(super) skin: f64,
    pub(super) periodic: [u32; 3],
    pub(super) block: u32,
}

// SAFETY: plain #[repr(C)] data (numbers and device addresses), laid out
// as the kernels' parameter structs.
unsafe impl DeviceRepr for Soa3P {}
unsafe impl DeviceRepr for GrainsP {}
unsafe impl DeviceRepr for ListP {}
unsafe impl DeviceRepr for ListsP {}
unsafe impl DeviceRepr for ExtraP {}
unsafe impl DeviceRepr for ForceArgsP {}
unsafe impl DeviceRepr for Box3P {}
unsafe impl DeviceRepr for GridP {}
unsafe impl DeviceRepr for ListArgsP {}

pub(super) fn grid_p(g: &Grid) -> GridP {
    GridP {
        dims: g.dims.map(|d| d as u64),
        lo: g.lo,
        inv_width: g.inv_width,
    }
}

pub(super) fn cfg(n: usize, threads: u32) -> LaunchConfig {
    LaunchConfig {
        grid_dim: ((n as u32).div_ceil(threads).max(1), 1, 1),
        block_dim: (threads, 1, 1),
        shared_mem_bytes: 0,
    }
}

/// One thread.
pub(super) const ONE: LaunchConfig = LaunchConfig {
    grid_dim: (1, 1, 1),
    block_dim: (1, 1, 1),
    shared_mem_bytes: 0,
};

/// A host array on the device (an empty one as one zero: no buffer is
/// allocated empty).
pub(super) fn up<T: DeviceRepr + Default + Copy>(
    s: &Arc<CudaStream>,
    v: &[T],
) -> Result<CudaSlice<T>> {
    let pad = [T::default()];
    let v = if v.is_empty() { &pad[..] } else { v };
    s.clone_htod(v).map_err(|e| gpu_err("upload", e))
}

/// `len` zeros on the device (at least one).
pub(super) fn zeros<T: DeviceRepr + cudarc::driver::ValidAsZeroBits>(
    s: &Arc<CudaStream>,
    len: usize,
) -> Result<CudaSlice<T>> {
    s.alloc_zeros::<T>(len.max(1))
        .map_err(|e| gpu_err("alloc", e))
}
