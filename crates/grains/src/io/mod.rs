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
pub mod num;
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
pub use num::{push_num, Num};
pub use picture::{
    draw_arrows, render_particles, viridis, world_rect, world_rect_of, Image, PictureOptions, View,
};
pub use thermo::ThermoWriter;
pub use vtk::{pvtp_string, vtp_string, write_piece, PvdCollection, VtkSeries};
pub use vtk_read::{read_collection, read_frame, read_series, FrameEntry};
