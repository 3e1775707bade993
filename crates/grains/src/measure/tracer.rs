//! A tracer grain's trajectory (seed 002 §3, fluidization onset): its
//! position, unwrapped across periodic boundaries, at every sample. Confined
//! to a small region in the solid-like state, exploring the box when fluid.

use super::draw::{faint, hv3};
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::Result;
use crate::io::{write_atomic, Frame};
use crate::view::GrainView;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Tracer {
    pub id: u64,
    /// (time, unwrapped xyz).
    rows: Vec<(f64, [f64; 3])>,
    last: Option<[f64; 3]>,
}

impl Tracer {
    pub fn new(id: u64) -> Self {
        Self {
            id,
            rows: Vec::new(),
            last: None,
        }
    }

    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        let p = &view.grains;
        let Some(i) = (0..p.len()).find(|&i| p.id[i] == self.id) else {
            return;
        };
        let now = p.pos[i];
        let x = match (self.last, self.rows.last()) {
            (Some(last), Some((_, prev))) => {
                let step = D::to_xyz(view.domain.minimum_image(now - D::from_xyz(last)));
                [prev[0] + step[0], prev[1] + step[1], prev[2] + step[2]]
            }
            _ => D::to_xyz(now),
        };
        self.last = Some(D::to_xyz(now));
        if self.rows.last().map(|r| r.0) != Some(view.time) {
            self.rows.push((view.time, x));
        }
    }

    /// Root-mean-square distance of the tracer from its mean position (m):
    /// small when solid-like, of the box size when fluid-like.
    pub fn rms_spread(&self) -> f64 {
        let n = self.rows.len();
        if n == 0 {
            return 0.0;
        }
        let mut mean = [0.0; 3];
        for (_, x) in &self.rows {
            for a in 0..3 {
                mean[a] += x[a] / n as f64;
            }
        }
        let s: f64 = self
            .rows
            .iter()
            .map(|(_, x)| (0..3).map(|a| (x[a] - mean[a]).powi(2)).sum::<f64>())
            .sum();
        (s / n as f64).sqrt()
    }

    /// tracer.csv and tracer.png (the path over the final state).
    pub fn write(&self, dir: &Path, last: &Frame) -> Result<()> {
        let mut csv = format!("# tracer id = {}\ntime,x,y,z\n", self.id);
        for (t, x) in &self.rows {
            let _ = writeln!(csv, "{t},{},{},{}", x[0], x[1], x[2]);
        }
        write_atomic(&dir.join("tracer.csv"), csv.as_bytes())?;
        let mut img = faint(last);
        let pts: Vec<[f64; 2]> = self
            .rows
            .iter()
            .map(|(_, x)| img.view.to_pixel(hv3(*x, last.dim)))
            .collect();
        for w in pts.windows(2) {
            img.draw_segment(w[0], w[1], 1.5, [200, 30, 30]);
        }
        if let Some(p) = pts.first() {
            img.fill_disk(*p, 5.0, [30, 130, 30], true);
        }
        if let Some(p) = pts.last() {
            img.fill_disk(*p, 5.0, [30, 30, 160], true);
        }
        img.save_png(&dir.join("tracer.png"))
    }
}

/// Checkpoint state (see `runner::checkpointing`).
impl Tracer {
    pub fn save(&self, e: &mut Enc) {
        e.u64(self.id);
        e.len(self.rows.len());
        for (t, x) in &self.rows {
            e.f64(*t);
            x.iter().for_each(|v| e.f64(*v));
        }
        e.bool(self.last.is_some());
        self.last.unwrap_or_default().iter().for_each(|v| e.f64(*v));
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let id = d.u64("tracer id")?;
        let n = d.len(32, "tracer rows")?;
        let mut rows = Vec::with_capacity(n);
        for _ in 0..n {
            let t = d.f64("tracer time")?;
            rows.push((t, xyz(d, "tracer position")?));
        }
        let some = d.bool("tracer last flag")?;
        let last = xyz(d, "tracer last position")?;
        Ok(Self {
            id,
            rows,
            last: some.then_some(last),
        })
    }
}

/// Three f64 (a position as xyz).
pub(crate) fn xyz(d: &mut Dec, what: &str) -> DecResult<[f64; 3]> {
    Ok([d.f64(what)?, d.f64(what)?, d.f64(what)?])
}
