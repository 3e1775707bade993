//! The CUDA kernels' parameter structs (feature `cuda`), laid out as the
//! structs of `kernels/common.cuh` and the `.cu` files: plain `#[repr(C)]`
//! numbers and device addresses, passed by value to each launch.

use super::grain_kernels::Grid;
use cudarc::driver::DeviceRepr;

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
#[derive(Clone, Copy)]
pub(super) struct HookeP {
    pub(super) kn: f64,
    pub(super) gamma_n: f64,
    pub(super) gamma_t: f64,
    pub(super) kt: f64,
    pub(super) mu: f64,
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
    pub(super) law: HookeP,
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
