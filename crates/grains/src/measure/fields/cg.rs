//! Coarse-grained fields from grains and contacts, after Weinhart,
//! Thornton, Luding & Bokhove (2012, Granular Matter 14, 289) and
//! Goldhirsch (2010, Granular Matter 12, 239):
//!
//! ρ(x) = Σ_i m_i φ(x − x_i), p(x) = Σ_i m_i v_i φ(x − x_i),
//! σ^c(x) = Σ_c f_c ⊗ b_c ∫_0^1 φ(x − x_j − s b_c) ds,
//!
//! with f_c the force on the first grain, b_c = x_i − x_j the branch
//! vector (for a wall contact, the force on the grain and b = x_i − c from
//! the contact point c), and stresses counted positive in compression (the
//! negative of the Cauchy stress, so that a bed at rest has σ_zz(z) =
//! ∫_z ρ g dz'). On a grid each grain's and each contact's weights are
//! normalised on the lattice (`spread`), so that the fields hold the
//! totals exactly. Everything here reads plain data ([`Snapshot`]).

use super::kernel::Kernel;
use crate::codec::{Dec, DecResult, Enc};
use crate::io::contact_records::{add_outer, Snapshot};

/// How grains are spread over the grid's points.
#[derive(Clone, Debug, PartialEq)]
pub enum Smoothing {
    /// A kernel over the grid's axes; the field is averaged over the box
    /// along the other axes.
    Kernel(Kernel),
    /// One point: the average over the whole box (φ = 1/V), where the
    /// contact stress is the virial Σ f ⊗ b / V.
    Box,
}

/// The points where fields are evaluated: cell centres of a regular grid
/// over the box along `axes` (none: the single box).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub dim: usize,
    pub axes: Vec<usize>,
    pub cells: Vec<usize>,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub periodic: [bool; 3],
}

impl Grid {
    /// The number of points.
    pub fn len(&self) -> usize {
        self.cells.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The spacing along grid axis number `g`.
    pub fn spacing(&self, g: usize) -> f64 {
        let a = self.axes[g];
        (self.hi[a] - self.lo[a]) / self.cells[g] as f64
    }

    /// The position of point `index` (grid axes in order, the first
    /// fastest); the box's middle along the other axes.
    pub fn point(&self, mut index: usize) -> [f64; 3] {
        let mut p = [0.0; 3];
        for (a, x) in p.iter_mut().enumerate().take(self.dim) {
            *x = 0.5 * (self.lo[a] + self.hi[a]);
        }
        for (g, &a) in self.axes.iter().enumerate() {
            let i = index % self.cells[g];
            index /= self.cells[g];
            p[a] = self.lo[a] + (i as f64 + 0.5) * self.spacing(g);
        }
        p
    }

    /// The volume a point stands for (a cell's spacings times the box's
    /// extent along the averaged axes; the box's volume for the single
    /// box): Σ ρ over the points times it is the grains' mass.
    pub fn point_volume(&self) -> f64 {
        self.cell() * self.cross()
    }

    /// The measure of the box along the axes the grid averages over (the
    /// whole box's volume for the single box).
    fn cross(&self) -> f64 {
        (0..self.dim)
            .filter(|a| !self.axes.contains(a))
            .map(|a| self.hi[a] - self.lo[a])
            .product()
    }

    /// The volume of one cell along the grid's axes (its spacings' product).
    fn cell(&self) -> f64 {
        (0..self.axes.len()).map(|g| self.spacing(g)).product()
    }

    /// Calls `f(point index, point position along the grid axes, unwrapped
    /// near the source)` for every lattice point whose grid coordinates lie
    /// within [lo, hi] (grid axes only): periodic axes visit the images;
    /// along the others, points of the lattice beyond the grid's ends are
    /// visited too, with no index.
    fn visit(&self, lo: [f64; 3], hi: [f64; 3], mut f: impl FnMut(Option<usize>, [f64; 3])) {
        let mut lists: Vec<Vec<(Option<usize>, f64)>> = Vec::with_capacity(self.axes.len());
        for (g, &a) in self.axes.iter().enumerate() {
            let (h, n) = (self.spacing(g), self.cells[g] as i64);
            let first = ((lo[a] - self.lo[a]) / h - 0.5).ceil() as i64;
            let last = ((hi[a] - self.lo[a]) / h - 0.5).floor() as i64;
            let list = (first..=last).map(|i| {
                let at = if self.periodic[a] {
                    Some(i.rem_euclid(n) as usize)
                } else {
                    (0..n).contains(&i).then_some(i as usize)
                };
                (at, self.lo[a] + (i as f64 + 0.5) * h)
            });
            lists.push(list.collect());
        }
        let mut p = [0.0; 3];
        visit_product(
            &lists,
            &self.axes,
            &self.cells,
            0,
            Some(0),
            1,
            &mut p,
            &mut f,
        );
    }
}

#[allow(clippy::too_many_arguments)]
fn visit_product(
    lists: &[Vec<(Option<usize>, f64)>],
    axes: &[usize],
    cells: &[usize],
    g: usize,
    index: Option<usize>,
    stride: usize,
    p: &mut [f64; 3],
    f: &mut impl FnMut(Option<usize>, [f64; 3]),
) {
    if g == lists.len() {
        f(index, *p);
        return;
    }
    for &(i, x) in &lists[g] {
        p[axes[g]] = x;
        let at = index.zip(i).map(|(index, i)| index + i * stride);
        visit_product(lists, axes, cells, g + 1, at, stride * cells[g], p, f);
    }
}

/// Into `hits`, the grid points (index, weight) within `lo..hi` where
/// `phi` is positive, the weights scaled so that over the whole lattice
/// (points beyond a non-periodic end included) they sum to
/// 1/`per_lattice`, the inverse of a lattice cell's volume times the
/// averaged extent: a source that no lattice point reaches gives nothing.
fn spread(
    grid: &Grid,
    (lo, hi): ([f64; 3], [f64; 3]),
    phi: impl Fn([f64; 3]) -> f64,
    per_lattice: f64,
    hits: &mut Vec<(usize, f64)>,
) {
    hits.clear();
    let mut norm = 0.0;
    grid.visit(lo, hi, |at, p| {
        let w = phi(p);
        norm += w;
        if let (Some(at), true) = (at, w > 0.0) {
            hits.push((at, w));
        }
    });
    let scale = if norm > 0.0 {
        1.0 / (norm * per_lattice)
    } else {
        0.0
    };
    for h in hits.iter_mut() {
        h.1 *= scale;
    }
}

/// Per point, the running sums: mass, momentum (3), Σ m v ⊗ v (9), grain
/// volume, number, contacts per grain, fabric (9), contact stress (9).
const MASS: usize = 0;
const MOM: usize = 1;
const MVV: usize = 4;
const VOL: usize = 13;
const NUM: usize = 14;
const COORD: usize = 15;
const FABRIC: usize = 16;
const CONTACT: usize = 25;
const STRIDE: usize = 34;

/// The time-averaged fields of a window of samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Fields {
    pub grid: Grid,
    pub samples: u64,
    /// First and last sampled time.
    pub times: (f64, f64),
    pub points: Vec<[f64; 3]>,
    pub density: Vec<f64>,
    pub packing_fraction: Vec<f64>,
    /// p / ρ (zero where ρ is).
    pub velocity: Vec<[f64; 3]>,
    /// tr σ^k / (d ρ): (1/d)⟨|v − u|²⟩ weighted by mass.
    pub temperature: Vec<f64>,
    /// σ^k = ⟨Σ m v ⊗ v φ⟩ − ρ u ⊗ u, u = ⟨p⟩/⟨ρ⟩.
    pub kinetic_stress: Vec<[[f64; 3]; 3]>,
    pub contact_stress: Vec<[[f64; 3]; 3]>,
    pub stress: Vec<[[f64; 3]; 3]>,
    /// Σ_i z_i φ / Σ_i φ, z_i the grain–grain contacts of grain i.
    pub coordination: Vec<f64>,
    /// Σ_i φ Σ_{c∋i} n_c ⊗ n_c / Σ_i φ (its trace is the coordination).
    pub fabric: Vec<[[f64; 3]; 3]>,
}

/// The running sums of one averaging window.
#[derive(Clone, Debug, PartialEq)]
pub struct CoarseGrainer {
    pub grid: Grid,
    pub smoothing: Smoothing,
    sums: Vec<f64>,
    samples: u64,
    times: (f64, f64),
}

impl CoarseGrainer {
    pub fn new(grid: Grid, smoothing: Smoothing) -> Self {
        let n = grid.len();
        Self {
            grid,
            smoothing,
            sums: vec![0.0; n * STRIDE],
            samples: 0,
            times: (f64::NAN, f64::NAN),
        }
    }

    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Adds one instant.
    pub fn add(&mut self, s: &Snapshot) {
        let n = s.pos.len();
        // Each grain's contacts and fabric Σ n ⊗ n (grain–grain only).
        let mut z = vec![0.0; n];
        let mut fab = vec![[[0.0; 3]; 3]; n];
        for c in &s.contacts {
            for &i in &c.index {
                z[i] += 1.0;
                add_outer(&mut fab[i], c.normal, c.normal, 1.0);
            }
        }
        let cross = self.grid.cross();
        let sums = &mut self.sums;
        let grid = &self.grid;
        let per_grain = |sums: &mut [f64], w: f64, i: usize| {
            let (m, v) = (s.mass[i], s.vel[i]);
            sums[MASS] += w * m;
            for a in 0..3 {
                sums[MOM + a] += w * m * v[a];
                for b in 0..3 {
                    sums[MVV + 3 * a + b] += w * m * v[a] * v[b];
                    sums[FABRIC + 3 * a + b] += w * fab[i][a][b];
                }
            }
            sums[VOL] += w * s.grain_volume(i);
            sums[NUM] += w;
            sums[COORD] += w * z[i];
        };
        let per_contact = |sums: &mut [f64], w: f64, f: [f64; 3], b: [f64; 3]| {
            for a in 0..3 {
                for c in 0..3 {
                    sums[CONTACT + 3 * a + c] += w * f[a] * b[c];
                }
            }
        };
        // Segments: (start, branch, force) of every contact.
        let segments = s
            .contacts
            .iter()
            .map(|c| (s.pos[c.index[1]], c.branch, c.force()))
            .chain(s.walls.iter().map(|c| {
                let b = s.minimum_image(crate::io::contact_records::sub(s.pos[c.index], c.point));
                (c.point, b, c.force)
            }));
        match &self.smoothing {
            Smoothing::Box => {
                let w = 1.0 / cross;
                for i in 0..n {
                    per_grain(&mut sums[..STRIDE], w, i);
                }
                for (_, b, f) in segments {
                    per_contact(&mut sums[..STRIDE], w, f, b);
                }
            }
            Smoothing::Kernel(k) => {
                let reach = k.cutoff();
                let on_grid = |v: [f64; 3]| {
                    let mut out = [0.0; 3];
                    for &a in &grid.axes {
                        out[a] = v[a];
                    }
                    out
                };
                // Each grain's (and contact's) weights are normalised on
                // the lattice: they sum to 1/ΔV over its points, those
                // beyond a non-periodic end included, so the fields on the
                // grid hold the totals (mass, momentum, the virial)
                // exactly, not to the lattice sum's error.
                let per_lattice = grid.cell() * cross;
                let mut hits: Vec<(usize, f64)> = Vec::new();
                for i in 0..n {
                    let x = s.pos[i];
                    let lo = x.map(|c| c - reach);
                    let hi = x.map(|c| c + reach);
                    let phi = |p: [f64; 3]| {
                        let d = on_grid(crate::io::contact_records::sub(p, x));
                        k.at(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
                    };
                    spread(grid, (lo, hi), phi, per_lattice, &mut hits);
                    for &(at, w) in &hits {
                        per_grain(&mut sums[at * STRIDE..(at + 1) * STRIDE], w, i);
                    }
                }
                for (a, b, f) in segments {
                    let end = crate::io::contact_records::add(a, b);
                    let lo = [0, 1, 2].map(|c| a[c].min(end[c]) - reach);
                    let hi = [0, 1, 2].map(|c| a[c].max(end[c]) + reach);
                    let bp = on_grid(b);
                    let phi =
                        |p: [f64; 3]| k.along(on_grid(crate::io::contact_records::sub(p, a)), bp);
                    spread(grid, (lo, hi), phi, per_lattice, &mut hits);
                    for &(at, w) in &hits {
                        per_contact(&mut sums[at * STRIDE..(at + 1) * STRIDE], w, f, b);
                    }
                }
            }
        }
        if self.samples == 0 {
            self.times.0 = s.time;
        }
        self.times.1 = s.time;
        self.samples += 1;
    }

    /// The window's running sums as checkpoint bytes.
    pub fn save(&self, e: &mut Enc) {
        e.u64(self.samples);
        e.f64(self.times.0);
        e.f64(self.times.1);
        e.f64s(&self.sums);
    }

    /// The sums saved by [`Self::save`], into this fresh window over the
    /// same grid.
    pub fn load(mut self, d: &mut Dec) -> DecResult<Self> {
        self.samples = d.u64("fields samples")?;
        self.times = (d.f64("fields first time")?, d.f64("fields last time")?);
        let sums = d.f64s("fields sums")?;
        if sums.len() != self.sums.len() {
            return Err(format!(
                "measurement fields: the checkpoint's window holds {} sums, the scenario's grid \
                 {} (measure.fields.axes or cells changed)",
                sums.len(),
                self.sums.len()
            ));
        }
        self.sums = sums;
        Ok(self)
    }

    /// The fields averaged over the samples so far.
    pub fn fields(&self) -> Fields {
        let np = self.grid.len();
        let inv = if self.samples > 0 {
            1.0 / self.samples as f64
        } else {
            0.0
        };
        let dim = self.grid.dim as f64;
        let mut out = Fields {
            grid: self.grid.clone(),
            samples: self.samples,
            times: self.times,
            points: (0..np).map(|i| self.grid.point(i)).collect(),
            density: Vec::with_capacity(np),
            packing_fraction: Vec::with_capacity(np),
            velocity: Vec::with_capacity(np),
            temperature: Vec::with_capacity(np),
            kinetic_stress: Vec::with_capacity(np),
            contact_stress: Vec::with_capacity(np),
            stress: Vec::with_capacity(np),
            coordination: Vec::with_capacity(np),
            fabric: Vec::with_capacity(np),
        };
        for p in 0..np {
            let s = &self.sums[p * STRIDE..(p + 1) * STRIDE];
            let rho = s[MASS] * inv;
            let u = if rho > 0.0 {
                [0, 1, 2].map(|a| s[MOM + a] * inv / rho)
            } else {
                [0.0; 3]
            };
            let tensor = |at: usize| {
                let mut t = [[0.0; 3]; 3];
                for (a, row) in t.iter_mut().enumerate() {
                    for (b, e) in row.iter_mut().enumerate() {
                        *e = s[at + 3 * a + b] * inv;
                    }
                }
                t
            };
            let mut kin = tensor(MVV);
            add_outer(&mut kin, u, u, -rho);
            let con = tensor(CONTACT);
            let mut total = kin;
            for (row, crow) in total.iter_mut().zip(&con) {
                for (e, c) in row.iter_mut().zip(crow) {
                    *e += c;
                }
            }
            let num = s[NUM] * inv;
            let mut fab = tensor(FABRIC);
            if num > 0.0 {
                fab.iter_mut().flatten().for_each(|e| *e /= num);
            }
            out.density.push(rho);
            out.packing_fraction.push(s[VOL] * inv);
            out.velocity.push(u);
            out.temperature.push(if rho > 0.0 {
                (kin[0][0] + kin[1][1] + kin[2][2]) / (dim * rho)
            } else {
                0.0
            });
            out.kinetic_stress.push(kin);
            out.contact_stress.push(con);
            out.stress.push(total);
            out.coordination
                .push(if num > 0.0 { s[COORD] * inv / num } else { 0.0 });
            out.fabric.push(fab);
        }
        out
    }
}
