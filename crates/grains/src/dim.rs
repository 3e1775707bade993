//! The dimension of space as a type: `D2` (disks in a plane) and `D3` (spheres).
//!
//! Physics code is generic over [`Dim`]; both dimensions are compiled into one
//! binary and the scenario file picks one at run time. The vertical axis is the
//! last one (y in 2D, z in 3D), as in LAMMPS's 2D convention.

use glam::{DVec2, DVec3};
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Arithmetic shared by position-like vectors and angular quantities.
pub trait Linear:
    Copy
    + Debug
    + Default
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign<f64>
    + Components
{
}

impl Linear for f64 {}
impl Linear for DVec2 {}
impl Linear for DVec3 {}

/// A value made of `N` consecutive `f64` and nothing else, so that a slice
/// of them can be read as a slice of numbers (loops over components
/// vectorize where loops over vectors do not). `bytemuck` checks the
/// layout: glam's `DVec2` and `DVec3` are plain-old-data `repr(C)` structs.
pub trait Components: bytemuck::Pod {
    const N: usize;
}

impl Components for f64 {
    const N: usize = 1;
}
impl Components for DVec2 {
    const N: usize = 2;
}
impl Components for DVec3 {
    const N: usize = 3;
}
const _: () =
    assert!(std::mem::size_of::<DVec2>() == 2 * 8 && std::mem::size_of::<DVec3>() == 3 * 8);

/// The components of `s`, in order.
#[inline(always)]
pub fn components<T: Components>(s: &[T]) -> &[f64] {
    bytemuck::cast_slice(s)
}

/// The components of `s`, in order, writable.
#[inline(always)]
pub fn components_mut<T: Components>(s: &mut [T]) -> &mut [f64] {
    bytemuck::cast_slice_mut(s)
}

/// A dimension of space.
pub trait Dim: Copy + Clone + Debug + Default + Send + Sync + 'static {
    /// Number of spatial axes.
    const D: usize;
    /// "2d" or "3d", as written in scenario files.
    const NAME: &'static str;
    /// Positions, velocities, forces.
    type V: Linear;
    /// Angular velocity and torque: a scalar spin in 2D, a vector in 3D.
    type A: Linear;

    fn dot(a: Self::V, b: Self::V) -> f64;
    fn get(v: Self::V, axis: usize) -> f64;
    fn set(v: &mut Self::V, axis: usize, value: f64);
    /// Angular velocity `w` crossed with a lever arm `r`: the velocity it induces.
    fn ang_cross(w: Self::A, r: Self::V) -> Self::V;
    /// Torque of force `f` applied at lever arm `r` (r × f).
    fn torque(r: Self::V, f: Self::V) -> Self::A;
    fn ang_dot(a: Self::A, b: Self::A) -> f64;
    /// Embeds a vector in 3D (z = 0 in 2D) for output.
    fn to_xyz(v: Self::V) -> [f64; 3];
    /// Embeds an angular quantity in 3D (spin about z in 2D) for output.
    fn ang_to_xyz(a: Self::A) -> [f64; 3];
    /// Reads the first `D` components of a 3-vector.
    fn from_xyz(x: [f64; 3]) -> Self::V;
    /// Reads an angular quantity from 3 components (z component in 2D).
    fn ang_from_xyz(x: [f64; 3]) -> Self::A;

    fn zero() -> Self::V {
        Self::V::default()
    }
    fn norm2(v: Self::V) -> f64 {
        Self::dot(v, v)
    }
    fn norm(v: Self::V) -> f64 {
        Self::dot(v, v).sqrt()
    }
    /// The unit vector along `axis`.
    fn unit(axis: usize) -> Self::V {
        let mut v = Self::zero();
        Self::set(&mut v, axis, 1.0);
        v
    }
    /// Index of the vertical axis (the last one).
    fn vertical() -> usize {
        Self::D - 1
    }
    fn is_finite(v: Self::V) -> bool {
        (0..Self::D).all(|a| Self::get(v, a).is_finite())
    }
}

/// Two dimensions: disks in the x–y plane, y vertical.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct D2;

/// Three dimensions: spheres, z vertical.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct D3;

impl Dim for D2 {
    const D: usize = 2;
    const NAME: &'static str = "2d";
    type V = DVec2;
    type A = f64;

    #[inline(always)]
    fn dot(a: DVec2, b: DVec2) -> f64 {
        a.dot(b)
    }
    #[inline(always)]
    fn get(v: DVec2, axis: usize) -> f64 {
        v[axis]
    }
    #[inline(always)]
    fn set(v: &mut DVec2, axis: usize, value: f64) {
        v[axis] = value;
    }
    #[inline(always)]
    fn ang_cross(w: f64, r: DVec2) -> DVec2 {
        DVec2::new(-w * r.y, w * r.x)
    }
    #[inline(always)]
    fn torque(r: DVec2, f: DVec2) -> f64 {
        r.x * f.y - r.y * f.x
    }
    #[inline(always)]
    fn ang_dot(a: f64, b: f64) -> f64 {
        a * b
    }
    fn to_xyz(v: DVec2) -> [f64; 3] {
        [v.x, v.y, 0.0]
    }
    fn ang_to_xyz(a: f64) -> [f64; 3] {
        [0.0, 0.0, a]
    }
    fn from_xyz(x: [f64; 3]) -> DVec2 {
        DVec2::new(x[0], x[1])
    }
    fn ang_from_xyz(x: [f64; 3]) -> f64 {
        x[2]
    }
}

impl Dim for D3 {
    const D: usize = 3;
    const NAME: &'static str = "3d";
    type V = DVec3;
    type A = DVec3;

    #[inline(always)]
    fn dot(a: DVec3, b: DVec3) -> f64 {
        a.dot(b)
    }
    #[inline(always)]
    fn get(v: DVec3, axis: usize) -> f64 {
        v[axis]
    }
    #[inline(always)]
    fn set(v: &mut DVec3, axis: usize, value: f64) {
        v[axis] = value;
    }
    #[inline(always)]
    fn ang_cross(w: DVec3, r: DVec3) -> DVec3 {
        w.cross(r)
    }
    #[inline(always)]
    fn torque(r: DVec3, f: DVec3) -> DVec3 {
        r.cross(f)
    }
    #[inline(always)]
    fn ang_dot(a: DVec3, b: DVec3) -> f64 {
        a.dot(b)
    }
    fn to_xyz(v: DVec3) -> [f64; 3] {
        v.to_array()
    }
    fn ang_to_xyz(a: DVec3) -> [f64; 3] {
        a.to_array()
    }
    fn from_xyz(x: [f64; 3]) -> DVec3 {
        DVec3::from_array(x)
    }
    fn ang_from_xyz(x: [f64; 3]) -> DVec3 {
        DVec3::from_array(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spin_cross_matches_3d_cross_about_z() {
        let r = DVec2::new(0.3, -1.2);
        let w = 2.5;
        let v2 = D2::ang_cross(w, r);
        let v3 = D3::ang_cross(DVec3::new(0.0, 0.0, w), DVec3::new(r.x, r.y, 0.0));
        assert_eq!([v2.x, v2.y], [v3.x, v3.y]);
        let f = DVec2::new(-0.7, 0.4);
        let t3 = D3::torque(DVec3::new(r.x, r.y, 0.0), DVec3::new(f.x, f.y, 0.0));
        assert_eq!(D2::torque(r, f), t3.z);
    }
}
