//! Rigid clumps in the MD engine: bodies whose sub-spheres are grains.

use super::Md;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::rigid::{BodySpec, Shape};

impl<D: Dim> Md<D> {
    /// Adds rigid clumps of the given shapes to the engine.
    pub fn add_bodies(&mut self, shapes: Vec<Shape<D>>, bodies: Vec<BodySpec<D>>) -> Result<()> {
        let _ = (shapes, bodies);
        Err(Error::input(
            "[[shapes]]: rigid clumps are not supported by this build",
        ))
    }
}
