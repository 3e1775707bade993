//! The files a run writes in its output directory.

use crate::dim::Dim;
use crate::error::Result;
use crate::io::{
    draw_arrows, render_particles, write_atomic, DumpWriter, Frame, PictureOptions, ThermoWriter,
    VtkSeries,
};
use crate::md::Md;
use crate::measure::draw::{faint, in_box};
use crate::measure::DisplacementField;
use crate::scenario::schema::OutputSpec;
use serde_json::Value;
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

pub struct Outputs {
    dir: PathBuf,
    thermo: ThermoWriter,
    frames: Option<VtkSeries>,
    dump: Option<DumpWriter>,
    picture: bool,
    last_step: Option<u64>,
}

impl Outputs {
    pub fn create(dir: &Path, spec: &OutputSpec) -> Result<Self> {
        Ok(Self {
            dir: dir.to_path_buf(),
            thermo: ThermoWriter::create(&dir.join("thermo.csv"), &THERMO_COLUMNS)?,
            frames: if spec.frames {
                Some(VtkSeries::new(dir)?)
            } else {
                None
            },
            dump: if spec.dump {
                Some(DumpWriter::create(&dir.join("dump.lammpstrj"))?)
            } else {
                None
            },
            picture: spec.picture,
            last_step: None,
        })
    }

    /// One output interval: a thermo row, a frame, a dump snapshot.
    pub fn record<D: Dim>(&mut self, md: &Md<D>, frame: &Frame, temperature: f64) -> Result<()> {
        if self.last_step == Some(md.step) {
            return Ok(());
        }
        self.last_step = Some(md.step);
        self.thermo.write_row(&[
            md.step as f64,
            md.time,
            md.particles.kinetic_energy(),
            md.particles.rotational_energy(),
            temperature,
            md.stats.contacts as f64,
            md.stats.max_overlap,
        ])?;
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
    pub fn finish(&mut self, last: &Frame, displacement: Option<&DisplacementField>) -> Result<()> {
        if self.picture {
            render_particles(&in_box(last), &PictureOptions::default())
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
            // Arrows from start to end on the plane of the picture (x and the
            // vertical axis), over the final state drawn faintly.
            let v = last.vertical();
            let from: Vec<[f64; 2]> = rows.iter().map(|r| [r.start[0], r.start[v]]).collect();
            let to: Vec<[f64; 2]> = rows.iter().map(|r| [r.end[0], r.end[v]]).collect();
            let mut img = faint(last);
            draw_arrows(&mut img, &from, &to, [200, 30, 30]);
            img.save_png(&self.dir.join("displacement.png"))?;
        }
        Ok(())
    }

    pub fn write_summary(&self, summary: &Value) -> Result<()> {
        let text = serde_json::to_string_pretty(summary).expect("JSON values always serialize");
        write_atomic(&self.dir.join("summary.json"), text.as_bytes())
    }
}
