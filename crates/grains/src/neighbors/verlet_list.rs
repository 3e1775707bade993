//! Verlet neighbour list with a skin, built from a cell grid.
//!
//! The list holds every pair closer than `r_i + r_j + skin`, so it stays valid
//! (no contact can be missing) until some grain has moved more than `skin / 2`
//! since the build: two grains then approach by at most `skin`. Between builds
//! the force loop reads the list instead of searching space every step.
//!
//! Periodic images are not copied as ghost particles: each pair carries an
//! image code saying which box-length shift to add to the partner's position.
//! Positions are wrapped only at builds, so the code stays valid while grains
//! drift out of the box between builds.

mod scan;
mod shear;
mod state;

pub use state::ListState;

use super::cell_grid::{CellGrid, GridShape};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use rayon::prelude::*;
use scan::{Scan, ScanShear};
use shear::ListShear;

/// Particles per work unit of a parallel build. Fixed, not derived from the
/// thread count, so the list comes out the same on any number of threads.
const CHUNK: usize = 2048;

/// Bounds on the number of grid cells (per particle, and in all): cells beyond
/// these cost memory and clearing time without finding pairs faster.
const CELLS_PER_PARTICLE: usize = 16;
const MIN_CELLS: usize = 4096;
const MAX_CELLS: usize = 1 << 24;

/// Powers of three: the weight of each axis's digit in an image code.
const POW3: [i32; 3] = [1, 3, 9];

/// A half neighbour list (each unordered pair once) with periodic image codes.
#[derive(Clone, Debug)]
pub struct NeighborList<D: Dim> {
    /// Half list: each unordered pair once, grouped by first index ascending
    /// (this implementation stores `[i, j]` with `i < j`).
    pub pairs: Vec<[u32; 2]>,
    /// Per pair: periodic image code; the partner's position to use is
    /// `pos[j] + list.shift(code)`. Per axis a digit 0/1/2 means −1/0/+1 box
    /// lengths; the code is the base-3 number of those digits, x least
    /// significant (9 codes in 2D, 27 in 3D).
    pub image: Vec<u8>,
    /// Shift vector of each image code, for the domain of the last build
    /// (in a sheared box, for the offset of the latest time set).
    shifts: [D::V; 27],
    /// Velocity of each image code relative to the grain it images: the
    /// sliding images' jump in a sheared box, zero otherwise.
    vshifts: [D::V; 27],
    /// The sliding images of a sheared box.
    shear: Option<ListShear>,
    /// Positions at the last build, for the skin criterion.
    ref_pos: Vec<D::V>,
    skin: f64,
    builds: u64,
    built: bool,
}

impl<D: Dim> Default for NeighborList<D> {
    fn default() -> Self {
        Self::new(0.0)
    }
}

impl<D: Dim> NeighborList<D> {
    /// An empty list that, once built, includes pairs up to `skin` beyond
    /// contact. A larger skin means fewer rebuilds but more pairs to check.
    pub fn new(skin: f64) -> Self {
        Self {
            pairs: Vec::new(),
            image: Vec::new(),
            shifts: [D::zero(); 27],
            vshifts: [D::zero(); 27],
            shear: None,
            ref_pos: Vec::new(),
            skin,
            builds: 0,
            built: false,
        }
    }

    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// Lists every pair (i, j) with |pos_i − (pos_j + shift)| < r_i + r_j + skin,
    /// skipping pairs where both are frozen (they exert no force that matters).
    ///
    /// Positions on periodic axes must already be wrapped into `[lo, hi)` by
    /// the caller (an error otherwise). Uses a cell grid of side ≥
    /// 2·max_radius + skin. Fails if a periodic length is below
    /// 2 × (largest diameter + skin), where a pair could interact through two
    /// images at once; the list is left unchanged on error. A sheared box's
    /// images slide: [`NeighborList::build_at`] builds at a time.
    pub fn build(
        &mut self,
        pos: &[D::V],
        radius: &[f64],
        frozen: &[bool],
        domain: &Domain<D>,
    ) -> Result<()> {
        self.build_at(pos, radius, frozen, domain, 0.0)
    }

    /// [`NeighborList::build`] at time `t`, where a sheared box's images
    /// have slid by its offset Δ(t) (positions wrapped for that offset,
    /// [`Domain::wrap_sheared`]); across the gradient boundary the search
    /// looks around each grain's place less the offset.
    pub fn build_at(
        &mut self,
        pos: &[D::V],
        radius: &[f64],
        frozen: &[bool],
        domain: &Domain<D>,
        t: f64,
    ) -> Result<()> {
        let n = pos.len();
        if radius.len() != n || frozen.len() != n {
            return Err(Error::input(format!(
                "neighbour list: {} positions but {} radii and {} frozen flags",
                n,
                radius.len(),
                frozen.len()
            )));
        }
        if n >= u32::MAX as usize {
            return Err(Error::input(format!(
                "neighbour list: too many particles ({n})"
            )));
        }
        if !(self.skin.is_finite() && self.skin >= 0.0) {
            return Err(Error::input(format!(
                "neighbour skin must be finite and non-negative, got {}",
                self.skin
            )));
        }
        let mut max_r: f64 = 0.0;
        for (i, &r) in radius.iter().enumerate() {
            if !(r.is_finite() && r >= 0.0) {
                return Err(Error::input(format!("particle {i} has invalid radius {r}")));
            }
            max_r = max_r.max(r);
        }
        let reach = 2.0 * max_r + self.skin;
        let mut length = [0.0; 3];
        let mut periodic = [false; 3];
        for a in 0..D::D {
            if !domain.is_periodic(a) {
                continue;
            }
            let l = domain.length(a);
            if !(l.is_finite() && l >= 2.0 * reach) {
                return Err(Error::input(format!(
                    "periodic box length {l} along axis {a} is smaller than \
                     2 × (largest diameter {} + neighbour skin {}) = {}: a pair could \
                     interact through two periodic images; enlarge the box or reduce the skin",
                    2.0 * max_r,
                    self.skin,
                    2.0 * reach
                )));
            }
            length[a] = l;
            periodic[a] = true;
        }
        let shear = ListShear::at(domain, t, reach)?;
        for (i, &p) in pos.iter().enumerate() {
            for (a, &wrapped) in periodic.iter().enumerate().take(D::D) {
                let x = D::get(p, a);
                if !x.is_finite() {
                    return Err(Error::Unstable(format!(
                        "particle {i} has a non-finite position {:?}",
                        D::to_xyz(p)
                    )));
                }
                let (lo, hi) = (D::get(domain.lo, a), D::get(domain.hi, a));
                if wrapped && !(x >= lo && x < hi) {
                    return Err(Error::input(format!(
                        "particle {i} lies outside the periodic box along axis {a} \
                         ({x} not in [{lo}, {hi})): wrap positions before building the neighbour list"
                    )));
                }
            }
        }

        // Image-code shift table: digit k on axis a means (k − 1) box lengths.
        for (code, s) in self.shifts.iter_mut().enumerate() {
            *s = D::zero();
            for a in 0..D::D {
                let digit = (code / POW3[a] as usize) % 3;
                D::set(s, a, (digit as f64 - 1.0) * length[a]);
            }
        }
        self.shear = shear;
        self.slide_images();
        self.set_velocity_shifts();

        let max_cells = (CELLS_PER_PARTICLE * n).clamp(MIN_CELLS, MAX_CELLS);
        let shape = GridShape::new(domain, reach, max_cells);
        // The grid is scratch, dropped after the build: keeping it would cost
        // about 14 bytes per grain between rebuilds.
        let mut grid = CellGrid::default();
        grid.bin::<D>(shape, pos);

        let scan = Scan::<D> {
            pos,
            radius,
            frozen,
            grid: &grid,
            periodic,
            length,
            shifts: &self.shifts,
            skin: self.skin,
            shear: shear.map(|s| ScanShear {
                gradient: s.gradient,
                offset: s.built,
            }),
        };
        self.pairs.clear();
        self.image.clear();
        if n <= CHUNK {
            scan.run(0..n, &mut self.pairs, &mut self.image);
        } else {
            let parts: Vec<(Vec<[u32; 2]>, Vec<u8>)> = (0..n.div_ceil(CHUNK))
                .into_par_iter()
                .with_min_len(crate::parallel::min_len(1))
                .map(|k| {
                    let (mut p, mut im) = (Vec::new(), Vec::new());
                    scan.run(k * CHUNK..((k + 1) * CHUNK).min(n), &mut p, &mut im);
                    (p, im)
                })
                .collect();
            let total = parts.iter().map(|(p, _)| p.len()).sum();
            self.pairs.reserve(total);
            self.image.reserve(total);
            for (p, im) in parts {
                self.pairs.extend_from_slice(&p);
                self.image.extend_from_slice(&im);
            }
        }

        self.ref_pos.clear();
        self.ref_pos.extend_from_slice(pos);
        self.builds += 1;
        self.built = true;
        Ok(())
    }

    /// True when any particle has moved more than skin/2 since the last build
    /// (or there was no build yet, or the particle count changed): only then
    /// can a contact be missing from the list.
    pub fn needs_rebuild(&self, pos: &[D::V]) -> bool {
        if !self.built || pos.len() != self.ref_pos.len() {
            return true;
        }
        let Some(limit) = self.limit2() else {
            return true;
        };
        pos.par_chunks(4096)
            .zip(self.ref_pos.par_chunks(4096))
            .with_min_len(crate::parallel::min_len(1))
            .any(|(a, b)| a.iter().zip(b).any(|(&p, &q)| D::norm2(p - q) > limit))
    }

    /// The positions of the last build and the squared displacement beyond
    /// which a grain calls for a rebuild (the test of [`Self::needs_rebuild`]),
    /// for an integrator that checks while it moves the grains; `None` when a
    /// rebuild is due whatever the motion (no build yet, or `n` grains now).
    pub fn skin_reference(&self, n: usize) -> Option<(&[D::V], f64)> {
        if !(self.built && n == self.ref_pos.len()) {
            return None;
        }
        Some((&self.ref_pos[..], self.limit2()?))
    }

    /// The squared displacement beyond which a grain calls for a rebuild:
    /// (skin/2)², less in a sheared box as its images slide (`None`: no
    /// skin left, a rebuild is due).
    fn limit2(&self) -> Option<f64> {
        match &self.shear {
            None => Some(0.25 * self.skin * self.skin),
            Some(s) => s.limit2(self.skin),
        }
    }

    /// The shift to add to the partner's position for image `code`.
    #[inline]
    pub fn shift(&self, code: u8) -> D::V {
        self.shifts[code as usize]
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// Marks the list as stale, so that the next displacement test asks for
    /// a rebuild (grains were added behind its back).
    pub fn invalidate(&mut self) {
        self.built = false;
    }

    /// Number of builds so far: statistics, and the key by which the mesh
    /// walls' per-grain triangle lists know they must be remade.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Keeps the pairs `[i, j]` for which `keep(i, j)` holds, in their
    /// order, with their image codes (the sub-spheres of one rigid body
    /// never touch each other).
    pub fn retain_pairs(&mut self, keep: impl Fn(u32, u32) -> bool) {
        let mut k = 0;
        for m in 0..self.pairs.len() {
            let [i, j] = self.pairs[m];
            if keep(i, j) {
                self.pairs[k] = self.pairs[m];
                self.image[k] = self.image[m];
                k += 1;
            }
        }
        self.pairs.truncate(k);
        self.image.truncate(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    /// Unordered pair (low id, high id) → separation pos_low − image of pos_high.
    type PairMap = BTreeMap<(u32, u32), [f64; 3]>;

    fn brute_force<D: Dim>(
        pos: &[D::V],
        radius: &[f64],
        frozen: &[bool],
        skin: f64,
        domain: &Domain<D>,
    ) -> PairMap {
        let mut map = PairMap::new();
        for i in 0..pos.len() {
            for j in i + 1..pos.len() {
                if frozen[i] && frozen[j] {
                    continue;
                }
                let d = domain.minimum_image(pos[i] - pos[j]);
                let cut = radius[i] + radius[j] + skin;
                if D::norm2(d) < cut * cut {
                    map.insert((i as u32, j as u32), D::to_xyz(d));
                }
            }
        }
        map
    }

    /// The list as a map, checking that each pair appears once, that pairs are
    /// grouped by ascending first index, and that codes are in range.
    fn listed<D: Dim>(list: &NeighborList<D>, pos: &[D::V]) -> PairMap {
        assert_eq!(list.pairs.len(), list.image.len());
        assert_eq!(list.len(), list.pairs.len());
        let mut map = PairMap::new();
        let mut prev_first = 0;
        for (&[i, j], &code) in list.pairs.iter().zip(&list.image) {
            assert!(i >= prev_first, "pairs not grouped by first index");
            prev_first = i;
            assert!(
                (code as usize) < POW3[D::D - 1] as usize * 3,
                "image code {code} out of range"
            );
            let d = (pos[i as usize] - pos[j as usize]) - list.shift(code);
            let (key, d) = if i < j { ((i, j), d) } else { ((j, i), -d) };
            assert!(
                map.insert(key, D::to_xyz(d)).is_none(),
                "pair {key:?} listed twice"
            );
        }
        map
    }

    #[derive(Clone, Debug)]
    struct Config {
        lo: [f64; 3],
        /// Box length per axis in units of the reach 2·max_radius + skin.
        boxes: [f64; 3],
        periodic: [bool; 3],
        r0: f64,
        ratio: f64,
        skin_frac: f64,
        /// Per particle: position as fractions, size fraction, frozen.
        parts: Vec<([f64; 3], f64, bool)>,
    }

    fn config() -> impl Strategy<Value = Config> {
        (
            prop::array::uniform3(-5.0..5.0f64),
            prop::array::uniform3(0.1..7.0f64),
            prop::array::uniform3(any::<bool>()),
            0.05..0.5f64,
            1.0..4.0f64,
            0.0..0.5f64,
            prop::collection::vec(
                (
                    prop::array::uniform3(0.0..1.0f64),
                    0.0..1.0f64,
                    prop::bool::weighted(0.3),
                ),
                2..200,
            ),
        )
            .prop_map(
                |(lo, boxes, periodic, r0, ratio, skin_frac, parts)| Config {
                    lo,
                    boxes,
                    periodic,
                    r0,
                    ratio,
                    skin_frac,
                    parts,
                },
            )
    }

    struct Setup<D: Dim> {
        pos: Vec<D::V>,
        radius: Vec<f64>,
        frozen: Vec<bool>,
        skin: f64,
        domain: Domain<D>,
    }

    fn setup<D: Dim>(c: &Config) -> Setup<D> {
        let radius: Vec<f64> = c
            .parts
            .iter()
            .map(|p| c.r0 * (1.0 + (c.ratio - 1.0) * p.1))
            .collect();
        let frozen = c.parts.iter().map(|p| p.2).collect();
        let skin = c.skin_frac * 2.0 * c.r0;
        let reach = 2.0 * radius.iter().copied().fold(0.0, f64::max) + skin;
        let mut hi = c.lo;
        for (a, h) in hi.iter_mut().enumerate() {
            // Periodic boxes at least (just over) the smallest allowed length.
            let k = if c.periodic[a] {
                c.boxes[a].max(2.0 + 1e-9)
            } else {
                c.boxes[a]
            };
            *h = c.lo[a] + k * reach;
        }
        let domain = Domain::<D>::new(D::from_xyz(c.lo), D::from_xyz(hi), c.periodic);
        let pos = c
            .parts
            .iter()
            .map(|p| {
                let mut x = [0.0; 3];
                for a in 0..3 {
                    let l = hi[a] - c.lo[a];
                    x[a] = if c.periodic[a] {
                        c.lo[a] + p.0[a] * l
                    } else {
                        // Non-periodic: grains may lie well outside the box.
                        c.lo[a] - 0.5 * l + 2.0 * p.0[a] * l
                    };
                }
                domain.wrap(D::from_xyz(x))
            })
            .collect();
        Setup {
            pos,
            radius,
            frozen,
            skin,
            domain,
        }
    }

    fn check_against_brute_force<D: Dim>(c: &Config) {
        let s = setup::<D>(c);
        let mut list = NeighborList::<D>::new(s.skin);
        list.build(&s.pos, &s.radius, &s.frozen, &s.domain).unwrap();
        let expected = brute_force(&s.pos, &s.radius, &s.frozen, s.skin, &s.domain);
        assert_eq!(listed(&list, &s.pos), expected);
        // Same input, same list.
        let (pairs, image) = (list.pairs.clone(), list.image.clone());
        list.build(&s.pos, &s.radius, &s.frozen, &s.domain).unwrap();
        assert_eq!((pairs, image), (list.pairs.clone(), list.image.clone()));
        assert_eq!(list.builds(), 2);
    }

    proptest! {
        #[test]
        fn matches_brute_force_2d(c in config()) {
            check_against_brute_force::<D2>(&c);
        }

        #[test]
        fn matches_brute_force_3d(c in config()) {
            check_against_brute_force::<D3>(&c);
        }
    }

    #[test]
    fn large_build_matches_brute_force_on_any_thread_count() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let n = 3 * CHUNK + 17;
        let domain = Domain::<D3>::new(
            DVec3::ZERO,
            DVec3::new(12.0, 10.0, 14.0),
            [true, true, false],
        );
        let pos: Vec<DVec3> = (0..n)
            .map(|_| {
                DVec3::new(
                    rng.gen_range(0.0..12.0),
                    rng.gen_range(0.0..10.0),
                    rng.gen_range(-1.0..15.0),
                )
            })
            .collect();
        let radius: Vec<f64> = (0..n).map(|_| rng.gen_range(0.1..0.4)).collect();
        let frozen: Vec<bool> = (0..n).map(|_| rng.gen_bool(0.1)).collect();
        let skin = 0.05;
        let build = || {
            let mut list = NeighborList::<D3>::new(skin);
            list.build(&pos, &radius, &frozen, &domain).unwrap();
            list
        };
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(build);
        let three = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap()
            .install(build);
        assert_eq!(one.pairs, three.pairs);
        assert_eq!(one.image, three.image);
        assert_eq!(
            listed(&one, &pos),
            brute_force(&pos, &radius, &frozen, skin, &domain)
        );
    }

    /// Lees–Edwards: the list built at time t holds exactly the pairs
    /// within reach through the sliding images, each once, for offsets
    /// across the whole shear length, in 2D and 3D.
    fn sheared_matches_brute_force<D: Dim>(gradient: usize, seed: u64) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        for round in 0..40 {
            let n = rng.gen_range(2..300);
            let lx = rng.gen_range(2.3..9.0);
            let hi = D::from_xyz([lx, rng.gen_range(3.4..9.0), rng.gen_range(3.4..9.0)]);
            let mut domain = Domain::<D>::new(D::zero(), hi, [true; 3]);
            domain.shear = Some(crate::domain::Shear {
                axis: 0,
                gradient,
                rate: rng.gen_range(-2.0..2.0),
            });
            let t = rng.gen_range(0.0..20.0);
            let (_, offset) = domain.shear_offset(t);
            let radius: Vec<f64> = (0..n).map(|_| rng.gen_range(0.2..0.5)).collect();
            let frozen = vec![false; n];
            let pos: Vec<D::V> = (0..n)
                .map(|_| {
                    let mut p = D::zero();
                    for a in 0..D::D {
                        D::set(&mut p, a, rng.gen_range(0.0..D::get(hi, a)));
                    }
                    p
                })
                .collect();
            let skin = 0.1;
            let mut list = NeighborList::<D>::new(skin);
            list.build_at(&pos, &radius, &frozen, &domain, t).unwrap();
            let mut expected = PairMap::new();
            for i in 0..n {
                for j in i + 1..n {
                    let (d, _) = domain.minimum_image_sheared(pos[i] - pos[j], offset);
                    let cut = radius[i] + radius[j] + skin;
                    if D::norm2(d) < cut * cut {
                        expected.insert((i as u32, j as u32), D::to_xyz(d));
                    }
                }
            }
            let got = listed(&list, &pos);
            assert_eq!(
                got.keys().collect::<Vec<_>>(),
                expected.keys().collect::<Vec<_>>(),
                "round {round}"
            );
            for (k, d) in &got {
                let e = expected[k];
                assert!(
                    (0..3).all(|a| (d[a] - e[a]).abs() < 1e-9),
                    "{k:?}: {d:?} {e:?}"
                );
            }
        }
    }

    #[test]
    fn sheared_list_matches_brute_force() {
        sheared_matches_brute_force::<D2>(1, 11);
        sheared_matches_brute_force::<D3>(2, 12);
        sheared_matches_brute_force::<D3>(1, 13);
    }

    #[test]
    fn needs_rebuild_triggers_just_past_half_skin() {
        let skin = 0.5;
        let mut list = NeighborList::<D2>::new(skin);
        let mut pos = vec![DVec2::new(1.0, 1.0), DVec2::new(3.0, 1.0)];
        assert!(list.needs_rebuild(&pos), "no build yet");
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(4.0, 4.0), [false; 3]);
        list.build(&pos, &[0.5, 0.5], &[false, false], &domain)
            .unwrap();
        assert_eq!(list.skin(), skin);
        assert!(!list.needs_rebuild(&pos));
        pos[1].x += 0.25; // exactly skin / 2
        assert!(!list.needs_rebuild(&pos));
        pos[1].x += 1e-12;
        assert!(list.needs_rebuild(&pos));
        pos[1].x = 3.0;
        pos[0] += DVec2::new(0.15, 0.2); // |move| = 0.25
        assert!(!list.needs_rebuild(&pos));
        pos[0].y += 1e-12;
        assert!(list.needs_rebuild(&pos));
        assert!(list.needs_rebuild(&pos[..1]), "particle count changed");
    }

    #[test]
    fn frozen_pairs_are_excluded() {
        let pos = [
            DVec2::new(1.0, 1.0),
            DVec2::new(1.5, 1.0),
            DVec2::new(1.2, 1.3),
        ];
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(5.0, 5.0), [false; 3]);
        let mut list = NeighborList::<D2>::new(0.1);
        list.build(&pos, &[0.5; 3], &[true, true, false], &domain)
            .unwrap();
        assert_eq!(list.pairs, vec![[0, 2], [1, 2]]);
        list.build(&pos, &[0.5; 3], &[false; 3], &domain).unwrap();
        assert_eq!(list.pairs, vec![[0, 1], [0, 2], [1, 2]]);
    }

    #[test]
    fn two_cell_periodic_axis_pairs_through_the_boundary_once() {
        // Reach 2·0.5 + 0.1 = 1.1; box 2.2 long: one or two cells on x.
        let l = 2.0 * 1.1;
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(l, 3.0), [true, false, false]);
        let pos = [
            DVec2::new(0.05, 1.0),
            DVec2::new(2.15, 1.0),
            DVec2::new(1.1, 1.0),
        ];
        let mut list = NeighborList::<D2>::new(0.1);
        list.build(&pos, &[0.5; 3], &[false; 3], &domain).unwrap();
        let map = listed(&list, &pos);
        assert_eq!(
            map.keys().copied().collect::<Vec<_>>(),
            vec![(0, 1), (0, 2), (1, 2)]
        );
        let k = list.pairs.iter().position(|p| *p == [0, 1]).unwrap();
        assert_eq!(list.shift(list.image[k]), DVec2::new(-l, 0.0));
        assert!((map[&(0, 1)][0] - 0.1).abs() < 1e-12);
    }

    #[test]
    fn small_periodic_box_is_an_error() {
        let reach = 2.0 * 0.5 + 0.1;
        let pos = [DVec2::new(0.5, 0.5)];
        let mut list = NeighborList::<D2>::new(0.1);
        let short = Domain::<D2>::new(
            DVec2::ZERO,
            DVec2::new(10.0, 2.0 * reach - 1e-9),
            [false, true, false],
        );
        let err = list.build(&pos, &[0.5], &[false], &short).unwrap_err();
        assert!(matches!(err, Error::Input(_)));
        let msg = err.to_string();
        assert!(
            msg.contains("periodic box length") && msg.contains("axis 1"),
            "{msg}"
        );
        assert_eq!(list.builds(), 0);
        let exact = Domain::<D2>::new(
            DVec2::ZERO,
            DVec2::new(10.0, 2.0 * reach),
            [false, true, false],
        );
        list.build(&pos, &[0.5], &[false], &exact).unwrap();
        // A short non-periodic axis is fine: its bounds only size the grid.
        let flat = Domain::<D2>::new(DVec2::ZERO, DVec2::new(10.0, 0.1), [true, false, false]);
        list.build(&pos, &[0.5], &[false], &flat).unwrap();
    }

    #[test]
    fn bad_input_is_reported() {
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(10.0, 10.0), [true, false, false]);
        let mut list = NeighborList::<D2>::new(0.1);
        let unwrapped = [DVec2::new(10.5, 1.0)];
        assert!(matches!(
            list.build(&unwrapped, &[0.5], &[false], &domain),
            Err(Error::Input(_))
        ));
        let nan = [DVec2::new(1.0, f64::NAN)];
        assert!(matches!(
            list.build(&nan, &[0.5], &[false], &domain),
            Err(Error::Unstable(_))
        ));
        let ok = [DVec2::new(1.0, 1.0)];
        assert!(list.build(&ok, &[0.5, 0.5], &[false], &domain).is_err());
        list.build(&[], &[], &[], &domain).unwrap();
        assert!(list.is_empty());
    }
}
