//! Lees–Edwards images in the neighbour list: the offset of the sliding
//! images, the shifts and velocity jumps of their image codes, and the
//! skin left for the grains while the offset moves.
//!
//! The images across the gradient axis slide along the shear axis between
//! builds. A listed pair through that boundary then approaches by up to
//! the two grains' displacements plus the offset's change δΔ since the
//! build, so the list stays complete while every grain has moved less than
//! (skin − |δΔ|)/2: the displacement test's limit shrinks as the offset
//! moves, and a rebuild is due once |δΔ| reaches the skin. This costs no
//! wider search, and a pair list that grows no longer than unsheared.

use super::{NeighborList, POW3};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};

/// The sliding images of a sheared box as the list holds them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ListShear {
    pub axis: usize,
    pub gradient: usize,
    /// Velocity jump γ̇ L_g of the image above the box.
    pub jump: f64,
    /// Box length along the shear axis.
    pub length: f64,
    /// Whole shear lengths taken off the offset at the last build.
    pub turns: f64,
    /// The image offset at the last build and at the latest time set.
    pub built: f64,
    pub now: f64,
    /// The box's slide origin (t_0, Δ_0) ([`Domain::slide_origin`]).
    pub origin: [f64; 2],
}

/// The digit (−1, 0, +1) of image `code` on `axis`.
fn digit(code: usize, axis: usize) -> f64 {
    ((code / POW3[axis] as usize) % 3) as f64 - 1.0
}

impl ListShear {
    /// The shear of `domain` at time `t`, checked against what the cell
    /// search needs: the shear axis is x and the gradient axis is long
    /// enough for three cells of the pair reach.
    pub(super) fn at<D: Dim>(domain: &Domain<D>, t: f64, reach: f64) -> Result<Option<Self>> {
        let Some(s) = domain.shear else {
            return Ok(None);
        };
        if s.axis != 0 || s.gradient == 0 || s.gradient >= D::D {
            return Err(Error::input(format!(
                "sheared box: the shear axis must be x and the gradient axis another \
                 axis of the {} box (got axes {} and {})",
                D::NAME,
                s.axis,
                s.gradient
            )));
        }
        if !(domain.is_periodic(s.axis) && domain.is_periodic(s.gradient)) {
            return Err(Error::input(
                "sheared box: the shear and gradient axes must both be periodic",
            ));
        }
        let lg = domain.length(s.gradient);
        if lg < 3.0 * reach {
            return Err(Error::input(format!(
                "sheared box: its length {lg} along the gradient axis is below \
                 3 × (largest diameter + neighbour skin) = {}: the sliding images \
                 need three cells across; enlarge the box",
                3.0 * reach
            )));
        }
        let (turns, offset) = domain.shear_offset(t);
        Ok(Some(Self {
            axis: s.axis,
            gradient: s.gradient,
            jump: domain.shear_jump(),
            length: domain.length(s.axis),
            turns,
            built: offset,
            now: offset,
            origin: domain.slide_origin,
        }))
    }

    /// The squared displacement beyond which a grain calls for a rebuild,
    /// with the skin the offset's move since the build leaves; `None` when
    /// it left none.
    pub(super) fn limit2(&self, skin: f64) -> Option<f64> {
        let half = 0.5 * (skin - (self.now - self.built).abs());
        (half > 0.0).then_some(half * half)
    }
}

impl<D: Dim> NeighborList<D> {
    /// Sets the shifts of the sliding images for the offset `shear.now`:
    /// along the shear axis, the box lengths of the code's digit plus the
    /// offset times its gradient digit.
    pub(super) fn slide_images(&mut self) {
        let Some(s) = self.shear else {
            return;
        };
        for (code, shift) in self.shifts.iter_mut().enumerate() {
            let x = digit(code, s.axis) * s.length + digit(code, s.gradient) * s.now;
            D::set(shift, s.axis, x);
        }
    }

    /// Moves the sliding images to time `t` (nothing unsheared): call it
    /// before the grains' displacement test of the step that ends at `t`.
    pub fn set_time(&mut self, t: f64) {
        if let Some(s) = &mut self.shear {
            let [since, base] = s.origin;
            // With the origin (0, 0), γ̇ L_g t − turns L_s to the bit.
            s.now = base + s.jump * (t - since) - s.turns * s.length;
            self.slide_images();
        }
    }

    /// Takes the jump and slide origin of `domain`, whose gradient length
    /// a checkpoint restored after the list (its shifts came with it).
    pub fn follow_box(&mut self, domain: &Domain<D>) {
        if let Some(s) = &mut self.shear {
            s.jump = domain.shear_jump();
            s.origin = domain.slide_origin;
        }
        self.set_velocity_shifts();
    }

    /// Whether the list was built for a sheared box.
    pub fn sheared(&self) -> bool {
        self.shear.is_some()
    }

    /// The velocity to add to the partner's for image `code`: the jump
    /// times the code's gradient digit, along the shear axis (zero
    /// unsheared).
    #[inline]
    pub fn velocity_shift(&self, code: u8) -> D::V {
        self.vshifts[code as usize]
    }

    /// The velocity shifts of every code, for the shear of the last build.
    pub(super) fn set_velocity_shifts(&mut self) {
        for (code, v) in self.vshifts.iter_mut().enumerate() {
            *v = D::zero();
            if let Some(s) = self.shear {
                D::set(v, s.axis, digit(code, s.gradient) * s.jump);
            }
        }
    }

    /// The sliding images' offsets (whole lengths taken off, at the build,
    /// now) for a checkpoint; `None` unsheared.
    pub fn shear_offsets(&self) -> Option<[f64; 3]> {
        self.shear.map(|s| [s.turns, s.built, s.now])
    }

    /// Puts back offsets saved by [`NeighborList::shear_offsets`]; a saved
    /// state of a sheared list needs a list built sheared, and conversely.
    pub(super) fn restore_offsets(&mut self, saved: Option<[f64; 3]>) -> Result<()> {
        match (&mut self.shear, saved) {
            (None, None) => Ok(()),
            (Some(s), Some([turns, built, now])) => {
                s.turns = turns;
                s.built = built;
                s.now = now;
                Ok(())
            }
            (s, _) => Err(Error::input(format!(
                "neighbour list: the saved state is {}sheared but the box is {}sheared",
                if s.is_some() { "not " } else { "" },
                if s.is_some() { "" } else { "not " }
            ))),
        }
    }
}
