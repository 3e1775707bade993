//! The coarse-grained fields of a window as a dict of numpy arrays shaped
//! like the grid.

use crate::errors::internal;
use grains::measure::fields::Fields;
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

const AXES: [&str; 3] = ["x", "y", "z"];

/// `f`'s arrays, each of shape `grid + components`: the grid's points are
/// indexed [i_a, i_b, …] along its axes in order (x before y before z),
/// where the library runs the first axis fastest (VTK's order).
pub(crate) fn fields_dict<'py>(py: Python<'py>, f: &Fields) -> PyResult<Bound<'py, PyDict>> {
    let g = &f.grid;
    let d = g.dim;
    let n = g.len();
    // The place in C order of each point, which the library numbers with
    // its first axis fastest.
    let mut strides = vec![0; g.cells.len()];
    let mut stride = 1;
    for k in (0..g.cells.len()).rev() {
        strides[k] = stride;
        stride *= g.cells[k];
    }
    let place: Vec<usize> = (0..n)
        .map(|mut p| {
            let mut at = 0;
            for (k, &c) in g.cells.iter().enumerate() {
                at += (p % c) * strides[k];
                p /= c;
            }
            at
        })
        .collect();
    let array = |width: &[usize], get: &dyn Fn(usize, &mut [f64])| -> PyResult<_> {
        let w: usize = width.iter().product();
        let mut data = vec![0.0; n * w];
        for (p, &at) in place.iter().enumerate() {
            get(p, &mut data[at * w..(at + 1) * w]);
        }
        let shape: Vec<usize> = g.cells.iter().chain(width).copied().collect();
        let a = ArrayD::from_shape_vec(IxDyn(&shape), data)
            .map_err(|e| internal(Box::new(e.to_string())))?;
        Ok(a.into_pyarray(py))
    };
    let scalar = |v: &[f64]| array(&[], &|p, o| o[0] = v[p]);
    let vector = |v: &[[f64; 3]]| array(&[d], &|p, o| o.copy_from_slice(&v[p][..d]));
    let tensor = |v: &[[[f64; 3]; 3]]| {
        array(&[d, d], &|p, o| {
            for (a, row) in v[p][..d].iter().enumerate() {
                o[a * d..(a + 1) * d].copy_from_slice(&row[..d]);
            }
        })
    };
    let out = PyDict::new(py);
    let names: Vec<&str> = g.axes.iter().map(|&a| AXES[a]).collect();
    out.set_item("axes", names.clone())?;
    for (k, name) in names.iter().enumerate() {
        let h = g.spacing(k);
        let a = g.axes[k];
        let coords: Vec<f64> = (0..g.cells[k])
            .map(|i| g.lo[a] + (i as f64 + 0.5) * h)
            .collect();
        out.set_item(*name, coords.into_pyarray(py))?;
    }
    out.set_item("point_volume", g.point_volume())?;
    out.set_item("samples", f.samples)?;
    out.set_item("times", f.times)?;
    out.set_item("density", scalar(&f.density)?)?;
    out.set_item("packing_fraction", scalar(&f.packing_fraction)?)?;
    out.set_item("velocity", vector(&f.velocity)?)?;
    out.set_item("temperature", scalar(&f.temperature)?)?;
    out.set_item("kinetic_stress", tensor(&f.kinetic_stress)?)?;
    out.set_item("contact_stress", tensor(&f.contact_stress)?)?;
    out.set_item("stress", tensor(&f.stress)?)?;
    out.set_item("coordination", scalar(&f.coordination)?)?;
    out.set_item("fabric", tensor(&f.fabric)?)?;
    Ok(out)
}
