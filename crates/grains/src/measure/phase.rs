//! Phase-resolved snapshots (seed 002 Fig. 1a-d): positions and velocities at
//! given phases φ = 2π f t + φ0 of the first vibrating wall, taken at the
//! first time each phase is reached after the measurement starts; and the
//! displacement picture of Fig. 1e: positions at phase 0 joined to the
//! positions a fixed time (15 ms in the seed) later.

use super::draw::{draw_walls, faint, hv3, in_box};
use super::tracer::xyz;
use crate::boundary::{Motion, Wall};
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::Result;
use crate::io::picture::draw_arrows;
use crate::io::{render_particles, write_atomic, Frame, PictureOptions};
use crate::view::GrainView;
use std::collections::HashMap;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::path::Path;

/// Frequency (Hz) and phase offset (rad) of the first wall that vibrates or
/// oscillates.
pub fn drive<D: Dim>(walls: &[Wall<D>]) -> Option<(f64, f64)> {
    walls.iter().find_map(|w| match &w.motion {
        Motion::Vibrate {
            frequency, phase, ..
        }
        | Motion::Oscillate {
            frequency, phase, ..
        } if *frequency > 0.0 => Some((*frequency, *phase)),
        _ => None,
    })
}

/// Number of cycles of the drive at time t (phase / 2π), unwrapped.
fn cycles(f: f64, phase0: f64, t: f64) -> f64 {
    f * t + phase0 / TAU
}

/// A grain's id, start and end positions.
type Moved = (u64, [f64; 3], [f64; 3]);

#[derive(Clone, Debug)]
pub struct PhaseSnapshots {
    freq: f64,
    phase0: f64,
    /// Target phases (rad) in [0, 2π).
    targets: Vec<f64>,
    taken: Vec<Option<Frame>>,
    /// Seconds a velocity is drawn for (segment length = |v| · this).
    segment_time: f64,
    /// Fig. 1e interval (s); `None`: no displacement picture.
    after: Option<f64>,
    /// Time the reference (phase 0) positions were taken, and them by id.
    disp_from: Option<(f64, HashMap<u64, [f64; 3]>)>,
    disp: Option<Vec<Moved>>,
    /// Time the measurement started (the walls' "starting position").
    t_start: f64,
    prev: f64,
}

impl PhaseSnapshots {
    /// `None` when the scenario has no vibrating wall.
    pub fn begin<D: Dim>(
        view: &GrainView<D>,
        phases: &[f64],
        segment_time: Option<f64>,
        after: Option<f64>,
    ) -> Option<Self> {
        let (freq, phase0) = drive(view.walls)?;
        Some(Self {
            freq,
            phase0,
            targets: phases.iter().map(|p| p.rem_euclid(TAU)).collect(),
            taken: vec![None; phases.len()],
            segment_time: segment_time.unwrap_or(0.1 / freq),
            after,
            disp_from: None,
            disp: None,
            t_start: view.time,
            prev: cycles(freq, phase0, view.time),
        })
    }

    /// Whether target phase `k` is first reached at drive cycle count `c`.
    fn reached(&self, k: usize, c: f64) -> bool {
        let s = self.targets[k] / TAU;
        self.taken[k].is_none() && (c - s).floor() > (self.prev - s).floor()
    }

    /// Whether [`Self::step`] at time `t` reads the grains (a snapshot or a
    /// displacement end is due), so that a decomposed run gathers them only
    /// then.
    pub fn due(&self, t: f64) -> bool {
        let c = cycles(self.freq, self.phase0, t);
        let disp = match (self.after, &self.disp_from) {
            (Some(_), None) => c.floor() > self.prev.floor(),
            (Some(after), Some((t0, _))) => self.disp.is_none() && t >= t0 + after,
            (None, _) => false,
        };
        disp || (0..self.targets.len()).any(|k| self.reached(k, c))
    }

    /// Called after every step.
    pub fn step<D: Dim>(&mut self, view: &GrainView<D>) {
        let c = cycles(self.freq, self.phase0, view.time);
        for k in 0..self.targets.len() {
            if self.reached(k, c) {
                self.taken[k] = Some(view.frame());
            }
        }
        if let Some(after) = self.after {
            if self.disp_from.is_none() && c.floor() > self.prev.floor() {
                let f = view.frame();
                let map = f.id.iter().copied().zip(f.pos.iter().copied()).collect();
                self.disp_from = Some((view.time, map));
            } else if let Some((t0, from)) = &self.disp_from {
                if self.disp.is_none() && view.time >= t0 + after {
                    let f = view.frame();
                    let rows =
                        f.id.iter()
                            .zip(&f.pos)
                            .filter_map(|(id, p)| from.get(id).map(|s| (*id, *s, *p)))
                            .collect();
                    self.disp = Some(rows);
                }
            }
        }
        self.prev = c;
    }

    /// Writes phase_<k>.csv and phase_<k>.png per target phase reached, and
    /// phase_displacement.{csv,png}.
    pub fn write<D: Dim>(&self, dir: &Path, walls: &[Wall<D>]) -> Result<()> {
        for (k, snap) in self.taken.iter().enumerate() {
            let Some(full) = snap else { continue };
            let mut csv = format!(
                "# phase = {} rad, time = {} s\nid,x,y,z,vx,vy,vz,radius\n",
                self.targets[k], full.time
            );
            for i in 0..full.len() {
                let (p, v) = (full.pos[i], full.vel[i]);
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{},{},{},{}",
                    full.id[i], p[0], p[1], p[2], v[0], v[1], v[2], full.radius[i]
                );
            }
            write_atomic(&dir.join(format!("phase_{k}.csv")), csv.as_bytes())?;
            let f = &in_box(full);
            let mut img = render_particles(f, &PictureOptions::default());
            draw_walls(&mut img, walls, self.t_start, [185, 185, 185], 2.0);
            draw_walls(&mut img, walls, f.time, [30, 30, 30], 3.0);
            for i in 0..f.len() {
                let a = hv3(f.pos[i], f.dim);
                let v = hv3(f.vel[i], f.dim);
                let b = [
                    a[0] + v[0] * self.segment_time,
                    a[1] + v[1] * self.segment_time,
                ];
                let (pa, pb) = (img.view.to_pixel(a), img.view.to_pixel(b));
                img.draw_segment(pa, pb, 2.0, [200, 30, 30]);
            }
            img.save_png(&dir.join(format!("phase_{k}.png")))?;
        }
        if let (Some(rows), Some(after)) = (&self.disp, self.after) {
            let mut csv = format!("# interval = {after} s\nid,x0,y0,z0,x1,y1,z1\n");
            for (id, s, e) in rows {
                let _ = writeln!(
                    csv,
                    "{id},{},{},{},{},{},{}",
                    s[0], s[1], s[2], e[0], e[1], e[2]
                );
            }
            write_atomic(&dir.join("phase_displacement.csv"), csv.as_bytes())?;
            if let Some(f) = self.taken.iter().flatten().next() {
                let dim = f.dim;
                let mut img = faint(f);
                let from: Vec<[f64; 2]> = rows.iter().map(|r| hv3(r.1, dim)).collect();
                let to: Vec<[f64; 2]> = rows.iter().map(|r| hv3(r.2, dim)).collect();
                for p in &from {
                    let c = img.view.to_pixel(*p);
                    img.fill_disk(c, 2.5, [30, 30, 30], true);
                }
                draw_arrows(&mut img, &from, &to, [200, 30, 30]);
                img.save_png(&dir.join("phase_displacement.png"))?;
            }
        }
        Ok(())
    }
}

fn save_xyz(e: &mut Enc, x: &[f64; 3]) {
    x.iter().for_each(|v| e.f64(*v));
}

fn save_opt_f64(e: &mut Enc, v: Option<f64>) {
    e.bool(v.is_some());
    e.f64(v.unwrap_or(0.0));
}

fn load_opt_f64(d: &mut Dec, what: &str) -> DecResult<Option<f64>> {
    let some = d.bool(what)?;
    let v = d.f64(what)?;
    Ok(some.then_some(v))
}

/// A snapshot frame, every field exact.
fn save_frame(e: &mut Enc, f: &Frame) {
    e.u64(f.step);
    e.f64(f.time);
    e.len(f.dim);
    save_xyz(e, &f.box_lo);
    save_xyz(e, &f.box_hi);
    f.periodic.iter().for_each(|p| e.bool(*p));
    e.len(f.id.len());
    for i in 0..f.id.len() {
        e.u64(f.id[i]);
        e.u32(f.kind[i]);
        save_xyz(e, &f.pos[i]);
        save_xyz(e, &f.vel[i]);
        save_xyz(e, &f.omega[i]);
        e.f64(f.radius[i]);
    }
}

fn load_frame(d: &mut Dec) -> DecResult<Frame> {
    let step = d.u64("snapshot step")?;
    let time = d.f64("snapshot time")?;
    let dim = d.u64("snapshot dimension")? as usize;
    let box_lo = xyz(d, "snapshot box")?;
    let box_hi = xyz(d, "snapshot box")?;
    let periodic = [
        d.bool("snapshot periodicity")?,
        d.bool("snapshot periodicity")?,
        d.bool("snapshot periodicity")?,
    ];
    let n = d.len(8 + 4 + 10 * 8, "snapshot grains")?;
    let mut f = Frame {
        step,
        time,
        dim,
        box_lo,
        box_hi,
        periodic,
        id: Vec::with_capacity(n),
        kind: Vec::with_capacity(n),
        pos: Vec::with_capacity(n),
        vel: Vec::with_capacity(n),
        omega: Vec::with_capacity(n),
        radius: Vec::with_capacity(n),
        body: None,
        orientation: None,
        mass: Vec::new(),
    };
    for _ in 0..n {
        f.id.push(d.u64("snapshot id")?);
        f.kind.push(d.u32("snapshot type")?);
        f.pos.push(xyz(d, "snapshot position")?);
        f.vel.push(xyz(d, "snapshot velocity")?);
        f.omega.push(xyz(d, "snapshot angular velocity")?);
        f.radius.push(d.f64("snapshot radius")?);
    }
    Ok(f)
}

/// Checkpoint state (see `runner::checkpointing`).
impl PhaseSnapshots {
    pub fn save(&self, e: &mut Enc) {
        e.f64(self.freq);
        e.f64(self.phase0);
        e.f64s(&self.targets);
        for t in &self.taken {
            e.bool(t.is_some());
            if let Some(f) = t {
                save_frame(e, f);
            }
        }
        e.f64(self.segment_time);
        save_opt_f64(e, self.after);
        e.bool(self.disp_from.is_some());
        if let Some((t0, from)) = &self.disp_from {
            e.f64(*t0);
            let mut ids: Vec<_> = from.keys().copied().collect();
            ids.sort_unstable();
            e.len(ids.len());
            for id in ids {
                e.u64(id);
                save_xyz(e, &from[&id]);
            }
        }
        e.bool(self.disp.is_some());
        if let Some(rows) = &self.disp {
            e.len(rows.len());
            for (id, a, b) in rows {
                e.u64(*id);
                save_xyz(e, a);
                save_xyz(e, b);
            }
        }
        e.f64(self.t_start);
        e.f64(self.prev);
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let freq = d.f64("phase frequency")?;
        let phase0 = d.f64("phase offset")?;
        let targets = d.f64s("phase targets")?;
        let mut taken = Vec::with_capacity(targets.len());
        for _ in 0..targets.len() {
            taken.push(if d.bool("snapshot flag")? {
                Some(load_frame(d)?)
            } else {
                None
            });
        }
        let segment_time = d.f64("segment time")?;
        let after = load_opt_f64(d, "displacement interval")?;
        let disp_from = if d.bool("displacement reference flag")? {
            let t0 = d.f64("displacement reference time")?;
            let n = d.len(32, "displacement reference grains")?;
            let mut map = HashMap::with_capacity(n);
            for _ in 0..n {
                let id = d.u64("displacement reference id")?;
                map.insert(id, xyz(d, "displacement reference position")?);
            }
            Some((t0, map))
        } else {
            None
        };
        let disp = if d.bool("phase displacement flag")? {
            let n = d.len(56, "phase displacement rows")?;
            let mut rows = Vec::with_capacity(n);
            for _ in 0..n {
                let id = d.u64("phase displacement id")?;
                let a = xyz(d, "phase displacement start")?;
                rows.push((id, a, xyz(d, "phase displacement end")?));
            }
            Some(rows)
        } else {
            None
        };
        Ok(Self {
            freq,
            phase0,
            targets,
            taken,
            segment_time,
            after,
            disp_from,
            disp,
            t_start: d.f64("measurement start")?,
            prev: d.f64("phase cycles")?,
        })
    }
}
