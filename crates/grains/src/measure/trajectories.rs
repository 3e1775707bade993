//! Particle trajectories over one cycle in steady state (seed 002 Fig. 4):
//! every mobile grain's position every `every` steps during the last cycle
//! of the run.

use super::draw::{draw_walls, faint, hv3};
use crate::boundary::Wall;
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::Result;
use crate::io::{write_atomic, Frame};
use crate::render::legend::id_colour;
use crate::view::GrainView;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Trajectories {
    every: u64,
    /// Absolute engine steps of the recorded window [start, end].
    start: u64,
    end: u64,
    /// (id, step, time, xyz), positions as in the engine (wrapped).
    rows: Vec<(u64, u64, f64, [f64; 3])>,
}

impl Trajectories {
    /// Records during the last `window` steps of a run that ends `remaining`
    /// steps from now.
    pub fn new<D: Dim>(view: &GrainView<D>, every: u64, remaining: u64, window: u64) -> Self {
        let end = view.step + remaining;
        Self {
            every: every.max(1),
            start: end.saturating_sub(window).max(view.step),
            end,
            rows: Vec::new(),
        }
    }

    /// Whether [`Self::step`] after engine step `step` records positions.
    pub fn due(&self, step: u64) -> bool {
        (self.start..=self.end).contains(&step) && (step - self.start).is_multiple_of(self.every)
    }

    /// Called after every step.
    pub fn step<D: Dim>(&mut self, view: &GrainView<D>) {
        if !self.due(view.step) {
            return;
        }
        let p = &view.grains;
        for i in 0..p.len() {
            if !p.frozen[i] {
                self.rows
                    .push((p.id[i], view.step, view.time, D::to_xyz(p.pos[i])));
            }
        }
    }

    /// trajectories.csv and trajectories.png (dots over the final state,
    /// one colour per grain, walls at the end time).
    pub fn write<D: Dim>(&self, dir: &Path, last: &Frame, walls: &[Wall<D>]) -> Result<()> {
        let mut csv = format!("# every {} steps\nid,step,time,x,y,z\n", self.every);
        for (id, s, t, x) in &self.rows {
            let _ = writeln!(csv, "{id},{s},{t},{},{},{}", x[0], x[1], x[2]);
        }
        write_atomic(&dir.join("trajectories.csv"), csv.as_bytes())?;
        let mut img = faint(last);
        for (id, _, _, x) in &self.rows {
            let c = img.view.to_pixel(hv3(*x, last.dim));
            img.fill_disk(c, 1.6, id_colour(*id), true);
        }
        draw_walls(&mut img, walls, last.time, [30, 30, 30], 2.0);
        img.save_png(&dir.join("trajectories.png"))
    }
}

/// Checkpoint state (see `runner::checkpointing`).
impl Trajectories {
    pub fn save(&self, e: &mut Enc) {
        e.u64(self.every);
        e.u64(self.start);
        e.u64(self.end);
        e.len(self.rows.len());
        for (id, s, t, x) in &self.rows {
            e.u64(*id);
            e.u64(*s);
            e.f64(*t);
            x.iter().for_each(|v| e.f64(*v));
        }
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let every = d.u64("trajectory interval")?;
        let start = d.u64("trajectory start")?;
        let end = d.u64("trajectory end")?;
        let n = d.len(48, "trajectory rows")?;
        let mut rows = Vec::with_capacity(n);
        for _ in 0..n {
            let id = d.u64("trajectory id")?;
            let s = d.u64("trajectory step")?;
            let t = d.f64("trajectory time")?;
            rows.push((id, s, t, super::tracer::xyz(d, "trajectory position")?));
        }
        Ok(Self {
            every: every.max(1),
            start,
            end,
            rows,
        })
    }
}
