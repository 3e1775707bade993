//! Vectors and angular velocities read from scenario keys, checked: the
//! number of components the dimension needs, all finite.

use crate::dim::Dim;
use crate::error::{Error, Result};

/// Reads a vector of `D::D` numbers from the scenario key `key`.
pub fn vector<D: Dim>(key: &str, v: &[f64]) -> Result<D::V> {
    if v.len() != D::D {
        return Err(Error::input(format!(
            "{key} has {} components; a {} scenario needs {}",
            v.len(),
            D::NAME,
            D::D
        )));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(Error::input(format!("{key} contains {x}: must be finite")));
    }
    let mut out = D::zero();
    for (a, x) in v.iter().enumerate() {
        D::set(&mut out, a, *x);
    }
    Ok(out)
}

/// Reads an angular velocity from the scenario key `key`: three numbers
/// in 3D, one (about z) in 2D.
pub fn angular<D: Dim>(key: &str, v: &[f64]) -> Result<D::A> {
    let want = if D::D == 2 { 1 } else { 3 };
    if v.len() != want {
        return Err(Error::input(format!(
            "{key} has {} components; an angular velocity in {} has {want}",
            v.len(),
            D::NAME
        )));
    }
    let mut xyz = [0.0; 3];
    if D::D == 2 {
        xyz[2] = v[0];
    } else {
        xyz.copy_from_slice(v);
    }
    Ok(D::ang_from_xyz(xyz))
}
