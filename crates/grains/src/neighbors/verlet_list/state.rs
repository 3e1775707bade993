//! A neighbour list's checkpoint state, exported and imported back.
//!
//! What the list carries from one step to the next; an import checks every
//! index and code.

use super::{NeighborList, POW3};
use crate::dim::Dim;
use crate::error::{Error, Result};

/// Everything a neighbour list carries from one step to the next (its cell
/// grid is scratch). Restoring it brings back the exact pair order, image
/// codes and skin reference positions, so forces are summed in the same
/// order as in an uninterrupted run.
#[derive(Clone, Debug, PartialEq)]
pub struct ListState<D: Dim> {
    pub pairs: Vec<[u32; 2]>,
    pub image: Vec<u8>,
    /// The 27 image shifts of the last build.
    pub shifts: Vec<D::V>,
    pub ref_pos: Vec<D::V>,
    pub builds: u64,
    pub built: bool,
    /// A sheared box's image offsets (whole lengths taken off, at the last
    /// build, now); `None` unsheared.
    pub shear: Option<[f64; 3]>,
}

impl<D: Dim> NeighborList<D> {
    /// The list's state for a checkpoint (the cell grid is scratch and not
    /// part of it).
    pub fn export_state(&self) -> ListState<D> {
        ListState {
            pairs: self.pairs.clone(),
            image: self.image.clone(),
            shifts: self.shifts.to_vec(),
            ref_pos: self.ref_pos.clone(),
            builds: self.builds,
            built: self.built,
            shear: self.shear_offsets(),
        }
    }

    /// Replaces the list by a saved state for `n` particles. Checks that
    /// every index, image code and length is consistent (a state from a
    /// damaged file is refused, never trusted); the list is unchanged on error.
    pub fn import_state(&mut self, s: ListState<D>, n: usize) -> Result<()> {
        let codes = POW3[D::D - 1] as usize * 3;
        if s.image.len() != s.pairs.len() {
            return Err(Error::input(format!(
                "neighbour list: {} pairs but {} image codes",
                s.pairs.len(),
                s.image.len()
            )));
        }
        if s.shifts.len() != 27 {
            return Err(Error::input(format!(
                "neighbour list: {} image shifts instead of 27",
                s.shifts.len()
            )));
        }
        if s.built && s.ref_pos.len() != n {
            return Err(Error::input(format!(
                "neighbour list: {} reference positions for {n} particles",
                s.ref_pos.len()
            )));
        }
        if let Some(p) = s
            .pairs
            .iter()
            .find(|p| p[0] as usize >= n || p[1] as usize >= n || p[0] == p[1])
        {
            return Err(Error::input(format!(
                "neighbour list: pair {:?} is not a pair of distinct grains among {n}",
                p
            )));
        }
        if let Some(c) = s.image.iter().find(|&&c| c as usize >= codes) {
            return Err(Error::input(format!(
                "neighbour list: image code {c} out of range (fewer than {codes} in {})",
                D::NAME
            )));
        }
        self.restore_offsets(s.shear)?;
        self.pairs = s.pairs;
        self.image = s.image;
        self.shifts.copy_from_slice(&s.shifts);
        self.ref_pos = s.ref_pos;
        self.builds = s.builds;
        self.built = s.built;
        Ok(())
    }
}
