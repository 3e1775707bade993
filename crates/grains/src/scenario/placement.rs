//! Initial placement of grains: regular rows from the bottom of a region, or
//! random non-overlapping positions. Random numbers come from a stream derived
//! from (scenario seed, purpose), so a run is reproducible bit for bit.
//! (A DSMC gas is placed by `crate::dsmc::placement`.)

use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::particles::SizeBand;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::HashMap;

/// Purposes of the random streams, mixed into the seed.
pub const STREAM_DIAMETERS: u64 = 1;
pub const STREAM_POSITIONS: u64 = 2;
pub const STREAM_VELOCITIES: u64 = 3;

/// A generator for one purpose of one scenario seed.
pub fn stream(seed: u64, purpose: u64) -> Xoshiro256PlusPlus {
    // SplitMix-style mixing so nearby seeds give unrelated streams.
    let mut z = seed ^ purpose.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Xoshiro256PlusPlus::seed_from_u64(z ^ (z >> 31))
}

/// `count` diameters from the band.
pub fn diameters(band: SizeBand, count: usize, seed: u64) -> Vec<f64> {
    let mut rng = stream(seed, STREAM_DIAMETERS);
    (0..count)
        .map(|_| band.diameter(rng.gen::<f64>()))
        .collect()
}

/// Rows of grains on a square (cubic) lattice of pitch `pitch`, filled
/// from the lower corner of the region along x first (then y in 3D), then up.
pub fn lattice<D: Dim>(lo: D::V, hi: D::V, pitch: f64, count: usize) -> Result<Vec<D::V>> {
    let per_axis: Vec<usize> = (0..D::D)
        .map(|a| ((D::get(hi, a) - D::get(lo, a)) / pitch).floor().max(0.0) as usize)
        .collect();
    let capacity: usize = per_axis.iter().product();
    if capacity < count {
        return Err(Error::input(format!(
            "particles.count = {count} does not fit the placement region on a lattice of pitch {pitch:.3e} m \
             (room for {capacity}); enlarge particles.region or the domain, or lower particles.spacing"
        )));
    }
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let mut rest = k;
        let mut p = D::zero();
        for (a, &along) in per_axis.iter().enumerate() {
            let idx = if a + 1 == D::D { rest } else { rest % along };
            if a + 1 < D::D {
                rest /= along;
            }
            D::set(&mut p, a, D::get(lo, a) + (idx as f64 + 0.5) * pitch);
        }
        out.push(p);
    }
    Ok(out)
}

/// Random non-overlapping positions for grains of the given diameters
/// inside the region (centres at least a radius from its faces).
pub fn random<D: Dim>(lo: D::V, hi: D::V, diameters: &[f64], seed: u64) -> Result<Vec<D::V>> {
    let mut rng = stream(seed, STREAM_POSITIONS);
    let dmax = diameters.iter().copied().fold(0.0, f64::max);
    let cell = dmax.max(1e-300);
    let mut grid: HashMap<Vec<i64>, Vec<usize>> = HashMap::new();
    let mut placed: Vec<(D::V, f64)> = Vec::with_capacity(diameters.len());
    let key = |p: D::V| -> Vec<i64> {
        (0..D::D)
            .map(|a| (D::get(p, a) / cell).floor() as i64)
            .collect()
    };
    for (n, &d) in diameters.iter().enumerate() {
        let r = 0.5 * d;
        let mut ok = None;
        for _attempt in 0..10_000 {
            let mut p = D::zero();
            for a in 0..D::D {
                let (l, h) = (D::get(lo, a) + r, D::get(hi, a) - r);
                if h <= l {
                    return Err(Error::input("particles.region is narrower than a grain"));
                }
                D::set(&mut p, a, rng.gen_range(l..h));
            }
            let k = key(p);
            let mut free = true;
            let offsets = 3usize.pow(D::D as u32);
            'search: for o in 0..offsets {
                let mut kk = k.clone();
                let mut rest = o;
                for c in kk.iter_mut() {
                    *c += (rest % 3) as i64 - 1;
                    rest /= 3;
                }
                if let Some(list) = grid.get(&kk) {
                    for &j in list {
                        let (q, rq) = placed[j];
                        if D::norm(p - q) < r + rq {
                            free = false;
                            break 'search;
                        }
                    }
                }
            }
            if free {
                ok = Some(p);
                break;
            }
        }
        let Some(p) = ok else {
            return Err(Error::input(format!(
                "could not place grain {} of {} at random without overlap; the region is too dense \
                 (random placement reaches about half the dense packing): enlarge particles.region",
                n + 1,
                diameters.len()
            )));
        };
        grid.entry(key(p)).or_default().push(placed.len());
        placed.push((p, r));
    }
    Ok(placed.into_iter().map(|(p, _)| p).collect())
}

/// Random velocities, each component uniform in ±`amplitude`.
pub fn velocities<D: Dim>(count: usize, amplitude: f64, seed: u64) -> Vec<D::V> {
    let mut rng = stream(seed, STREAM_VELOCITIES);
    (0..count)
        .map(|_| {
            let mut v = D::zero();
            if amplitude > 0.0 {
                for a in 0..D::D {
                    D::set(&mut v, a, rng.gen_range(-amplitude..amplitude));
                }
            }
            v
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    #[test]
    fn lattice_fills_rows_from_the_bottom() {
        let p = lattice::<D2>(DVec2::ZERO, DVec2::new(4.0, 10.0), 1.0, 6).unwrap();
        assert_eq!(p[0], DVec2::new(0.5, 0.5));
        assert_eq!(p[3], DVec2::new(3.5, 0.5));
        assert_eq!(p[4], DVec2::new(0.5, 1.5));
        assert!(lattice::<D2>(DVec2::ZERO, DVec2::new(2.0, 2.0), 1.0, 5).is_err());
    }

    #[test]
    fn random_placement_has_no_overlap() {
        let d = diameters(
            SizeBand {
                d0: 1.0,
                width: 0.5,
            },
            300,
            3,
        );
        let p = random::<D3>(DVec3::ZERO, DVec3::splat(12.0), &d, 3).unwrap();
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                assert!((p[i] - p[j]).length() >= 0.5 * (d[i] + d[j]));
            }
        }
        assert_eq!(
            p,
            random::<D3>(DVec3::ZERO, DVec3::splat(12.0), &d, 3).unwrap()
        );
    }
}
