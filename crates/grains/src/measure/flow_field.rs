//! The coarse-grained flow field (`measure.flow_field`): on a grid of cells
//! in the plane of the pictures (x and the vertical axis; in 3D averaged
//! over y), the packing fraction, the mass-weighted mean velocity and the
//! granular temperature, averaged over the samples from time `from` on,
//! with a standard error per cell. Writes flow_field.csv and
//! flow_field.png (arrows over a packing-fraction map).
//!
//! Each grain counts wholly in the cell holding its centre (centre binning:
//! exact for a lattice whose cells hold whole unit cells). Over all samples
//! in a cell, with sums of m, m v and m |v|² over N grain-samples:
//! V = Σ m v / Σ m and T = (Σ m |v|² − |Σ m v|² / Σ m) / (d N), the same
//! temperature (J per grain and degree of freedom) as
//! [`super::granular_temperature`], about the cell's mean. The packing
//! fraction is the grains' area (2D) or volume (3D) per sample over the
//! cell's. Standard errors are those of batch means: consecutive samples
//! are correlated, so the samples are cut into batches of [`BATCH`] (one
//! output interval of the runner) and the error is the spread of the
//! batch means over √(batches − 1).

use crate::boundary::Wall;
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::{draw_arrows, viridis, write_atomic, Frame, Num};
use crate::measure::draw::draw_walls;
use crate::render::legend::{draw_band, Legend};
use crate::render::text::{draw_text, fill_rect, sig3};
use crate::render::{Painter, StillOptions};
use crate::view::GrainView;
use std::fmt::Write as _;
use std::path::Path;

/// Samples per batch for the standard errors.
pub const BATCH: u64 = 10;

/// Per-cell sums over a set of samples.
#[derive(Clone, Debug, PartialEq)]
struct Sums {
    /// Σ grain area or volume.
    vol: Vec<f64>,
    mass: Vec<f64>,
    /// Σ m v, three components per cell.
    mv: Vec<f64>,
    /// Σ m |v|².
    mv2: Vec<f64>,
    /// Grain-samples.
    count: Vec<f64>,
}

impl Sums {
    fn new(cells: usize) -> Self {
        Sums {
            vol: vec![0.0; cells],
            mass: vec![0.0; cells],
            mv: vec![0.0; 3 * cells],
            mv2: vec![0.0; cells],
            count: vec![0.0; cells],
        }
    }

    fn clear(&mut self) {
        for v in [
            &mut self.vol,
            &mut self.mass,
            &mut self.mv,
            &mut self.mv2,
            &mut self.count,
        ] {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
    }

    fn save(&self, e: &mut Enc) {
        for v in [&self.vol, &self.mass, &self.mv, &self.mv2, &self.count] {
            e.f64s(v);
        }
    }

    fn load(d: &mut Dec, cells: usize) -> DecResult<Self> {
        let mut one = |what: &str, n: usize| -> DecResult<Vec<f64>> {
            let v = d.f64s(what)?;
            if v.len() != n {
                return Err(format!(
                    "flow field {what}: {} values, {n} expected",
                    v.len()
                ));
            }
            Ok(v)
        };
        Ok(Sums {
            vol: one("volume", cells)?,
            mass: one("mass", cells)?,
            mv: one("momentum", 3 * cells)?,
            mv2: one("energy", cells)?,
            count: one("count", cells)?,
        })
    }
}

/// The flow-field accumulator.
#[derive(Clone, Debug, PartialEq)]
pub struct FlowField {
    /// Cells along x and the vertical axis.
    pub cells: [usize; 2],
    /// The grid: [x0, x1, v0, v1].
    pub rect: [f64; 4],
    /// 2 or 3.
    pub dim: usize,
    /// The box's length along y in 3D (cells are slabs through it); 1 in 2D.
    pub depth: f64,
    /// x wraps (a periodic box): grains outside it are folded in.
    pub periodic_x: bool,
    pub from: f64,
    pub samples: u64,
    all: Sums,
    batch: Sums,
    batch_samples: u64,
    /// Per cell: Σ and Σ² of batch means of (φ, v_x, v_vertical), and the
    /// number of batches holding each (velocity only where there was mass).
    bsum: Vec<f64>,
    bsum2: Vec<f64>,
    bcount: Vec<f64>,
}

/// One cell's results.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    pub packing: f64,
    pub packing_se: f64,
    /// Mean velocity along x and the vertical axis.
    pub v: [f64; 2],
    pub v_se: [f64; 2],
    pub temperature: f64,
    pub grain_samples: f64,
}

impl FlowField {
    /// A grid of `cells` = [nx, n_vertical] over `rect` = [x0, x1, v0, v1].
    pub fn new(
        cells: &[usize],
        rect: [f64; 4],
        dim: usize,
        depth: f64,
        periodic_x: bool,
        from: f64,
    ) -> Result<Self> {
        let &[nx, nv] = cells else {
            return Err(Error::input(format!(
                "measure.flow_field.cells = {cells:?}: give two counts, [cells along x, cells \
                 along the vertical axis] (a 3D field is averaged over y)"
            )));
        };
        if nx == 0 || nv == 0 || nx * nv > 1_000_000 {
            return Err(Error::input(format!(
                "measure.flow_field.cells = {cells:?}: each count must be at least 1, and \
                 at most 10^6 cells in all"
            )));
        }
        if !(rect[1] > rect[0] && rect[3] > rect[2] && rect.iter().all(|x| x.is_finite())) {
            return Err(Error::input(format!(
                "measure.flow_field: the grid [{}, {}] x [{}, {}] is empty (is `top` above \
                 the box floor?)",
                rect[0], rect[1], rect[2], rect[3]
            )));
        }
        if !from.is_finite() {
            return Err(Error::input(
                "measure.flow_field.from must be a finite time (s)",
            ));
        }
        let n = nx * nv;
        Ok(FlowField {
            cells: [nx, nv],
            rect,
            dim,
            depth,
            periodic_x,
            from,
            samples: 0,
            all: Sums::new(n),
            batch: Sums::new(n),
            batch_samples: 0,
            bsum: vec![0.0; 3 * n],
            bsum2: vec![0.0; 3 * n],
            bcount: vec![0.0; 3 * n],
        })
    }

    /// The field for `view`'s box: x across it, the vertical axis from its
    /// floor to `top` (default its top).
    pub fn for_md<D: Dim>(
        view: &GrainView<D>,
        cells: &[usize],
        from: f64,
        top: Option<f64>,
    ) -> Result<Self> {
        let (lo, hi) = (D::to_xyz(view.domain.lo), D::to_xyz(view.domain.hi));
        let v = D::vertical();
        let rect = [lo[0], hi[0], lo[v], top.unwrap_or(hi[v])];
        let depth = if D::D == 3 { hi[1] - lo[1] } else { 1.0 };
        FlowField::new(cells, rect, D::D, depth, view.domain.periodic[0], from)
    }

    fn cell_size(&self) -> [f64; 2] {
        [
            (self.rect[1] - self.rect[0]) / self.cells[0] as f64,
            (self.rect[3] - self.rect[2]) / self.cells[1] as f64,
        ]
    }

    fn cell_volume(&self) -> f64 {
        let [dx, dv] = self.cell_size();
        dx * dv * self.depth
    }

    /// The cell holding (x, vertical) position `p`, if any.
    fn cell_of(&self, x: f64, v: f64) -> Option<usize> {
        let [dx, dv] = self.cell_size();
        let mut i = ((x - self.rect[0]) / dx).floor();
        let k = ((v - self.rect[2]) / dv).floor();
        let nx = self.cells[0] as f64;
        if self.periodic_x {
            i = i.rem_euclid(nx);
        }
        (i >= 0.0 && i < nx && k >= 0.0 && k < self.cells[1] as f64)
            .then(|| k as usize * self.cells[0] + i as usize)
    }

    /// Samples the mobile grains of `view` (from time `from` on).
    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        let p = &view.grains;
        let n = p.len();
        let keep = (0..n).filter(|&i| !p.frozen[i]);
        let pos: Vec<[f64; 3]> = keep.clone().map(|i| D::to_xyz(p.pos[i])).collect();
        let vel: Vec<[f64; 3]> = keep.clone().map(|i| D::to_xyz(p.vel[i])).collect();
        let radius: Vec<f64> = keep.clone().map(|i| p.radius[i]).collect();
        let mass: Vec<f64> = keep.map(|i| p.mass[i]).collect();
        self.sample_grains(view.time, &pos, &vel, &radius, &mass);
    }

    /// Samples grains given as arrays (xyz; z = 0 in 2D).
    pub fn sample_grains(
        &mut self,
        t: f64,
        pos: &[[f64; 3]],
        vel: &[[f64; 3]],
        radius: &[f64],
        mass: &[f64],
    ) {
        if t < self.from {
            return;
        }
        let vert = if self.dim == 3 { 2 } else { 1 };
        let mut now = Sums::new(self.all.vol.len());
        for i in 0..pos.len() {
            let Some(c) = self.cell_of(pos[i][0], pos[i][vert]) else {
                continue;
            };
            let r = radius[i];
            let size = if self.dim == 3 {
                4.0 / 3.0 * std::f64::consts::PI * r * r * r
            } else {
                std::f64::consts::PI * r * r
            };
            let (m, v) = (mass[i], vel[i]);
            now.vol[c] += size;
            now.mass[c] += m;
            for (acc, vk) in now.mv[3 * c..3 * c + 3].iter_mut().zip(v) {
                *acc += m * vk;
            }
            now.mv2[c] += m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            now.count[c] += 1.0;
        }
        for acc in [&mut self.all, &mut self.batch] {
            for (a, b) in [
                (&mut acc.vol, &now.vol),
                (&mut acc.mass, &now.mass),
                (&mut acc.mv, &now.mv),
                (&mut acc.mv2, &now.mv2),
                (&mut acc.count, &now.count),
            ] {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
            }
        }
        self.samples += 1;
        self.batch_samples += 1;
        if self.batch_samples == BATCH {
            self.close_batch();
        }
    }

    fn close_batch(&mut self) {
        let vol = self.cell_volume();
        let vert = if self.dim == 3 { 2 } else { 1 };
        for c in 0..self.all.vol.len() {
            let b = &self.batch;
            let mut add = |slot: usize, x: f64| {
                self.bsum[3 * c + slot] += x;
                self.bsum2[3 * c + slot] += x * x;
                self.bcount[3 * c + slot] += 1.0;
            };
            add(0, b.vol[c] / (vol * self.batch_samples as f64));
            if b.mass[c] > 0.0 {
                add(1, b.mv[3 * c] / b.mass[c]);
                add(2, b.mv[3 * c + vert] / b.mass[c]);
            }
        }
        self.batch.clear();
        self.batch_samples = 0;
    }

    /// The results of cell (ix, iv); velocities and temperature are NaN in
    /// a cell no grain entered, standard errors NaN with under two batches.
    pub fn cell(&self, ix: usize, iv: usize) -> Cell {
        let c = iv * self.cells[0] + ix;
        let a = &self.all;
        let vert = if self.dim == 3 { 2 } else { 1 };
        let m = a.mass[c];
        let mv = [a.mv[3 * c], a.mv[3 * c + 1], a.mv[3 * c + 2]];
        let p2 = mv[0] * mv[0] + mv[1] * mv[1] + mv[2] * mv[2];
        let (v, temperature) = if m > 0.0 {
            let t = (a.mv2[c] - p2 / m) / (self.dim as f64 * a.count[c]);
            ([mv[0] / m, mv[vert] / m], t.max(0.0))
        } else {
            ([f64::NAN; 2], f64::NAN)
        };
        let se = |slot: usize| {
            let n = self.bcount[3 * c + slot];
            if n < 2.0 {
                return f64::NAN;
            }
            let mean = self.bsum[3 * c + slot] / n;
            let var = (self.bsum2[3 * c + slot] / n - mean * mean).max(0.0);
            (var / (n - 1.0)).sqrt()
        };
        Cell {
            packing: if self.samples > 0 {
                a.vol[c] / (self.cell_volume() * self.samples as f64)
            } else {
                f64::NAN
            },
            packing_se: se(0),
            v,
            v_se: [se(1), se(2)],
            temperature,
            grain_samples: a.count[c],
        }
    }

    /// The cell centre (x, vertical).
    pub fn centre(&self, ix: usize, iv: usize) -> [f64; 2] {
        let [dx, dv] = self.cell_size();
        [
            self.rect[0] + (ix as f64 + 0.5) * dx,
            self.rect[2] + (iv as f64 + 0.5) * dv,
        ]
    }

    /// flow_field.csv: one row per cell.
    pub fn csv(&self) -> String {
        let (v, vv) = if self.dim == 3 {
            ("z", "vz")
        } else {
            ("y", "vy")
        };
        let mut s = format!(
            "ix,i{v},x,{v},grain_samples,packing_fraction,packing_fraction_se,vx,vx_se,{vv},\
             {vv}_se,temperature\n"
        );
        for iv in 0..self.cells[1] {
            for ix in 0..self.cells[0] {
                let c = self.cell(ix, iv);
                let p = self.centre(ix, iv);
                let _ = writeln!(
                    s,
                    "{ix},{iv},{},{},{},{},{},{},{},{},{},{}",
                    Num(p[0]),
                    Num(p[1]),
                    c.grain_samples,
                    Num(c.packing),
                    Num(c.packing_se),
                    Num(c.v[0]),
                    Num(c.v_se[0]),
                    Num(c.v[1]),
                    Num(c.v_se[1]),
                    Num(c.temperature)
                );
            }
        }
        s
    }

    /// Writes flow_field.csv and flow_field.png (over the final state's
    /// rectangle, with `walls` at its time).
    pub fn write<D: Dim>(&self, dir: &Path, last: &Frame, walls: &[Wall<D>]) -> Result<()> {
        write_atomic(&dir.join("flow_field.csv"), self.csv().as_bytes())?;
        // The picture shows the grid, with headroom for the note on top.
        let vert = if self.dim == 3 { 2 } else { 1 };
        let mut grid = Frame {
            dim: self.dim,
            box_lo: last.box_lo,
            box_hi: last.box_hi,
            periodic: last.periodic,
            ..Default::default()
        };
        grid.box_lo[0] = self.rect[0];
        grid.box_hi[0] = self.rect[1];
        grid.box_lo[vert] = self.rect[2];
        grid.box_hi[vert] = self.rect[3] + 0.06 * (self.rect[3] - self.rect[2]);
        let painter = Painter::new(&[&grid], &StillOptions::default());
        let mut img = painter.canvas();
        let top = (0..self.cells[1])
            .flat_map(|iv| (0..self.cells[0]).map(move |ix| (ix, iv)))
            .map(|(ix, iv)| self.cell(ix, iv).packing)
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max);
        let [dx, dv] = self.cell_size();
        let mut vmax = 0.0f64;
        for iv in 0..self.cells[1] {
            for ix in 0..self.cells[0] {
                let c = self.cell(ix, iv);
                if c.grain_samples <= 0.0 {
                    continue;
                }
                vmax = vmax.max(c.v[0].hypot(c.v[1]));
                // A light map (viridis halfway to white) so that dark
                // arrows stand out on every cell.
                let col = viridis(if top > 0.0 { c.packing / top } else { 0.0 })
                    .map(|x| 255 - (255 - x) / 2);
                let a = img.view.to_pixel([
                    self.rect[0] + ix as f64 * dx,
                    self.rect[2] + (iv + 1) as f64 * dv,
                ]);
                let b = img.view.to_pixel([
                    self.rect[0] + (ix + 1) as f64 * dx,
                    self.rect[2] + iv as f64 * dv,
                ]);
                let (x0, y0) = (a[0].round() as i64, a[1].round() as i64);
                let (w, h) = (
                    (b[0].round() as i64 - x0).max(0) as u32,
                    (b[1].round() as i64 - y0).max(0) as u32,
                );
                // Keep the band below the world part white.
                let h = h.min(painter.world_height.saturating_sub(y0.max(0) as u32));
                fill_rect(&mut img, x0, y0, w, h, col);
            }
        }
        // The fastest cell's arrow spans 0.9 of a cell.
        let reach = 0.9 * dx.min(dv);
        let (mut from, mut to) = (Vec::new(), Vec::new());
        for iv in 0..self.cells[1] {
            for ix in 0..self.cells[0] {
                let c = self.cell(ix, iv);
                if vmax > 0.0 && c.v.iter().all(|x| x.is_finite()) {
                    let p = self.centre(ix, iv);
                    let s = reach / vmax;
                    from.push([p[0] - 0.5 * s * c.v[0], p[1] - 0.5 * s * c.v[1]]);
                    to.push([p[0] + 0.5 * s * c.v[0], p[1] + 0.5 * s * c.v[1]]);
                }
            }
        }
        draw_arrows(&mut img, &from, &to, [20, 20, 20]);
        draw_walls(&mut img, walls, last.time, [40, 40, 40], 2.0);
        let note = format!(
            "arrows: {} m/s spans {} of a cell; {} samples",
            sig3(vmax),
            0.9,
            self.samples
        );
        draw_text(&mut img, 8, 8, 2, &note, [0, 0, 0]);
        draw_band(
            &mut img,
            painter.world_height,
            2,
            last.time,
            &Legend::Scale {
                name: "packing",
                lo: 0.0,
                hi: top,
                unit: "",
            },
        );
        img.save_png(&dir.join("flow_field.png"))
    }

    /// The accumulator as checkpoint bytes.
    pub fn save(&self, e: &mut Enc) {
        e.u64(self.samples);
        e.u64(self.batch_samples);
        self.all.save(e);
        self.batch.save(e);
        e.f64s(&self.bsum);
        e.f64s(&self.bsum2);
        e.f64s(&self.bcount);
    }

    /// Restores what [`FlowField::save`] wrote into a field built from the
    /// same scenario (`self`: its grid).
    pub fn load(mut self, d: &mut Dec) -> DecResult<Self> {
        let n = self.all.vol.len();
        self.samples = d.u64("flow field samples")?;
        self.batch_samples = d.u64("flow field batch")?;
        self.all = Sums::load(d, n)?;
        self.batch = Sums::load(d, n)?;
        for (v, what) in [
            (&mut self.bsum, "batch sums"),
            (&mut self.bsum2, "batch squares"),
            (&mut self.bcount, "batch counts"),
        ] {
            let got = d.f64s(what)?;
            if got.len() != 3 * n {
                return Err(format!(
                    "flow field {what}: {} values, {} expected",
                    got.len(),
                    3 * n
                ));
            }
            *v = got;
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A square lattice of disks (spacing a, radius r) filling [0, 4] × [0, 2].
    fn lattice(a: f64, r: f64) -> (Vec<[f64; 3]>, Vec<f64>, Vec<f64>) {
        let mut pos = Vec::new();
        for j in 0..(2.0 / a) as usize {
            for i in 0..(4.0 / a) as usize {
                pos.push([(i as f64 + 0.5) * a, (j as f64 + 0.5) * a, 0.0]);
            }
        }
        let n = pos.len();
        (pos, vec![r; n], vec![2.0; n])
    }

    #[test]
    fn a_rigidly_moving_lattice_gives_its_packing_velocity_and_no_temperature() {
        let (a, r) = (0.25, 0.1);
        let (mut pos, radius, mass) = lattice(a, r);
        let u = [0.3, -0.2, 0.0];
        let mut f = FlowField::new(&[4, 2], [0.0, 4.0, 0.0, 2.0], 2, 1.0, true, 0.5).unwrap();
        for k in 0..30 {
            let t = 0.1 * k as f64;
            // Moves along x by whole lattice spacings (periodic in x), so
            // every cell holds the same grains' worth at every sample.
            for p in pos.iter_mut() {
                p[0] += a;
            }
            let vel = vec![u; pos.len()];
            f.sample_grains(t, &pos, &vel, &radius, &mass);
        }
        // Samples from t = 0.5 on: k = 5..29.
        assert_eq!(f.samples, 25);
        let phi = PI * r * r / (a * a);
        for iv in 0..2 {
            for ix in 0..4 {
                let c = f.cell(ix, iv);
                assert!((c.packing - phi).abs() < 1e-12, "{c:?}");
                assert!((c.v[0] - u[0]).abs() < 1e-12 && (c.v[1] - u[1]).abs() < 1e-12);
                assert!(c.temperature.abs() < 1e-12);
                // Two full batches, identical: no spread.
                assert!(c.packing_se.abs() < 1e-12 && c.v_se[0].abs() < 1e-12);
            }
        }
        let csv = f.csv();
        assert_eq!(csv.lines().count(), 1 + 8);
        assert!(csv.starts_with("ix,iy,x,y,grain_samples,packing_fraction"));
    }

    #[test]
    fn a_rotating_packing_gives_omega_cross_r_and_its_spread_as_temperature() {
        let (a, r) = (0.25, 0.1);
        let (pos, radius, mass) = lattice(a, r);
        let w = 1.5;
        let centre = [2.0, 1.0];
        // v = ω ẑ × (p − c)
        let vel: Vec<[f64; 3]> = pos
            .iter()
            .map(|p| [-w * (p[1] - centre[1]), w * (p[0] - centre[0]), 0.0])
            .collect();
        let mut f = FlowField::new(&[4, 2], [0.0, 4.0, 0.0, 2.0], 2, 1.0, false, 0.0).unwrap();
        f.sample_grains(0.0, &pos, &vel, &radius, &mass);
        // Cell (0, 0) spans [0, 1] × [0, 1]: its centre of mass is
        // (0.5, 0.5), so V = ω ẑ × ((0.5, 0.5) − (2, 1)) = (0.75, −2.25).
        let c = f.cell(0, 0);
        assert!(
            (c.v[0] - 0.75).abs() < 1e-12 && (c.v[1] + 2.25).abs() < 1e-12,
            "{c:?}"
        );
        // T = m ω² ⟨|p − p̄|²⟩ / d over the cell's 4 × 4 grains: the spread of
        // 4 points a apart along each axis is a² (n² − 1) / 12 = 5 a² / 4.
        let spread = 2.0 * 5.0 * a * a / 4.0;
        let t = 2.0 * w * w * spread / 2.0;
        assert!((c.temperature - t).abs() < 1e-12, "{} {t}", c.temperature);
        // One sample: no batch, no error bars.
        assert!(c.packing_se.is_nan());
    }

    #[test]
    fn spheres_count_by_volume_in_slabs_and_bad_grids_are_refused() {
        // Simple cubic spheres, spacing 1, in a box 2 × 3 × 2 (y depth 3).
        let mut pos = Vec::new();
        for x in 0..2 {
            for y in 0..3 {
                for z in 0..2 {
                    pos.push([x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5]);
                }
            }
        }
        let n = pos.len();
        let mut f = FlowField::new(&[2, 2], [0.0, 2.0, 0.0, 2.0], 3, 3.0, false, 0.0).unwrap();
        f.sample_grains(0.0, &pos, &vec![[0.0; 3]; n], &vec![0.4; n], &vec![1.0; n]);
        let phi = 4.0 / 3.0 * PI * 0.4f64.powi(3);
        assert!((f.cell(1, 1).packing - phi).abs() < 1e-12);
        let e = FlowField::new(&[4], [0.0, 1.0, 0.0, 1.0], 2, 1.0, false, 0.0).unwrap_err();
        assert!(e.to_string().contains("measure.flow_field.cells"), "{e}");
        let e = FlowField::new(&[4, 0], [0.0, 1.0, 0.0, 1.0], 2, 1.0, false, 0.0).unwrap_err();
        assert!(e.to_string().contains("at least 1"), "{e}");
        // Checkpoint bytes round-trip.
        let mut enc = Enc::default();
        f.save(&mut enc);
        let fresh = FlowField::new(&[2, 2], [0.0, 2.0, 0.0, 2.0], 3, 3.0, false, 0.0).unwrap();
        let back = fresh.load(&mut Dec::new(&enc.buf)).unwrap();
        assert_eq!(back, f);
    }
}
