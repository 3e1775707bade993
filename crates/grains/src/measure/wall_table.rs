//! walls.csv: the force and torque the grains put on each mesh wall, and
//! each servo wall's position and measured pressure, one row per output
//! step (written only when the scenario has a mesh or a servo wall).

use crate::dim::Dim;
use crate::error::Result;
use crate::io::ThermoWriter;
use crate::view::GrainView;
use std::path::Path;

/// The open walls.csv of a run.
pub(crate) struct WallTable {
    writer: ThermoWriter,
    last_step: Option<u64>,
}

impl WallTable {
    /// Creates `dir/walls.csv` with columns `step, time`, then for each
    /// mesh wall `NAME_fx, NAME_fy, NAME_fz` (the force on it) and
    /// `NAME_tx, NAME_ty, NAME_tz` (the torque about its load point); `None`
    /// then for each servo wall `NAME_offset` (m, its displacement along
    /// its normal), `NAME_speed` (m/s) and `NAME_pressure` (Pa; 2D N/m,
    /// measured at the last force evaluation); `None` when no wall is a
    /// mesh or a servo.
    pub(crate) fn create<D: Dim>(dir: &Path, view: &GrainView<D>) -> Result<Option<Self>> {
        let loads = view.mesh_loads();
        let servos = view.walls.iter().filter(|w| w.motion.is_servo());
        if loads.is_empty() && servos.clone().next().is_none() {
            return Ok(None);
        }
        let mut columns = vec!["step".to_string(), "time".to_string()];
        for l in &loads {
            let name = &view.walls[l.wall].name;
            for c in ["fx", "fy", "fz", "tx", "ty", "tz"] {
                columns.push(format!("{name}_{c}"));
            }
        }
        for w in servos {
            for c in ["offset", "speed", "pressure"] {
                columns.push(format!("{}_{c}", w.name));
            }
        }
        let columns: Vec<&str> = columns.iter().map(String::as_str).collect();
        let path = dir.join("walls.csv");
        // A run resumed from a checkpoint keeps the rows written up to its
        // step (numbers in shortest round-trip form: read and written
        // again, the same text) and drops any an interrupted run wrote
        // after it.
        let earlier: Vec<Vec<f64>> = match (view.step, std::fs::read_to_string(&path)) {
            (1.., Ok(text)) => text
                .lines()
                .skip(1)
                .filter_map(|l| l.split(',').map(|x| x.parse().ok()).collect())
                .filter(|row: &Vec<f64>| row.len() == columns.len() && row[0] <= view.step as f64)
                .collect(),
            _ => Vec::new(),
        };
        let mut writer = ThermoWriter::create(&path, &columns)?;
        for row in &earlier {
            writer.write_row(row)?;
        }
        Ok(Some(Self {
            writer,
            last_step: None,
        }))
    }

    /// A row for the engine's step (once per step).
    pub(crate) fn record<D: Dim>(&mut self, view: &GrainView<D>) -> Result<()> {
        if self.last_step == Some(view.step) {
            return Ok(());
        }
        self.last_step = Some(view.step);
        let mut row = vec![view.step as f64, view.time];
        for l in view.mesh_loads() {
            row.extend(l.force.to_array());
            row.extend(l.torque.to_array());
        }
        for s in view.walls.iter().filter_map(|w| w.motion.servo_state()) {
            row.extend(s.to_array());
        }
        self.writer.write_row(&row)
    }
}
