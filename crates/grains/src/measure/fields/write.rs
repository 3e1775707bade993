//! The fields' files: `fields/fields_NNNNN.vti` (VTK image data, one per
//! window) listed in `fields.pvd`, and `fields/fields_NNNNN.csv` for a
//! profile along one axis or the single box.

use super::cg::Fields;
use crate::error::{Error, Result};
use crate::io::vti::{write_vti, PointArray};
use crate::io::{push_num, write_atomic, PvdCollection};
use std::path::Path;

const AXES: [&str; 3] = ["x", "y", "z"];

/// Writes every window.
pub fn write_windows(dir: &Path, windows: &[Fields]) -> Result<()> {
    let sub = dir.join("fields");
    std::fs::create_dir_all(&sub).map_err(|e| Error::io(&sub, e))?;
    let mut pvd = PvdCollection::new(dir.join("fields.pvd"));
    for (k, f) in windows.iter().enumerate() {
        let name = format!("fields/fields_{k:05}.vti");
        let g = &f.grid;
        let mut points = [1; 3];
        let mut spacing = [1.0; 3];
        for (a, h) in spacing.iter_mut().enumerate().take(g.dim) {
            *h = g.hi[a] - g.lo[a];
        }
        for (i, &a) in g.axes.iter().enumerate() {
            points[a] = g.cells[i];
            spacing[a] = g.spacing(i);
        }
        let origin = f.points.first().copied().unwrap_or_default();
        let scalar = |v: &[f64]| v.to_vec();
        let vector = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<_>>();
        let tensor = |v: &[[[f64; 3]; 3]]| v.iter().flatten().flatten().copied().collect();
        let arrays = [
            array("density", 1, scalar(&f.density)),
            array("packing_fraction", 1, scalar(&f.packing_fraction)),
            array("velocity", 3, vector(&f.velocity)),
            array("temperature", 1, scalar(&f.temperature)),
            array("kinetic_stress", 9, tensor(&f.kinetic_stress)),
            array("contact_stress", 9, tensor(&f.contact_stress)),
            array("stress", 9, tensor(&f.stress)),
            array("coordination", 1, scalar(&f.coordination)),
            array("fabric", 9, tensor(&f.fabric)),
        ];
        write_vti(
            &dir.join(&name),
            points,
            origin,
            spacing,
            f.times.1,
            &arrays,
        )?;
        pvd.add(f.times.1, name)?;
        if g.axes.len() <= 1 {
            let csv = dir.join(format!("fields/fields_{k:05}.csv"));
            write_atomic(&csv, csv_string(f).as_bytes())?;
        }
    }
    Ok(())
}

fn array(name: &str, components: usize, values: Vec<f64>) -> PointArray<'_> {
    PointArray {
        name,
        components,
        values,
    }
}

/// One row per point: its coordinate along the grid's axis (absent for
/// the box), then every field, tensors as their d × d components.
pub fn csv_string(f: &Fields) -> String {
    let d = f.grid.dim;
    let mut head: Vec<String> = f.grid.axes.iter().map(|&a| AXES[a].to_string()).collect();
    head.extend(["density", "packing_fraction"].map(String::from));
    head.extend((0..d).map(|a| format!("v{}", AXES[a])));
    head.push("temperature".into());
    for t in ["stress", "kinetic_stress", "contact_stress", "fabric"] {
        for a in &AXES[..d] {
            for b in &AXES[..d] {
                head.push(format!("{t}_{a}{b}"));
            }
        }
    }
    head.push("coordination".into());
    let mut s = head.join(",");
    s.push('\n');
    for i in 0..f.points.len() {
        let mut row: Vec<f64> = f.grid.axes.iter().map(|&a| f.points[i][a]).collect();
        row.push(f.density[i]);
        row.push(f.packing_fraction[i]);
        row.extend(&f.velocity[i][..d]);
        row.push(f.temperature[i]);
        for t in [&f.stress, &f.kinetic_stress, &f.contact_stress, &f.fabric] {
            for r in &t[i][..d] {
                row.extend(&r[..d]);
            }
        }
        row.push(f.coordination[i]);
        for (k, v) in row.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            push_num(&mut s, *v);
        }
        s.push('\n');
    }
    s
}
