//! A `shape = { type = "mesh", ... }` wall: its STL file read and placed.

use super::schema::ShapeSpec;
use super::Loaded;
use crate::boundary::{Mesh, MeshPlacement, Shape};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::stl::read_stl;
use std::sync::Arc;

/// Three numbers from the key `key` (a mesh is 3D whatever the scenario;
/// a 2D scenario is refused by the shape's own check).
fn triple(key: &str, v: &[f64]) -> Result<[f64; 3]> {
    let out: [f64; 3] = v
        .try_into()
        .map_err(|_| Error::input(format!("{key} has {} components; it needs 3", v.len())))?;
    if let Some(x) = out.iter().find(|x| !x.is_finite()) {
        return Err(Error::input(format!("{key} contains {x}: must be finite")));
    }
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
    if D::D != 3 {
        return Err(Error::input(format!(
            "{key}: meshes are 3D walls; in {} use segments",
            D::NAME
        )));
    }
    let place = MeshPlacement {
        scale: *scale,
        rotate_deg: match rotate_deg {
            Some(r) => triple(&format!("{key}.shape.rotate_deg"), r)?,
            None => [0.0; 3],
        },
        translate: match translate {
            Some(t) => triple(&format!("{key}.shape.translate"), t)?,
            None => [0.0; 3],
        },
    };
    let path = loaded.path(file);
    let triangles = read_stl(&path).map_err(|e| Error::input(format!("{key}: {e}")))?;
    let name = path.display().to_string();
    let mut mesh = Mesh::new(&name, &triangles, &place)
        .map_err(|e| Error::input(format!("{key}: mesh file {name}: {e}")))?;
    if let Some(p) = load_point {
        let p = triple(&format!("{key}.shape.load_point"), p)?;
        mesh = mesh
            .with_load_point(glam::DVec3::from_array(p))
            .map_err(|e| Error::input(format!("{key}: {e}")))?;
    }
    Ok(Shape::Mesh(Arc::new(mesh)))
}
