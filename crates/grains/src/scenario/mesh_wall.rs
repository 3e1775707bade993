//! A `shape = { type = "mesh", ... }` wall: its STL file (3D) or polyline
//! file (2D) read and placed.

use super::schema::ShapeSpec;
use super::Loaded;
use crate::boundary::{Mesh, MeshPlacement, Shape};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::polyline::read_polylines;
use crate::io::stl::read_stl;
use std::sync::Arc;

/// `n` finite numbers from the key `key`, widened to three with zeros in
/// front (`lead`) or behind: a 2D mesh lies in z = 0 and turns about z.
fn numbers(key: &str, v: &[f64], n: usize, lead: bool) -> Result<[f64; 3]> {
    if v.len() != n {
        return Err(Error::input(format!(
            "{key} has {} components; it needs {n}",
            v.len()
        )));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(Error::input(format!("{key} contains {x}: must be finite")));
    }
    let mut out = [0.0; 3];
    let at = if lead { 3 - n } else { 0 };
    out[at..at + n].copy_from_slice(v);
    Ok(out)
}

/// The mesh shape of wall `key` from its scenario table (`spec` must be
/// [`ShapeSpec::Mesh`]); errors name the wall, the key or the file and
/// the triangle.
pub(super) fn shape<D: Dim>(key: &str, spec: &ShapeSpec, loaded: &Loaded) -> Result<Shape<D>> {
    let ShapeSpec::Mesh {
        file,
        scale,
        rotate_deg,
        translate,
        load_point,
    } = spec
    else {
        return Err(Error::input(format!("{key}: not a mesh")));
    };
    // In 2D: a point has two components and the turn is one angle (z).
    let (n, turns) = if D::D == 3 { (3, 3) } else { (2, 1) };
    let place = MeshPlacement {
        scale: *scale,
        rotate_deg: match rotate_deg {
            Some(r) => numbers(&format!("{key}.shape.rotate_deg"), r, turns, true)?,
            None => [0.0; 3],
        },
        translate: match translate {
            Some(t) => numbers(&format!("{key}.shape.translate"), t, n, false)?,
            None => [0.0; 3],
        },
    };
    let path = loaded.path(file);
    let name = path.display().to_string();
    let mesh = if D::D == 3 {
        let triangles = read_stl(&path).map_err(|e| Error::input(format!("{key}: {e}")))?;
        Mesh::new(&name, &triangles, &place)
    } else {
        let lines = read_polylines(&path).map_err(|e| Error::input(format!("{key}: {e}")))?;
        Mesh::from_polylines(&name, &lines, &place)
    };
    let mut mesh = mesh.map_err(|e| Error::input(format!("{key}: mesh file {name}: {e}")))?;
    if let Some(p) = load_point {
        let p = numbers(&format!("{key}.shape.load_point"), p, n, false)?;
        mesh = mesh
            .with_load_point(glam::DVec3::from_array(p))
            .map_err(|e| Error::input(format!("{key}: {e}")))?;
    }
    Ok(Shape::Mesh(Arc::new(mesh)))
}
