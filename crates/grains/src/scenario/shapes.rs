//! `[[shapes]]` read and checked: each entry's spheres (inline or from a
//! file, in metres or multiples of d0, scaled) made into a [`Shape`] with
//! its mass properties, and what `grains check` prints of it.

use super::schema::{ClumpSpec, Scenario, ShapeUnits, SphereSpec};
use super::Loaded;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::particles::MassModel;
use crate::rigid::mass::Ball;
use crate::rigid::shape::{clump, detached, Props};
use crate::rigid::Shape;
use glam::DVec3;
use serde_json::{json, Value};

/// The scenario's shapes in `[[shapes]]` order, with what check prints.
pub fn build<D: Dim>(loaded: &Loaded) -> Result<(Vec<Shape<D>>, Vec<Props>)> {
    let s = &loaded.scenario;
    let density = super::materials::density(s, None)?;
    let mut shapes = Vec::with_capacity(s.shapes.len());
    let mut props = Vec::with_capacity(s.shapes.len());
    for (k, spec) in s.shapes.iter().enumerate() {
        let key = format!("shapes[{k}] ({})", spec.name);
        let balls = spheres::<D>(loaded, spec, &key)?;
        let (shape, p) = clump::<D>(&spec.name, &balls, density, s.particles.mass_model);
        shapes.push(shape);
        props.push(p);
    }
    Ok((shapes, props))
}

/// The index of the shape named `name`; `key` is the scenario key that
/// names it.
pub fn index(s: &Scenario, name: &str, key: &str) -> Result<usize> {
    s.shapes.iter().position(|x| x.name == name).ok_or_else(|| {
        let names: Vec<String> = s.shapes.iter().map(|x| format!("\"{}\"", x.name)).collect();
        Error::input(format!(
            "{key} = \"{name}\" names no [[shapes]] entry; the scenario has {}",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ))
    })
}

/// The names are unique: bodies refer to shapes by name.
pub fn check_names(s: &Scenario) -> Result<()> {
    for (k, a) in s.shapes.iter().enumerate() {
        if a.name.is_empty() {
            return Err(Error::input(format!("shapes[{k}].name is empty")));
        }
        if s.shapes[..k].iter().any(|b| b.name == a.name) {
            return Err(Error::input(format!(
                "shapes[{k}].name = \"{}\" is used twice: bodies refer to shapes by name",
                a.name
            )));
        }
    }
    Ok(())
}

/// The entry's spheres in metres, checked: positive radii, centres with
/// one entry per axis (2D: two, or three with z = 0), joined into one
/// clump.
fn spheres<D: Dim>(loaded: &Loaded, spec: &ClumpSpec, key: &str) -> Result<Vec<Ball>> {
    if !(spec.scale.is_finite() && spec.scale > 0.0) {
        return Err(Error::input(format!(
            "{key}.scale = {}: must be a positive factor",
            spec.scale
        )));
    }
    let unit = match spec.units {
        ShapeUnits::M => 1.0,
        ShapeUnits::D0 => loaded.scenario.particles.d0,
    } * spec.scale;
    let (written, origin): (Vec<(String, SphereSpec)>, String) =
        match (&spec.file, spec.spheres.is_empty()) {
            (Some(_), false) => {
                return Err(Error::input(format!(
                    "{key}: give spheres or file, not both"
                )))
            }
            (None, true) => {
                return Err(Error::input(format!(
                    "{key}: no spheres; give spheres = [{{ center = [x, y, z], radius = r }}, …] \
                 or file = \"NAME.csv\" (x y z r per line)"
                )))
            }
            (None, false) => (
                (spec.spheres.iter().enumerate())
                    .map(|(j, s)| (format!("{key}.spheres[{j}]"), s.clone()))
                    .collect(),
                format!("{key}.spheres"),
            ),
            (Some(name), true) => {
                let path = loaded.path(name);
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    Error::input(format!(
                        "{key}.file = \"{name}\": cannot read {}: {e}",
                        path.display()
                    ))
                })?;
                let rows = read_rows(&text, &format!("{key}.file ({})", path.display()))?;
                if rows.is_empty() {
                    return Err(Error::input(format!(
                        "{key}.file = \"{name}\": {} holds no spheres (x y z r per line)",
                        path.display()
                    )));
                }
                (rows, format!("{key}.file"))
            }
        };
    let mut balls = Vec::with_capacity(written.len());
    for (at, s) in &written {
        let c = &s.center;
        let ok_len = c.len() == D::D || (D::D == 2 && c.len() == 3);
        if !ok_len {
            return Err(Error::input(format!(
                "{at}.center has {} components; a {} shape needs {}",
                c.len(),
                D::NAME,
                if D::D == 2 {
                    "2 (or 3 with z = 0)"
                } else {
                    "3"
                }
            )));
        }
        if let Some(x) = c.iter().find(|x| !x.is_finite()) {
            return Err(Error::input(format!(
                "{at}.center contains {x}: must be finite"
            )));
        }
        if D::D == 2 && c.len() == 3 && c[2] != 0.0 {
            return Err(Error::input(format!(
                "{at}.center has z = {}: a 2d clump's disks lie in the plane z = 0",
                c[2]
            )));
        }
        if !(s.radius.is_finite() && s.radius > 0.0) {
            return Err(Error::input(format!(
                "{at}.radius = {}: must be positive",
                s.radius
            )));
        }
        let z = if c.len() == 3 { c[2] } else { 0.0 };
        balls.push((DVec3::new(c[0], c[1], z) * unit, s.radius * unit));
    }
    if let Some(j) = detached(&balls) {
        return Err(Error::input(format!(
            "{}: sphere {} touches no chain of spheres joined to the first: a clump must be \
             connected, since a rigid body is held together by its own material and none joins \
             separate pieces; move it to touch or overlap the others, or give it a shape of its own \
             ({origin})",
            written[j].0,
            j + 1
        )));
    }
    Ok(balls)
}

/// The rows `x y z r` of a shape file (spaces or commas between numbers;
/// `#` starts a comment; blank lines skipped), each named by its line.
fn read_rows(text: &str, key: &str) -> Result<Vec<(String, SphereSpec)>> {
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = format!("{key} line {}", n + 1);
        let nums: Vec<f64> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|w| !w.is_empty())
            .map(|w| {
                w.parse::<f64>().map_err(|_| {
                    Error::input(format!("{at}: \"{w}\" is not a number (x y z r per line)"))
                })
            })
            .collect::<Result<_>>()?;
        if nums.len() != 4 {
            return Err(Error::input(format!(
                "{at}: {} numbers; a sphere is x y z r",
                nums.len()
            )));
        }
        let sphere = SphereSpec {
            center: nums[..3].to_vec(),
            radius: nums[3],
        };
        rows.push((at, sphere));
    }
    Ok(rows)
}

/// What `grains check` prints of one shape; `model` is the grains' mass
/// model (a 2D clump under `disk` has an area, otherwise a volume).
pub fn report<D: Dim>(shape: &Shape<D>, p: &Props, model: MassModel, bodies: usize) -> Value {
    let axes = [p.axes.x_axis, p.axes.y_axis, p.axes.z_axis];
    let flat = D::D == 2;
    let measure = if flat && model == MassModel::Disk {
        "area"
    } else {
        "volume"
    };
    json!({
        "name": shape.name,
        (if flat { "sub_disks" } else { "sub_spheres" }): shape.spheres.len(),
        "bodies": bodies,
        "mass": shape.mass,
        measure: p.measure,
        "centre_of_mass_input_frame": if flat { json!([p.com.x, p.com.y]) } else { json!(p.com.to_array()) },
        "principal_moments": if flat { json!(shape.inertia[2]) } else { json!(shape.inertia) },
        "principal_axes_input_frame": if flat {
            json!(axes[..2].iter().map(|a| [a.x, a.y]).collect::<Vec<_>>())
        } else {
            json!(axes.iter().map(|a| a.to_array()).collect::<Vec<_>>())
        },
        "bounding_radius": p.bounding_radius,
        "mass_properties": if p.exact {
            "closed forms (each sphere meets at most one earlier sphere)".to_string()
        } else {
            format!("quadrature on rays, converged to {:.1e} (relative change of the last refinement)", p.last_change)
        },
    })
}
