//! VTK image data (`.vti`, XML, arrays in the inline binary format of
//! `vtk_binary`): values on a regular grid of points, read by ParaView and
//! VTK's `vtkXMLImageDataReader`.

use super::vtk_binary::f64_array;
use super::{write_atomic, Num};
use crate::error::Result;
use std::fmt::Write as _;
use std::path::Path;

/// One point array: a name, its components per point, and the values
/// (point after point, x fastest).
pub struct PointArray<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: Vec<f64>,
}

/// The text of a `.vti` file of `points[0] × points[1] × points[2]` points
/// from `origin` with `spacing`, its field data holding `TimeValue`.
pub fn vti_string(
    points: [usize; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    time: f64,
    arrays: &[PointArray],
) -> String {
    let extent = format!(
        "0 {} 0 {} 0 {}",
        points[0].saturating_sub(1),
        points[1].saturating_sub(1),
        points[2].saturating_sub(1)
    );
    let mut s = String::from("<?xml version=\"1.0\"?>\n");
    s.push_str("<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    let _ = writeln!(
        s,
        "  <ImageData WholeExtent=\"{extent}\" Origin=\"{} {} {}\" Spacing=\"{} {} {}\">",
        Num(origin[0]),
        Num(origin[1]),
        Num(origin[2]),
        Num(spacing[0]),
        Num(spacing[1]),
        Num(spacing[2])
    );
    s.push_str("    <FieldData>\n");
    let _ = writeln!(
        s,
        "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
        Num(time)
    );
    s.push_str("    </FieldData>\n");
    let _ = writeln!(s, "    <Piece Extent=\"{extent}\">");
    s.push_str("      <PointData>\n");
    for a in arrays {
        f64_array(&mut s, 8, a.name, a.components, a.values.iter().copied());
    }
    s.push_str("      </PointData>\n      <CellData/>\n    </Piece>\n  </ImageData>\n</VTKFile>\n");
    s
}

/// Writes [`vti_string`] atomically to `path`.
pub fn write_vti(
    path: &Path,
    points: [usize; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    time: f64,
    arrays: &[PointArray],
) -> Result<()> {
    write_atomic(
        path,
        vti_string(points, origin, spacing, time, arrays).as_bytes(),
    )
}
