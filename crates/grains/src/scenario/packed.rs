//! A packed fill (`particles.placement = "packed"`): a region filled to a
//! target packing fraction by growing the grains from a loose random
//! placement while their overlaps are pushed apart.
//!
//! Random placement stalls near a packing of 0.3 (3D); growing radii
//! reaches the random close packing of frictionless spheres, about 0.64 in
//! 3D and 0.84 for disks (O'Hern, Silbert, Liu & Nagel 2003). The count
//! follows from the target: diameters are drawn one by one from the
//! placement's own diameter stream (the random placement's first grains),
//! until their volume is nearest to packing × the region's volume. Those
//! grains are placed at random, shrunk by one common factor to a packing
//! of [`START_3D`] ([`START_2D`]), then grown in steps of [`GROW`] in
//! radius to exactly their drawn diameters; after each step the overlaps
//! are pushed apart, pair by pair in a fixed order (each grain moved in
//! proportion to the other's volume), and the grains held inside the
//! region's faces (periodic axes that the region spans wrap instead).
//!
//! Pushing apart geometrically rather than running the engine's contacts
//! leaves overlaps of [`FINAL_OVERLAP`] of a diameter whatever the
//! material's stiffness (a stiff bead's 1 % overlap, released, flies off at
//! metres per second), needs no friction switched off, and is serial: the
//! same positions on any thread count.

use super::placement;
use super::schema::Placement;
use super::sizes::SizeLaw;
use super::Loaded;
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::particles::SizeBand;

/// The largest packing asked of a 3D (2D) fill: random close packing of
/// frictionless spheres (disks).
pub const LIMIT_3D: f64 = 0.64;
pub const LIMIT_2D: f64 = 0.84;
/// The packing of the random start.
pub const START_3D: f64 = 0.25;
pub const START_2D: f64 = 0.35;
/// Growth of the radii per step.
pub const GROW: f64 = 1.005;
/// Largest overlap, as a fraction of the smaller diameter of the pair,
/// left after each growth step and at the end.
pub const STEP_OVERLAP: f64 = 1e-3;
pub const FINAL_OVERLAP: f64 = 1e-6;
/// Passes over the pairs allowed per growth step and at the end.
const STEP_PASSES: usize = 400;
const FINAL_PASSES: usize = 50_000;

/// The volume (area in 2D) of a grain of diameter `d`.
pub fn grain_volume<D: Dim>(d: f64) -> f64 {
    if D::D == 2 {
        std::f64::consts::PI * d * d / 4.0
    } else {
        std::f64::consts::PI * d * d * d / 6.0
    }
}

/// The packing `packing` checked against the dimension's limit.
pub fn check_packing<D: Dim>(packing: Option<f64>) -> Result<f64> {
    let limit = if D::D == 2 { LIMIT_2D } else { LIMIT_3D };
    let Some(p) = packing else {
        return Err(Error::input(
            "particles.placement = \"packed\" needs particles.packing, the target packing \
             fraction",
        ));
    };
    if !(p.is_finite() && p > 0.0 && p <= limit) {
        return Err(Error::input(format!(
            "particles.packing = {p}: must be in (0, {limit}] in {} (random close packing of \
             frictionless {}, O'Hern et al. 2003)",
            D::NAME,
            if D::D == 2 { "disks" } else { "spheres" }
        )));
    }
    Ok(p)
}

/// The diameters of a fill of `volume` to `packing`: the shortest prefix
/// of the diameter stream (`draw(n)` gives its first n) whose volume is
/// nearest to packing × volume; a count beyond the machine's memory at
/// `bytes_each` a grain is refused.
pub fn diameters<D: Dim>(
    packing: f64,
    volume: f64,
    bytes_each: u64,
    draw: &dyn Fn(usize) -> Result<Vec<f64>>,
) -> Result<Vec<f64>> {
    let target = packing * volume;
    let mut n = 64;
    loop {
        super::memory::check("the packed fill's grain count", n / 2, bytes_each)?;
        let d = draw(n)?;
        let mut sum = 0.0;
        for (k, &x) in d.iter().enumerate() {
            let v = grain_volume::<D>(x);
            if sum + v >= target {
                // k grains or k + 1, whichever comes nearer.
                let keep = if target - sum <= sum + v - target {
                    k
                } else {
                    k + 1
                };
                let mut d = d;
                d.truncate(keep.max(1));
                return Ok(d);
            }
            sum += v;
        }
        n *= 2;
    }
}

/// The region of a fill: its corners, and the axes it wraps around (a
/// periodic axis of the domain that the region spans).
#[derive(Clone, Copy, Debug)]
pub struct FillBox<D: Dim> {
    pub lo: D::V,
    pub hi: D::V,
    pub wraps: [bool; 3],
}

impl<D: Dim> FillBox<D> {
    fn side(&self, a: usize) -> f64 {
        D::get(self.hi, a) - D::get(self.lo, a)
    }

    /// `x` across the wrapped axes taken to its nearest image.
    fn image(&self, mut x: D::V) -> D::V {
        for a in 0..D::D {
            if self.wraps[a] {
                let l = self.side(a);
                let v = D::get(x, a);
                D::set(&mut x, a, v - l * (v / l).round());
            }
        }
        x
    }

    /// Puts grain centre `x` of radius `r` back in the box: wrapped on
    /// the wrapped axes, a radius inside the faces on the others.
    fn hold(&self, x: &mut D::V, r: f64) {
        for a in 0..D::D {
            let (lo, hi) = (D::get(self.lo, a), D::get(self.hi, a));
            let v = D::get(*x, a);
            let v = if self.wraps[a] {
                let l = hi - lo;
                let w = v - l * ((v - lo) / l).floor();
                if w >= hi {
                    lo
                } else {
                    w
                }
            } else {
                v.clamp(lo + r, hi - r)
            };
            D::set(x, a, v);
        }
    }
}

/// The pairs closer than their radii plus `skin`, each once (i < j), by a
/// grid of cells at least as wide as the widest pair's reach.
fn pairs<D: Dim>(b: &FillBox<D>, x: &[D::V], r: &[f64], skin: f64) -> Vec<(u32, u32)> {
    let reach = 2.0 * r.iter().copied().fold(0.0, f64::max) + skin;
    let mut n = [1usize; 3];
    for (a, n) in n.iter_mut().enumerate().take(D::D) {
        *n = ((b.side(a) / reach).floor() as usize).max(1);
    }
    let cell_of = |p: D::V| -> [usize; 3] {
        let mut c = [0usize; 3];
        for a in 0..D::D {
            let f = (D::get(p, a) - D::get(b.lo, a)) / b.side(a);
            c[a] = ((f * n[a] as f64).floor().max(0.0) as usize).min(n[a] - 1);
        }
        c
    };
    let index = |c: [usize; 3]| (c[2] * n[1] + c[1]) * n[0] + c[0];
    let mut start = vec![0usize; n[0] * n[1] * n[2] + 1];
    let cells: Vec<usize> = x.iter().map(|&p| index(cell_of(p))).collect();
    for &c in &cells {
        start[c + 1] += 1;
    }
    for k in 1..start.len() {
        start[k] += start[k - 1];
    }
    let mut fill = start.clone();
    let mut order = vec![0u32; x.len()];
    for (i, &c) in cells.iter().enumerate() {
        order[fill[c]] = i as u32;
        fill[c] += 1;
    }
    // The neighbouring cells along each axis, each once.
    let around = |a: usize, c: usize| -> Vec<usize> {
        let mut v: Vec<usize> = Vec::with_capacity(3);
        for o in [-1i64, 0, 1] {
            let k = c as i64 + o;
            let k = if b.wraps[a] {
                k.rem_euclid(n[a] as i64)
            } else if k < 0 || k >= n[a] as i64 {
                continue;
            } else {
                k
            } as usize;
            if !v.contains(&k) {
                v.push(k);
            }
        }
        v
    };
    let mut out = Vec::new();
    for i in 0..x.len() {
        let c = cell_of(x[i]);
        let zs = if D::D == 3 { around(2, c[2]) } else { vec![0] };
        for &cz in &zs {
            for cy in around(1, c[1]) {
                for cx in around(0, c[0]) {
                    let k = index([cx, cy, cz]);
                    for &j in &order[start[k]..start[k + 1]] {
                        let j = j as usize;
                        if j <= i {
                            continue;
                        }
                        let gap = r[i] + r[j] + skin;
                        if D::norm2(b.image(x[i] - x[j])) < gap * gap {
                            out.push((i as u32, j as u32));
                        }
                    }
                }
            }
        }
    }
    out
}

/// One pass over `pairs`, each overlap pushed apart as it comes (grain i
/// moved by the share w_j = R_j^D / (R_i^D + R_j^D) of the final sizes),
/// then every grain held in the box. Returns the largest overlap met, as a
/// fraction of the pair's smaller diameter.
fn pass<D: Dim>(
    b: &FillBox<D>,
    x: &mut [D::V],
    r: &[f64],
    size: &[f64],
    pairs: &[(u32, u32)],
) -> f64 {
    let mut worst: f64 = 0.0;
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        let dx = b.image(x[i] - x[j]);
        let dist = D::norm(dx);
        let overlap = r[i] + r[j] - dist;
        if overlap <= 0.0 || dist == 0.0 {
            continue;
        }
        worst = worst.max(overlap / (2.0 * r[i].min(r[j])));
        let n = dx * (1.0 / dist);
        let share = size[j] / (size[i] + size[j]);
        x[i] += n * (overlap * share);
        x[j] -= n * (overlap * (1.0 - share));
    }
    for (p, &ri) in x.iter_mut().zip(r) {
        b.hold(p, ri);
    }
    worst
}

/// The largest overlap of `pairs` as they stand, as a fraction of the
/// pair's smaller diameter.
fn largest<D: Dim>(b: &FillBox<D>, x: &[D::V], r: &[f64], pairs: &[(u32, u32)]) -> f64 {
    let mut worst: f64 = 0.0;
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        let overlap = r[i] + r[j] - D::norm(b.image(x[i] - x[j]));
        worst = worst.max(overlap / (2.0 * r[i].min(r[j])));
    }
    worst
}

/// Moves the grains at radii `r` until no pair overlaps by more than
/// `tolerance` of its smaller diameter or `passes` passes are spent;
/// returns the largest overlap of the last pass and the passes spent.
fn relax<D: Dim>(
    b: &FillBox<D>,
    x: &mut [D::V],
    r: &[f64],
    size: &[f64],
    tolerance: f64,
    passes: usize,
) -> (f64, usize) {
    let skin = 0.2 * r.iter().copied().fold(0.0, f64::max);
    let mut list = pairs(b, x, r, skin);
    let mut built: Vec<D::V> = x.to_vec();
    let mut worst = f64::INFINITY;
    for k in 0..passes {
        worst = pass(b, x, r, size, &list);
        // The pass met each pair before later pushes moved it: measured
        // again, still.
        if worst <= tolerance {
            worst = largest(b, x, r, &pairs(b, x, r, skin));
            if worst <= tolerance {
                return (worst, k + 1);
            }
        }
        // A pair may come within reach once a grain has moved half the
        // skin since the list was made.
        let moved = (x.iter().zip(&built))
            .map(|(p, q)| D::norm2(b.image(*p - *q)))
            .fold(0.0, f64::max);
        if 4.0 * moved > skin * skin {
            list = pairs(b, x, r, skin);
            built.copy_from_slice(x);
        }
    }
    (worst, passes)
}

/// Positions for grains of the diameters `d` in the box `b` at their
/// drawn sizes: a random placement (stream of `seed`) at radii shrunk to
/// the start packing, grown back step by step.
pub fn place<D: Dim>(b: &FillBox<D>, d: &[f64], packing: f64, seed: u64) -> Result<Vec<D::V>> {
    let start = if D::D == 2 { START_2D } else { START_3D };
    let mut s = (start / packing).powf(1.0 / D::D as f64).min(1.0);
    let shrunk: Vec<f64> = d.iter().map(|&x| x * s).collect();
    let mut x = placement::random::<D>(b.lo, b.hi, &shrunk, seed)?;
    let size: Vec<f64> = d.iter().map(|&x| x.powi(D::D as i32)).collect();
    let mut r: Vec<f64> = d.iter().map(|&x| 0.5 * x * s).collect();
    while s < 1.0 {
        s = (s * GROW).min(1.0);
        for (ri, &di) in r.iter_mut().zip(d) {
            *ri = 0.5 * di * s;
        }
        relax(b, &mut x, &r, &size, STEP_OVERLAP, STEP_PASSES);
    }
    // Exactly the drawn radii.
    for (ri, &di) in r.iter_mut().zip(d) {
        *ri = 0.5 * di;
    }
    let (worst, spent) = relax(b, &mut x, &r, &size, FINAL_OVERLAP, FINAL_PASSES);
    if worst > FINAL_OVERLAP {
        return Err(Error::input(format!(
            "particles.packing = {packing}: the fill jammed, overlaps of {worst:.1e} of a \
             diameter remain after {spent} passes (at most {FINAL_OVERLAP:e}); lower \
             particles.packing (walls lower the packing a region reaches)"
        )));
    }
    Ok(x)
}

/// The diameters and positions of a scenario's packed fill of the region
/// `lo`–`hi` of the domain `dom`.
pub fn grains<D: Dim>(
    loaded: &Loaded,
    dom: &Domain<D>,
    lo: D::V,
    hi: D::V,
) -> Result<(Vec<f64>, Vec<D::V>)> {
    let s = &loaded.scenario;
    let ps = &s.particles;
    debug_assert_eq!(ps.placement, Placement::Packed);
    let packing = check_packing::<D>(ps.packing)?;
    if ps.count != 0 {
        return Err(Error::input(format!(
            "particles.count = {}: with placement = \"packed\" the count follows from \
             particles.packing and the region; leave particles.count out",
            ps.count
        )));
    }
    let law = match &ps.size {
        Some(spec) => SizeLaw::new(spec, ps.mass_model, &loaded.base_dir)?,
        None => SizeLaw::band(ps.d0, ps.width),
    };
    let mut wraps = [false; 3];
    let mut volume = 1.0;
    for (a, wrap) in wraps.iter_mut().enumerate().take(D::D) {
        let (l, h) = (D::get(lo, a), D::get(hi, a));
        if h - l <= law.max() {
            return Err(Error::input(format!(
                "particles.region is {:e} m along axis {a}, not wider than the largest grain \
                 ({:e} m): enlarge particles.region",
                h - l,
                law.max()
            )));
        }
        volume *= h - l;
        *wrap = dom.periodic[a] && l <= D::get(dom.lo, a) && h >= D::get(dom.hi, a);
    }
    let band = SizeBand {
        d0: ps.d0,
        width: ps.width,
    };
    let bytes = super::memory::md_bytes_per_grain(D::D, s.run.integrator);
    let draw = |n: usize| match &ps.size {
        Some(_) => law.draw(n, s.seed),
        None => Ok(placement::diameters(band, n, s.seed)),
    };
    let d = diameters::<D>(packing, volume, bytes, &draw)?;
    let b = FillBox::<D> { lo, hi, wraps };
    let x = place(&b, &d, packing, s.seed)?;
    Ok((d, x))
}
