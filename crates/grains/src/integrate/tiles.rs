//! What the integrators' passes share: tiles of grains, worked component by
//! component with the widest vectors, frozen grains kept by a selection.

use super::Report;
use crate::dim::{Components, Dim};
use crate::simd::{self, Kernel};

/// Grains per tile: a pass runs its loops one after the other over a tile,
/// which stays in the L1 cache meanwhile, so each grain is read from memory
/// once. A grain has about 600 bytes in the Gear-5 pass (the history,
/// rotation, in 3D), so 32 grains fit a 32 KB L1 cache; tiles of 64 did
/// not, and on the AMD machine (32 KB) they missed it 12 % more often and
/// ran chute's Gear-5 step 2 to 4 % slower (cachegrind, side-by-side runs).
pub(super) const TILE: usize = 32;

/// A tile's components of the largest vector (3D).
pub(super) const TILE_COMPONENTS: usize = 3 * TILE;

/// A per-grain value repeated over the grain's `T::N` components, for the
/// `n` grains of a tile.
#[inline(always)]
pub(super) fn spread<T: Components, X: Copy + Default>(
    n: usize,
    value: impl Fn(usize) -> X,
) -> [X; TILE_COMPONENTS] {
    let mut s = [X::default(); TILE_COMPONENTS];
    for k in 0..n {
        for a in 0..T::N {
            s[k * T::N + a] = value(k);
        }
    }
    s
}

/// The loops' `moving` in a tile without frozen grains. `pick::<false>`
/// ignores it, so it only spares such a tile building a mask (a shared
/// constant, not a copy per tile).
pub(super) static ALL_MOVING: [bool; TILE_COMPONENTS] = [true; TILE_COMPONENTS];

/// Which components move in a tile with frozen grains (`frozen` holds the
/// tile's flags): of the vectors, and of the spins (only with `rotation`;
/// spins are left alone without it).
#[inline(always)]
pub(super) fn moving_masks<D: Dim>(
    frozen: &[bool],
    rotation: bool,
) -> [[bool; TILE_COMPONENTS]; 2] {
    let spins = if rotation { frozen.len() } else { 0 };
    [
        spread::<D::V, bool>(frozen.len(), |k| !frozen[k]),
        spread::<D::A, bool>(spins, |k| !frozen[k]),
    ]
}

/// `new` for a moving grain's component, `old` for a frozen grain's; `new`
/// whatever `moving` says in a tile without frozen grains (`MIXED` false).
///
/// A selection on the bits, not an `if`: the compiler turned the `if` into
/// masked stores (`vmaskmovpd`), which are slow on AMD's cores: without
/// them chute's Gear-5 step took 3 % less time there.
#[inline(always)]
pub(super) fn pick<const MIXED: bool>(moving: bool, new: f64, old: f64) -> f64 {
    if !MIXED {
        return new;
    }
    let keep_new = (moving as u64).wrapping_neg();
    f64::from_bits((new.to_bits() & keep_new) | (old.to_bits() & !keep_new))
}

/// Cuts the first `n` elements off `s` (all when fewer are left).
pub(super) fn cut<'a, T>(s: &mut &'a mut [T], n: usize) -> &'a mut [T] {
    let n = n.min(s.len());
    let (front, back) = std::mem::take(s).split_at_mut(n);
    *s = back;
    front
}

/// A run of consecutive grains' slices, which a pass cuts into tiles.
pub(super) trait Run: Sized {
    fn len(&self) -> usize;
    /// Cuts the first `n` grains (or all that are left) off the run.
    fn split_front(&mut self, n: usize) -> Self;
}

/// An integrator's work on one tile of grains of type `R`, compiled with
/// the selections for frozen grains (`MIXED`) or without; mark the
/// implementation `#[inline(always)]` (see [`Kernel`]).
pub(super) trait TilePass<R: Run> {
    fn tile<const MIXED: bool>(&self, tile: R) -> Report;
}

/// Runs `pass` over `run` tile by tile, with the widest vectors the
/// processor has (`frozen`: the run's grains' flags); the reports are
/// joined in grain order.
pub(super) fn over_tiles<R: Run, P: TilePass<R>>(pass: &P, run: R, frozen: &[bool]) -> Report {
    let mut tiles = OverTiles {
        pass,
        run,
        frozen,
        out: Report::default(),
    };
    simd::run_widest(&mut tiles);
    tiles.out
}

/// [`over_tiles`]'s loop, compiled for each instruction set.
struct OverTiles<'p, R, P> {
    pass: &'p P,
    run: R,
    /// The flags of the grains not yet cut off the run.
    frozen: &'p [bool],
    out: Report,
}

impl<R: Run, P: TilePass<R>> Kernel for OverTiles<'_, R, P> {
    #[inline(always)]
    fn run(&mut self) {
        while self.run.len() > 0 {
            let tile = self.run.split_front(TILE);
            let (frozen, rest) = self.frozen.split_at(tile.len());
            self.frozen = rest;
            // Most tiles have no frozen grain, and skip the selections.
            let r = if frozen.contains(&true) {
                self.pass.tile::<true>(tile)
            } else {
                self.pass.tile::<false>(tile)
            };
            self.out = Report::join(self.out, r);
        }
    }
}
