//! Wall shapes: the geometry of a wall in its reference (time-zero) position.

use super::flat;
use super::geom::{from3, to3, Touch};
use super::mesh::{Mesh, MeshScratch};
use super::round;
use crate::dim::Dim;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// The geometry of a wall, before any prescribed motion is applied.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "type",
    rename_all = "lowercase",
    bound(serialize = "D::V: Serialize", deserialize = "D::V: Deserialize<'de>")
)]
pub enum Shape<D: Dim> {
    /// Infinite line (2D) or plane (3D) through `point`. One-sided: particles
    /// live on the side `normal` points to. A particle whose centre has
    /// crossed the plane still feels overlap `r − s` (`s` the signed distance)
    /// and is pushed back; one wholly behind it (`s < −r`) is considered lost
    /// and feels nothing.
    Plane { point: D::V, normal: D::V },
    /// Finite segment from `a` to `b` (2D only). Two-sided; end caps round.
    Segment { a: D::V, b: D::V },
    /// Convex planar polygon (3D only), vertices in order around it.
    /// Two-sided; edges and corners round. `seams` lists edges (edge i runs
    /// from vertex i to i + 1) shared with a coplanar neighbour that carries
    /// the grains beyond them: no contact there, so a grain on a seam is
    /// pushed once, not by both pieces.
    Polygon {
        vertices: Vec<D::V>,
        #[serde(default)]
        seams: Vec<usize>,
    },
    /// Cylinder of `radius` about the line through `point` along `axis`; in 2D
    /// a circle about `point` (axis ignored). `inside`: particles are inside
    /// (pipe, drum); otherwise outside (a post). One-sided like `Plane`.
    Cylinder {
        point: D::V,
        axis: D::V,
        radius: f64,
        inside: bool,
    },
    /// Fixed circle (2D) or sphere (3D) of diameter d1: overlap r + d1/2 − |p − c|.
    Obstacle { center: D::V, diameter: f64 },
    /// A triangle mesh (3D), or in 2D a polyline's ribbon across the plane
    /// ([`super::mesh`]'s `ribbon`), read from a file by the scenario
    /// builder; two-sided, pushing with several contacts where it bends
    /// ([`super::mesh`]). Not written or read by serde (it comes from its
    /// file).
    #[serde(skip)]
    Mesh(Arc<Mesh>),
}

fn finite<D: Dim>(v: D::V, what: &str) -> Result<(), String> {
    if D::is_finite(v) {
        Ok(())
    } else {
        Err(format!("{what} is not finite"))
    }
}

fn unit<D: Dim>(v: &mut D::V, what: &str) -> Result<(), String> {
    finite::<D>(*v, what)?;
    let n = D::norm(*v);
    if n == 0.0 {
        return Err(format!("{what} is the zero vector"));
    }
    *v = *v / n;
    Ok(())
}

fn positive(x: f64, what: &str) -> Result<(), String> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(format!("{what} must be positive and finite, got {x}"))
    }
}

impl<D: Dim> Shape<D> {
    /// A short name of the shape kind, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Plane { .. } => "plane",
            Shape::Segment { .. } => "segment",
            Shape::Polygon { .. } => "polygon",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Obstacle { .. } => "obstacle",
            Shape::Mesh(_) => "mesh",
        }
    }

    /// Checks the shape and normalizes its direction vectors in place.
    pub(crate) fn validate(&mut self) -> Result<(), String> {
        match self {
            Shape::Plane { point, normal } => {
                finite::<D>(*point, "plane point")?;
                unit::<D>(normal, "plane normal")
            }
            Shape::Segment { a, b } => {
                if D::D != 2 {
                    return Err(format!(
                        "segments are 2D walls; in {} use a polygon",
                        D::NAME
                    ));
                }
                finite::<D>(*a, "segment end a")?;
                finite::<D>(*b, "segment end b")?;
                if D::norm(*b - *a) == 0.0 {
                    return Err("segment has zero length (a = b)".into());
                }
                Ok(())
            }
            Shape::Polygon { vertices, seams } => {
                if let Some(i) = seams.iter().find(|&&i| i >= vertices.len()) {
                    return Err(format!(
                        "polygon seam {i} is not an edge (edges 0 to {})",
                        vertices.len().saturating_sub(1)
                    ));
                }
                if D::D != 3 {
                    return Err(format!(
                        "polygons are 3D walls; in {} use segments",
                        D::NAME
                    ));
                }
                let v: Vec<DVec3> = vertices.iter().map(|x| to3::<D>(*x)).collect();
                flat::check_polygon(&v)
            }
            Shape::Cylinder {
                point,
                axis,
                radius,
                ..
            } => {
                finite::<D>(*point, "cylinder point")?;
                positive(*radius, "cylinder radius")?;
                if D::D == 3 {
                    unit::<D>(axis, "cylinder axis")?;
                }
                Ok(())
            }
            Shape::Obstacle { center, diameter } => {
                finite::<D>(*center, "obstacle center")?;
                positive(*diameter, "obstacle diameter")
            }
            Shape::Mesh(_) => Ok(()),
        }
    }

    /// The point that represents the shape's position (for output and for
    /// [`super::Wall::displacement`]): the plane's point, the segment's
    /// midpoint, the polygon's vertex mean, the cylinder's point, the
    /// obstacle's centre, the mesh's load point (by default its centroid).
    pub fn reference_point(&self) -> D::V {
        match self {
            Shape::Mesh(m) => from3::<D>(m.load_point()),
            Shape::Plane { point, .. } | Shape::Cylinder { point, .. } => *point,
            Shape::Segment { a, b } => (*a + *b) * 0.5,
            Shape::Polygon { vertices, .. } => {
                let n = vertices.len().max(1);
                vertices.iter().fold(D::zero(), |s, v| s + *v) / n as f64
            }
            Shape::Obstacle { center, .. } => *center,
        }
    }

    /// The smallest box, in 3D form, that holds a finite shape (segment,
    /// polygon, obstacle) and every contact point [`Shape::touch`] can
    /// find on it; `None` for the unbounded ones (plane, cylinder).
    pub(crate) fn bounding_box(&self) -> Option<(DVec3, DVec3)> {
        let corners = |points: &mut dyn Iterator<Item = DVec3>| {
            points.fold(
                (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), x| (lo.min(x), hi.max(x)),
            )
        };
        match self {
            Shape::Plane { .. } | Shape::Cylinder { .. } => None,
            Shape::Mesh(m) => Some(m.bounds()),
            Shape::Segment { a, b } => Some(corners(&mut [*a, *b].into_iter().map(to3::<D>))),
            Shape::Polygon { vertices, .. } => {
                // `touch` meets the polygon projected along its normal onto
                // the plane of its first vertex: validation lets the
                // vertices stray from one plane by 1e-9 of the size, so the
                // projected vertices go into the box too.
                let vert = |i: usize| to3::<D>(vertices[i]);
                let normal = flat::polygon_normal(vertices.len(), vert);
                let v0 = vert(0);
                let projected = (0..vertices.len()).map(|i| {
                    let v = vert(i);
                    v - normal * (v - v0).dot(normal)
                });
                Some(corners(&mut (0..vertices.len()).map(vert).chain(projected)))
            }
            Shape::Obstacle { center, diameter } => {
                // In 2D the disk lies in the z = 0 plane.
                let mut half = DVec3::splat(0.5 * diameter);
                if D::D == 2 {
                    half.z = 0.0;
                }
                let c = to3::<D>(*center);
                Some((c - half, c + half))
            }
        }
    }

    /// Contact of a sphere (radius `r`, centre `p`) with the unmoved shape.
    /// Assumes the shape passed [`Shape::validate`].
    pub(crate) fn touch(&self, p: DVec3, r: f64) -> Option<Touch> {
        match self {
            Shape::Plane { point, normal } => {
                flat::plane(p, to3::<D>(*point), to3::<D>(*normal), r)
            }
            Shape::Segment { a, b } => flat::segment(p, to3::<D>(*a), to3::<D>(*b), r),
            Shape::Polygon { vertices, seams } => {
                let n = vertices.len();
                let vert = |i: usize| to3::<D>(vertices[i]);
                let normal = flat::polygon_normal(n, vert);
                flat::polygon(p, n, vert, seams, normal, r)
            }
            Shape::Cylinder {
                point,
                axis,
                radius,
                inside,
            } => {
                let axis = if D::D == 2 { DVec3::Z } else { to3::<D>(*axis) };
                round::cylinder(p, to3::<D>(*point), axis, *radius, *inside, r)
            }
            Shape::Obstacle { center, diameter } => {
                let up = to3::<D>(D::unit(D::vertical()));
                round::obstacle(p, to3::<D>(*center), *diameter, r, up)
            }
            Shape::Mesh(m) => {
                // The deepest of its contacts: the wall pass asks for all of
                // them (`PlacedWall::mesh_contacts`); this answers the
                // one-contact questions (`Wall::contact`).
                let mut scratch = MeshScratch::default();
                m.touches(p, r, &mut scratch);
                let deepest = scratch
                    .touches()
                    .iter()
                    .max_by(|a, b| a.touch.overlap.total_cmp(&b.touch.overlap));
                deepest.map(|t| t.touch)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    //! Wall construction: normalisation, the errors, serde.

    use crate::boundary::tests::{fixed2, fixed3, plate};
    use crate::boundary::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    #[test]
    fn constructor_normalizes() {
        let w = fixed2(Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::new(0.0, 2.0),
        });
        assert_eq!(
            w.shape,
            Shape::Plane {
                point: DVec2::ZERO,
                normal: DVec2::Y
            }
        );
        let w = fixed3(Shape::Cylinder {
            point: DVec3::ZERO,
            axis: DVec3::new(0.0, 0.0, -4.0),
            radius: 1.0,
            inside: true,
        });
        match w.shape {
            Shape::Cylinder { axis, .. } => assert_eq!(axis, -DVec3::Z),
            _ => unreachable!(),
        }
    }

    fn err<D: Dim>(shape: Shape<D>, motion: Motion<D>) -> String {
        Wall::new("left", shape, motion).unwrap_err().to_string()
    }

    #[test]
    fn constructor_errors() {
        let plane2 = || Shape::<D2>::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        };
        let e = err(
            Shape::<D2>::Plane {
                point: DVec2::ZERO,
                normal: DVec2::ZERO,
            },
            Motion::Fixed,
        );
        assert!(
            e.contains("wall 'left'") && e.contains("plane normal"),
            "{e}"
        );
        let e = err(
            Shape::<D3>::Segment {
                a: DVec3::ZERO,
                b: DVec3::X,
            },
            Motion::Fixed,
        );
        assert!(e.contains("'left'") && e.contains("2D"), "{e}");
        let e = err(
            Shape::<D2>::Segment {
                a: DVec2::X,
                b: DVec2::X,
            },
            Motion::Fixed,
        );
        assert!(e.contains("zero length"), "{e}");
        let e = err(
            Shape::<D2>::Polygon {
                vertices: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
                seams: vec![],
            },
            Motion::Fixed,
        );
        assert!(e.contains("3D"), "{e}");
        let e = err(
            Shape::<D3>::Polygon {
                vertices: vec![DVec3::ZERO, DVec3::X],
                seams: vec![],
            },
            Motion::Fixed,
        );
        assert!(e.contains("at least 3"), "{e}");
        let e = err(
            Shape::<D3>::Polygon {
                vertices: vec![DVec3::ZERO, DVec3::X, DVec3::new(0.2, 0.2, 0.0), DVec3::Y],
                seams: vec![],
            },
            Motion::Fixed,
        );
        assert!(e.contains("convex"), "{e}");
        let e = err(
            Shape::<D3>::Polygon {
                vertices: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.5), DVec3::Y],
                seams: vec![],
            },
            Motion::Fixed,
        );
        assert!(e.contains("coplanar"), "{e}");
        let e = err(
            Shape::<D3>::Polygon {
                vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
                seams: vec![3],
            },
            Motion::Fixed,
        );
        assert!(e.contains("seam 3 is not an edge"), "{e}");
        let e = err(
            Shape::<D2>::Cylinder {
                point: DVec2::ZERO,
                axis: DVec2::ZERO,
                radius: -1.0,
                inside: true,
            },
            Motion::Fixed,
        );
        assert!(e.contains("cylinder radius"), "{e}");
        let e = err(
            Shape::<D3>::Cylinder {
                point: DVec3::ZERO,
                axis: DVec3::ZERO,
                radius: 1.0,
                inside: true,
            },
            Motion::Fixed,
        );
        assert!(e.contains("cylinder axis"), "{e}");
        let e = err(
            Shape::<D3>::Obstacle {
                center: DVec3::ZERO,
                diameter: 0.0,
            },
            Motion::Fixed,
        );
        assert!(e.contains("obstacle diameter"), "{e}");
        let e = err(
            Shape::<D2>::Plane {
                point: DVec2::new(f64::NAN, 0.0),
                normal: DVec2::Y,
            },
            Motion::Fixed,
        );
        assert!(e.contains("not finite"), "{e}");
        let e = err(
            plane2(),
            Motion::Vibrate {
                direction: DVec2::Y,
                amplitude: 1e-3,
                modulation: 0.0,
                wavelength: 0.0,
                frequency: -1.0,
                phase: 0.0,
            },
        );
        assert!(e.contains("'left'") && e.contains("frequency"), "{e}");
        let e = err(
            plane2(),
            Motion::Vibrate {
                direction: DVec2::ZERO,
                amplitude: 1e-3,
                modulation: 0.0,
                wavelength: 0.0,
                frequency: 1.0,
                phase: 0.0,
            },
        );
        assert!(e.contains("direction"), "{e}");
        let e = err(
            plane2(),
            Motion::Vibrate {
                direction: DVec2::Y,
                amplitude: 1e-3,
                modulation: 0.5,
                wavelength: 0.0,
                frequency: 1.0,
                phase: 0.0,
            },
        );
        assert!(e.contains("wavelength"), "{e}");
        let e = err(
            plane2(),
            Motion::Oscillate {
                amplitude: DVec2::X,
                frequency: f64::INFINITY,
                phase: 0.0,
            },
        );
        assert!(e.contains("frequency"), "{e}");
        let e = Wall::<D2>::new("x", plane2(), Motion::Fixed)
            .unwrap()
            .with_remove_at(f64::NAN)
            .unwrap_err()
            .to_string();
        assert!(e.contains("removal time"), "{e}");
    }

    #[test]
    fn serde_round_trip() {
        let w = plate(0.5).with_remove_at(2.0).unwrap();
        let s = serde_json::to_string(&w).unwrap();
        assert!(s.contains("\"type\":\"vibrate\""), "{s}");
        let back: Wall<D2> = serde_json::from_str(&s).unwrap();
        assert_eq!(back, w);
        let d = Wall::<D3>::new(
            "drum",
            Shape::Cylinder {
                point: DVec3::ZERO,
                axis: DVec3::Y,
                radius: 1.0,
                inside: true,
            },
            Motion::Rotate {
                center: DVec3::ZERO,
                omega: DVec3::new(0.0, 2.0, 0.0),
            },
        )
        .unwrap();
        let back: Wall<D3> = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
        assert_eq!(back, d);
    }
}
