//! Collisions inside one cell (seed 000 §4, PHYSICS.md §2, steps 3–5).
//!
//! M_c = N_c (N_c − 1) σ v_max τ / (2 Ṽ_c) candidate pairs, the fractional
//! part carried to the next step in the cell; a candidate (i, j) collides
//! when Z v_max < |v_i − v_j|, Z uniform in [0, 1); v_max is raised to any
//! larger relative speed met. The impact parameter b is uniform in
//! [−2R, 2R] (2D) or in the disk of radius 2R (3D); it fixes the normal n
//! at contact, whose component of the relative velocity is reversed and
//! scaled by e while the tangential part is kept.
//!
//! With ĝ = g/|g| and b = 2R s (s the impact parameter over 2R, a scalar in
//! 2D, a vector ⊥ ĝ in 3D), n = √(1 − s²) ĝ + s, and g·n = |g| √(1 − s²).
//! Each particle's velocity changes by ∓(1 + e)/2 (g·n) n, equal masses.

use super::dense::Correction;
use super::rng::Stream;
use super::store::Particle;
use crate::dim::{Dim, D2, D3};
use glam::{DVec2, DVec3};

/// The dimension-specific part of a binary collision.
pub trait GasDim: Dim {
    /// The momentum transfer (g·n) n of a collision with relative velocity
    /// `g` (|g|² = `g2`) at an impact parameter drawn from `rng`; particle i
    /// gets −(1+e)/2 times it, particle j +(1+e)/2 times it.
    fn transfer(g: Self::V, g2: f64, rng: &mut Stream) -> Self::V;

    /// Draws an impact parameter over 2R: in 2D (s, 0) with s uniform in
    /// [−1, 1); in 3D a point uniform in the unit disk.
    #[inline(always)]
    fn impact(rng: &mut Stream) -> [f64; 2] {
        if Self::D == 2 {
            [rng.symmetric(), 0.0]
        } else {
            loop {
                let (x, y) = (rng.symmetric(), rng.symmetric());
                if x * x + y * y < 1.0 {
                    return [x, y];
                }
            }
        }
    }
}

impl GasDim for D2 {
    #[inline(always)]
    fn transfer(g: DVec2, _g2: f64, rng: &mut Stream) -> DVec2 {
        let [s, _] = Self::impact(rng);
        let c2 = 1.0 - s * s;
        let c = c2.sqrt();
        // |g| c (c ĝ + s t̂) with t̂ = ĝ rotated by +90°.
        let cs = c * s;
        DVec2::new(c2 * g.x - cs * g.y, c2 * g.y + cs * g.x)
    }
}

impl GasDim for D3 {
    #[inline(always)]
    fn transfer(g: DVec3, g2: f64, rng: &mut Stream) -> DVec3 {
        let [x, y] = Self::impact(rng);
        let c2 = 1.0 - x * x - y * y;
        let c = c2.sqrt();
        let gn = g2.sqrt();
        let u = g / gn;
        // Orthonormal basis (e1, e2) of the plane ⊥ u (Duff et al. 2017).
        let sign = 1.0f64.copysign(u.z);
        let a = -1.0 / (sign + u.z);
        let b = u.x * u.y * a;
        let e1 = DVec3::new(1.0 + sign * u.x * u.x * a, sign * b, -sign * u.x);
        let e2 = DVec3::new(b, sign + u.y * u.y * a, -u.y);
        g * c2 + (e1 * x + e2 * y) * (c * gn)
    }
}

/// Per-cell state carried from step to step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellState {
    /// Upper bound of the relative speed in the cell (m/s).
    pub vmax: f64,
    /// Fractional candidate count carried over.
    pub remainder: f32,
    /// Collisions since the diagnostics last read them.
    pub collisions: u32,
}

/// What every cell's selection needs.
#[derive(Clone, Copy, Debug)]
pub struct Selection {
    /// σ τ / (2 V_c): M_c = N_c (N_c − 1) v_max χ_c · this.
    pub rate: f64,
    /// (1 + e)/2.
    pub half_one_plus_e: f64,
    pub correction: Correction,
}

/// Candidates and collisions of one cell in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub candidates: u64,
    pub collisions: u64,
}

impl std::ops::AddAssign for Tally {
    fn add_assign(&mut self, o: Self) {
        self.candidates += o.candidates;
        self.collisions += o.collisions;
    }
}

/// Collides particles i and j of relative velocity `g` = v_i − v_j
/// (|g|² = `g2`) with restitution e given as (1 + e)/2; returns the change of
/// v_j (v_i changes by its opposite).
#[inline(always)]
pub fn collide_pair<D: GasDim>(
    vi: &mut D::V,
    vj: &mut D::V,
    g2: f64,
    half_one_plus_e: f64,
    rng: &mut Stream,
) -> D::V {
    let g = *vi - *vj;
    let dv = D::transfer(g, g2, rng) * half_one_plus_e;
    *vi -= dv;
    *vj += dv;
    dv
}

/// Performs the collisions of one cell, whose particles are
/// `base[idx[k]]`.
///
/// # Safety
/// `base` must point to a live array that every entry of `idx` indexes,
/// the entries of `idx` must be distinct, and no other thread may touch
/// those particles during the call.
#[inline]
pub unsafe fn collide_cell<D: GasDim>(
    base: *mut Particle<D>,
    idx: &[u32],
    st: &mut CellState,
    sel: &Selection,
    rng: &mut Stream,
) -> Tally {
    let n = idx.len();
    if n < 2 {
        return Tally::default();
    }
    let nf = n as f64;
    let expected =
        nf * (nf - 1.0) * st.vmax * sel.rate * sel.correction.factor(n) + st.remainder as f64;
    let m = expected.floor();
    st.remainder = (expected - m) as f32;
    let m = m as u64;
    let mut vmax = st.vmax;
    let mut vmax2 = vmax * vmax;
    let mut hits = 0u64;
    let nu = n as u32;
    for _ in 0..m {
        let (i, j) = rng.pair_below(nu);
        let (i, j) = (i as usize, j as usize);
        // SAFETY: distinct entries of `idx` (i ≠ j) into the live array,
        // owned by this call (the caller's contract).
        let pi = unsafe { &mut *base.add(*idx.get_unchecked(i) as usize) };
        let pj = unsafe { &mut *base.add(*idx.get_unchecked(j) as usize) };
        let g = pi.v - pj.v;
        let g2 = D::norm2(g);
        if g2 > vmax2 {
            vmax2 = g2;
            vmax = g2.sqrt();
        }
        // Z v_max < |g| without a square root: both sides are positive.
        let z = rng.uniform() * vmax;
        if z * z < g2 {
            collide_pair::<D>(&mut pi.v, &mut pj.v, g2, sel.half_one_plus_e, rng);
            hits += 1;
        }
    }
    st.vmax = vmax;
    st.collisions = st.collisions.saturating_add(hits as u32);
    Tally {
        candidates: m,
        collisions: hits,
    }
}
