//! The files a run writes in its output directory.

use crate::boundary::Wall;
pub use crate::checkpoint::run::OutputState;
use crate::comm::Comm;
use crate::dim::Dim;
use crate::error::Error;
use crate::error::Result;
use crate::io::contacts_out::ContactSeries;
use crate::io::{write_atomic, BodyTable, DumpWriter, Frame, Num, ThermoWriter, VtkSeries};
use crate::md::Md;
use crate::measure::draw::in_box;
use crate::measure::{granular_temperature, DisplacementField};
use crate::render::{Painter, Scene, StillOptions};
use crate::scenario::schema::{FramesLayout, OutputSpec};
use crate::scenario::{Loaded, Resolved};
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Columns of thermo.csv.
pub const THERMO_COLUMNS: [&str; 7] = [
    "step",
    "time",
    "kinetic_energy",
    "rotational_energy",
    "granular_temperature",
    "contacts",
    "max_overlap",
];

/// thermo.csv: a fresh table, or one reopened for appending after a resume.
pub(crate) enum Thermo {
    Fresh(ThermoWriter),
    Appended { path: PathBuf, file: std::fs::File },
}

impl Thermo {
    pub(crate) fn write_row(&mut self, values: &[f64]) -> Result<()> {
        match self {
            Thermo::Fresh(w) => w.write_row(values),
            Thermo::Appended { path, file } => {
                use std::io::Write as _;
                let mut line = String::new();
                for (k, v) in values.iter().enumerate() {
                    if k > 0 {
                        line.push(',');
                    }
                    let _ = write!(line, "{}", Num(*v));
                }
                line.push('\n');
                file.write_all(line.as_bytes())
                    .map_err(|e| Error::io(path.as_path(), e))
            }
        }
    }
}

/// The frame series of a run (None without frames): fresh, or continuing a
/// checkpoint's `resumed` entries; in pieces (of one rank until
/// [`Outputs::set_ranks`]) when the scenario asks.
pub(crate) fn frame_series(
    dir: &Path,
    spec: &OutputSpec,
    resumed: Option<&[(f64, String)]>,
) -> Result<Option<VtkSeries>> {
    if spec.movie && !spec.frames {
        return Err(Error::input(
            "output.movie = true needs output.frames = true: the movie is drawn from the frames",
        ));
    }
    if !spec.frames {
        return Ok(None);
    }
    let series = match resumed {
        Some(entries) => VtkSeries::resume(dir, entries)?,
        None => VtkSeries::new(dir)?,
    };
    Ok(Some(match spec.frames_layout {
        FramesLayout::Pieces => series.in_pieces(1),
        FramesLayout::Gathered => series,
    }))
}

/// Whether each of `ranks` ranks writes its own piece of every frame (in
/// pieces on one rank, the frame series writes the single piece itself).
fn in_pieces(spec: &OutputSpec, ranks: usize) -> bool {
    spec.frames && spec.frames_layout == FramesLayout::Pieces && ranks > 1
}

/// One rank's pieces of the frames of a distributed run (MD or DSMC):
/// with frames in pieces on several ranks, each rank writes its own grains
/// at an output step; otherwise nothing.
pub(crate) struct Pieces {
    dir: PathBuf,
    rank: usize,
    on: bool,
}

impl Pieces {
    pub(crate) fn new(spec: &OutputSpec, dir: &Path, comm: &dyn Comm) -> Self {
        Self {
            dir: dir.to_path_buf(),
            rank: comm.rank(),
            on: in_pieces(spec, comm.size()),
        }
    }

    /// Writes this rank's piece, `frame()` (built only when pieces are
    /// written).
    pub(crate) fn write(&self, frame: impl FnOnce() -> Frame) -> Result<()> {
        match self.on {
            true => crate::io::write_piece(&self.dir, &frame(), self.rank),
            false => Ok(()),
        }
    }
}

/// The end-of-run pictures of a DSMC run (a gas: no walls but the box):
/// scene.json with the frames, final.png, and the movie when asked.
pub(crate) fn finish_gas(dir: &Path, spec: &OutputSpec, last: &Frame) -> Result<()> {
    let scene = Scene::bare(last);
    if spec.frames {
        scene.write(dir)?;
    }
    if spec.picture {
        Painter::new(&[last], &StillOptions::default())
            .paint(last, &[])
            .save_png(&dir.join("final.png"))?;
    }
    if spec.movie {
        crate::render::make_movie(dir, &Default::default())?;
    }
    Ok(())
}

/// The files a run writes as it goes (thermo.csv, frames, the LAMMPS
/// dump), MD or DSMC, and what it draws at the end.
pub struct Outputs {
    dir: PathBuf,
    thermo: Thermo,
    frames: Option<VtkSeries>,
    dump: Option<DumpWriter>,
    picture: bool,
    movie: bool,
    last_step: Option<u64>,
    contacts: Option<ContactSeries>,
    /// bodies.csv, written at each output step of a run with rigid bodies.
    bodies: BodyTable,
}

impl Outputs {
    /// The files of an MD run.
    pub fn create(dir: &Path, spec: &OutputSpec) -> Result<Self> {
        Self::with_columns(dir, spec, &THERMO_COLUMNS, spec.dump)
    }

    /// Fresh files with thermo columns `columns`; a dump when `dump`.
    pub(crate) fn with_columns(
        dir: &Path,
        spec: &OutputSpec,
        columns: &[&str],
        dump: bool,
    ) -> Result<Self> {
        Ok(Self {
            dir: dir.to_path_buf(),
            thermo: Thermo::Fresh(ThermoWriter::create(&dir.join("thermo.csv"), columns)?),
            frames: frame_series(dir, spec, None)?,
            dump: if dump {
                Some(DumpWriter::create(&dir.join("dump.lammpstrj"))?)
            } else {
                None
            },
            picture: spec.picture,
            movie: spec.movie,
            last_step: None,
            contacts: contact_series(dir, spec)?,
            bodies: BodyTable::new(dir),
        })
    }

    /// Frames in pieces come from `ranks` ranks (each writes its own piece).
    pub fn set_ranks(&mut self, ranks: usize) {
        if let Some(f) = self.frames.as_mut() {
            f.set_ranks(ranks);
        }
    }

    /// Where the files stand now (every row and frame is flushed when written).
    pub fn state(&self) -> Result<OutputState> {
        let len = |p: &Path| {
            std::fs::metadata(p)
                .map(|m| m.len())
                .map_err(|e| Error::io(p, e))
        };
        Ok(OutputState {
            thermo_len: len(&self.dir.join("thermo.csv"))?,
            dump_len: match &self.dump {
                Some(d) => Some(len(d.path())?),
                None => None,
            },
            frames: self
                .frames
                .as_ref()
                .map(|f| f.collection.entries.clone())
                .unwrap_or_default(),
            last_step: self.last_step,
        })
    }

    /// Reopens the files of an interrupted run, cut back to `state`.
    pub fn resume(dir: &Path, spec: &OutputSpec, state: &OutputState) -> Result<Self> {
        let cut = |p: &Path, len: u64| -> Result<std::fs::File> {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(p)
                .map_err(|e| Error::io(p, e))?;
            let have = f.metadata().map_err(|e| Error::io(p, e))?.len();
            if have < len {
                return Err(Error::input(format!(
                    "{}: {have} bytes, shorter than the {len} bytes the checkpoint saw; \
                     the run directory was changed after the checkpoint",
                    p.display()
                )));
            }
            f.set_len(len).map_err(|e| Error::io(p, e))?;
            Ok(f)
        };
        let thermo_path = dir.join("thermo.csv");
        cut(&thermo_path, state.thermo_len)?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&thermo_path)
            .map_err(|e| Error::io(&thermo_path, e))?;
        let dump = match (spec.dump, state.dump_len) {
            (true, Some(len)) => {
                let p = dir.join("dump.lammpstrj");
                cut(&p, len)?;
                Some(DumpWriter::append(&p)?)
            }
            _ => None,
        };
        let frames = frame_series(dir, spec, Some(&state.frames))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            thermo: Thermo::Appended {
                path: thermo_path,
                file,
            },
            frames,
            dump,
            picture: spec.picture,
            movie: spec.movie,
            last_step: state.last_step,
            contacts: match spec.contacts {
                true => Some(ContactSeries::resume(
                    dir,
                    state.frames.last().map(|e| e.0),
                )?),
                false => None,
            },
            bodies: BodyTable::resume(dir, state.last_step),
        })
    }

    /// One output step of an MD run: its thermo row, frame and dump
    /// snapshot.
    pub fn record_md<D: Dim>(&mut self, md: &Md<D>) -> Result<()> {
        let mut frame = md.frame();
        if self.contacts.is_some() {
            // With the contacts, the frames hold all `grains cg` reads.
            frame.mass = md.view().grains.mass.to_vec();
        }
        let row = [
            md.step as f64,
            md.time,
            md.kinetic_energy(),
            md.rotational_energy(),
            granular_temperature(&md.particles),
            md.stats.contacts as f64,
            md.stats.max_overlap,
        ];
        if let Some(c) = self
            .contacts
            .as_mut()
            .filter(|_| self.last_step != Some(md.step))
        {
            c.write(&crate::measure::fields::snapshot(&md.view()))?;
        }
        if let Some(rows) = md.body_rows().filter(|_| self.last_step != Some(md.step)) {
            self.bodies.write(md.step, md.time, &rows)?;
        }
        // What a later `grains movie` or `grains view` needs besides the
        // frames (written again at the end, with any walls removed).
        self.record(&row, &frame, |f| Some(Scene::new(&md.walls, f)))
    }

    /// One output step: a thermo row, a frame, a dump snapshot, once per
    /// step; before the first frame, the `scene` of the run when it has one.
    pub fn record(
        &mut self,
        row: &[f64],
        frame: &Frame,
        scene: impl FnOnce(&Frame) -> Option<Scene>,
    ) -> Result<()> {
        if self.last_step == Some(frame.step) {
            return Ok(());
        }
        if self.last_step.is_none() && self.frames.is_some() {
            if let Some(scene) = scene(frame) {
                scene.write(&self.dir)?;
            }
        }
        self.last_step = Some(frame.step);
        self.thermo.write_row(row)?;
        if let Some(f) = &mut self.frames {
            f.write(frame)?;
        }
        if let Some(d) = &mut self.dump {
            d.write(frame)?;
        }
        Ok(())
    }

    /// The final picture and measurement files. (The final state was
    /// recorded as the last frame by the run loop.)
    pub fn finish<D: Dim>(
        &mut self,
        last: &Frame,
        walls: &[Wall<D>],
        displacement: Option<&DisplacementField>,
    ) -> Result<()> {
        let scene = Scene::new(walls, last);
        if self.frames.is_some() {
            scene.write(&self.dir)?;
        }
        if self.picture {
            let shown = in_box(last);
            Painter::new(&[&shown], &StillOptions::default())
                .paint(&shown, &scene.wires(last.time))
                .save_png(&self.dir.join("final.png"))?;
        }
        if let Some(field) = displacement {
            let rows = field.displacements();
            let mut csv = String::from("id,x0,y0,z0,x1,y1,z1\n");
            for r in &rows {
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{},{},{}",
                    r.id, r.start[0], r.start[1], r.start[2], r.end[0], r.end[1], r.end[2]
                );
            }
            write_atomic(&self.dir.join("displacement.csv"), csv.as_bytes())?;
            crate::measure::displacement_draw::picture(&rows, field.t0, last, walls)
                .save_png(&self.dir.join("displacement.png"))?;
        }
        if self.movie {
            crate::render::make_movie(&self.dir, &Default::default())?;
        }
        Ok(())
    }

    pub fn write_summary(&self, summary: &Value) -> Result<()> {
        let text = serde_json::to_string_pretty(summary).expect("JSON values always serialize");
        write_atomic(&self.dir.join("summary.json"), text.as_bytes())
    }
}

/// The contact series when `output.contacts` asks for it.
fn contact_series(dir: &Path, spec: &OutputSpec) -> Result<Option<ContactSeries>> {
    spec.contacts.then(|| ContactSeries::new(dir)).transpose()
}

/// The summary scalars every MD run reports: what ran, how long it took
/// (`stepped` steps of this process's timing) and the final energies.
pub fn md_summary<D: Dim>(
    loaded: &Loaded,
    md: &Md<D>,
    resolved: &Resolved,
    steps: u64,
    stepped: u64,
    wall_seconds: f64,
) -> Map<String, Value> {
    let updates = (stepped.max(1) as f64) * md.particles.n_mobile().max(1) as f64;
    let mut summary = Map::new();
    summary.insert("scenario".into(), json!(loaded.scenario.name));
    summary.insert("dimension".into(), json!(D::NAME));
    summary.insert("particles".into(), json!(md.particles.n_owned()));
    summary.insert("steps".into(), json!(steps));
    summary.insert("time".into(), json!(md.time));
    summary.insert("dt".into(), json!(resolved.dt));
    summary.insert("contact_time".into(), json!(resolved.contact_time));
    summary.insert("wall_seconds".into(), json!(wall_seconds));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall_seconds / updates),
    );
    summary.insert("kinetic_energy".into(), json!(md.kinetic_energy()));
    summary.insert("rotational_energy".into(), json!(md.rotational_energy()));
    summary.insert(
        "granular_temperature".into(),
        json!(granular_temperature(&md.particles)),
    );
    summary
}
