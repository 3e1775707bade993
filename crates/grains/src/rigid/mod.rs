//! Rigid clumps of spheres (disks in 2D): what a body is made of and how it
//! is placed, the interface between the scenario that builds bodies and the
//! engine that moves them.
//!
//! A clump is a rigid union of sub-spheres. Its shape is given in its
//! principal frame: the centre of mass at the origin and the axes along the
//! principal axes of inertia, so that the inertia tensor is diagonal there.
//! The engine keeps each sub-sphere as a grain of its store (so neighbour
//! search, walls, meshes and outputs see spheres) tied to its body.

use crate::dim::Dim;

pub mod bodies;
pub mod no_squish;

/// One sphere of a clump, in the clump's principal frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubSphere<D: Dim> {
    /// Centre relative to the clump's centre of mass, along its principal axes (m).
    pub center: D::V,
    /// Radius (m).
    pub radius: f64,
}

/// A clump's shape with its mass properties, ready for the engine.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape<D: Dim> {
    /// The name of its `[[shapes]]` entry.
    pub name: String,
    /// The sub-spheres in the principal frame.
    pub spheres: Vec<SubSphere<D>>,
    /// Mass of the union of the sub-spheres, overlaps counted once (kg).
    pub mass: f64,
    /// Principal moments of inertia about the centre of mass (kg m²),
    /// about the body's x, y and z axes; in 2D only the z moment is used.
    pub inertia: [f64; 3],
}

/// One clump to be made: its shape, placement and motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodySpec<D: Dim> {
    /// Index into the run's shapes.
    pub shape: usize,
    /// Kind (material) of all its sub-spheres.
    pub kind: u32,
    /// Position of its centre of mass (m).
    pub pos: D::V,
    /// Unit quaternion (w, x, y, z) turning the body frame into the space
    /// frame; in 2D a rotation about z.
    pub orientation: [f64; 4],
    /// Velocity of its centre of mass (m/s).
    pub vel: D::V,
    /// Angular velocity in the space frame (rad/s).
    pub omega: D::A,
}

pub mod mass;
pub mod shape;
