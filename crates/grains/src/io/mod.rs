//! Input and output: VTK frames, LAMMPS dumps and data files, CSV, PNG pictures.
//!
//! Nothing here depends on the engine: writers take a [`Frame`], a neutral
//! snapshot, and readers return plain records.

pub mod atomic;
pub mod bodies_csv;
pub mod contact_records;
pub mod contacts_out;
pub mod contacts_read;
pub mod csv_particles;
pub mod frame;
pub mod lammps_data;
pub mod lammps_dump;
pub mod picture;
pub mod polyline;
pub mod stl;
pub mod thermo;
pub mod vti;
pub mod vtk;
pub mod vtk_binary;
pub mod vtk_read;

pub use atomic::{write_atomic, write_durable, AtomicWriter};
pub use bodies_csv::{BodyRow, BodyTable};
pub use csv_particles::{parse_particles_csv, read_particles_csv, CsvParticle};
pub use frame::Frame;
pub use lammps_data::{
    parse_lammps_data, read_lammps_data, LammpsAtom, LammpsData, LammpsVelocity,
};
pub use lammps_dump::{write_snapshot, DumpWriter};
pub use picture::{
    draw_arrows, render_particles, viridis, world_rect, world_rect_of, Image, PictureOptions, View,
};
pub use thermo::ThermoWriter;
pub use vtk::{pvtp_string, vtp_string, write_piece, PvdCollection, VtkSeries};
pub use vtk_read::{read_collection, read_frame, read_series, FrameEntry};

/// Displays an `f64` with full (round-trip) precision and compactly: plain
/// decimals for moderate magnitudes, scientific notation (`1e-300`) otherwise.
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Num;

    #[test]
    fn num_round_trips_and_stays_short() {
        for v in [
            0.0,
            -0.0,
            1.0,
            100.0,
            0.01,
            1.0 / 3.0,
            1e-300,
            -2.5e-17,
            6.02e23,
            f64::MAX,
            1e-5,
            9.99e15,
        ] {
            let s = Num(v).to_string();
            assert!(s.len() <= 24, "{s}");
            assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
        }
        assert_eq!(Num(100.0).to_string(), "100");
        assert_eq!(Num(1e-300).to_string(), "1e-300");
    }
}
