//! Walls as drawable geometry at one instant: polylines and balls in world
//! coordinates (xyz), clipped to the box, that the PNG renderer projects
//! and the browser viewer draws as lines.
//!
//! Each wall's reference shape is sampled, then every sample is carried by
//! the wall's motion at time `t` ([`crate::boundary::Motion::place`]), so a
//! modulated plate shows its curved surface and a moving wall its place.

use crate::boundary::{Motion, Shape, Wall, CREASE_DEG};
use crate::dim::Dim;
use serde::{Deserialize, Serialize};

/// One drawable piece of a wall.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Wire {
    /// Points joined in order (a closed outline repeats its first point).
    Line { points: Vec<[f64; 3]> },
    /// An obstacle: a disk (2D) or sphere (3D).
    Ball { center: [f64; 3], radius: f64 },
}

/// Samples along a straight piece: enough that a modulated plate
/// (one wavelength across the box at most a few times) looks smooth.
const LINE_SAMPLES: usize = 64;
const CIRCLE_SAMPLES: usize = 96;

/// The walls present at time `t`, as wires inside the box `lo`–`hi`
/// (planes and cylinder axes are cut to it; in 2D only x and y count).
pub fn wires_at<D: Dim>(walls: &[Wall<D>], t: f64, lo: [f64; 3], hi: [f64; 3]) -> Vec<Wire> {
    let mut out = Vec::new();
    for w in walls.iter().filter(|w| w.is_active(t)) {
        let place = |q: [f64; 3]| D::to_xyz(w.motion.place(D::from_xyz(q), t));
        let line = |pts: Vec<[f64; 3]>| Wire::Line {
            points: pts.into_iter().map(place).collect(),
        };
        match &w.shape {
            Shape::Plane { point, normal } => {
                let (p, n) = (D::to_xyz(*point), D::to_xyz(*normal));
                if D::D == 2 {
                    let dir = [-n[1], n[0], 0.0];
                    if let Some((s0, s1)) = clip_line(p, dir, lo, hi, 2) {
                        out.push(line(sample(add(p, dir, s0), add(p, dir, s1))));
                    }
                } else if let Some(poly) = plane_in_box(p, n, lo, hi) {
                    out.push(line(sample_loop(&poly)));
                }
            }
            Shape::Segment { a, b } => out.push(line(vec![D::to_xyz(*a), D::to_xyz(*b)])),
            Shape::Polygon { vertices, .. } => {
                let v: Vec<[f64; 3]> = vertices.iter().map(|x| D::to_xyz(*x)).collect();
                out.push(line(closed(&v)));
            }
            Shape::Cylinder {
                point,
                axis,
                radius,
                ..
            } => {
                let p = D::to_xyz(*point);
                if D::D == 2 {
                    out.push(line(circle(p, [0.0, 0.0, 1.0], *radius)));
                } else {
                    let a = D::to_xyz(*axis);
                    let Some((s0, s1)) = clip_line(p, a, lo, hi, 3) else {
                        continue;
                    };
                    let (c0, c1) = (add(p, a, s0), add(p, a, s1));
                    out.push(line(circle(c0, a, *radius)));
                    out.push(line(circle(c1, a, *radius)));
                    let (u, v) = basis(a);
                    for k in 0..4 {
                        let ang = k as f64 * std::f64::consts::FRAC_PI_2;
                        let off = |c: [f64; 3]| {
                            let r = *radius;
                            [0, 1, 2].map(|i| c[i] + r * (ang.cos() * u[i] + ang.sin() * v[i]))
                        };
                        out.push(line(vec![off(c0), off(c1)]));
                    }
                }
            }
            Shape::Obstacle { center, diameter } => out.push(Wire::Ball {
                center: place(D::to_xyz(*center)),
                radius: 0.5 * diameter,
            }),
            // Shapes this renderer does not know yet are left out, not guessed.
            #[allow(unreachable_patterns)]
            _ => {}
        }
    }
    out
}

/// A mesh wall as drawn: its outline ([`crate::boundary::Mesh::outline`],
/// reference frame) with the wall's motion and removal time. Its triangles
/// stay in their STL file; this is what `scene.json` carries of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(bound(
    serialize = "D::V: Serialize, D::A: Serialize",
    deserialize = "D::V: Deserialize<'de>, D::A: Deserialize<'de>"
))]
pub struct MeshOutline<D: Dim> {
    pub name: String,
    pub motion: Motion<D>,
    pub remove_at: Option<f64>,
    pub lines: Vec<Vec<[f64; 3]>>,
}

impl<D: Dim> MeshOutline<D> {
    /// The outline of `wall`, when it is a mesh wall.
    pub fn of(wall: &Wall<D>) -> Option<Self> {
        let Shape::Mesh(mesh) = &wall.shape else {
            return None;
        };
        let lines = mesh.outline(CREASE_DEG);
        Some(Self {
            name: wall.name.clone(),
            motion: wall.motion.clone(),
            remove_at: wall.remove_at,
            lines: lines
                .into_iter()
                .map(|l| l.into_iter().map(|v| v.to_array()).collect())
                .collect(),
        })
    }
}

/// The outlines of the mesh walls present at time `t`, carried by their
/// motions.
pub fn outline_wires_at<D: Dim>(meshes: &[MeshOutline<D>], t: f64) -> Vec<Wire> {
    let present = |m: &&MeshOutline<D>| m.remove_at.is_none_or(|tr| t < tr);
    meshes
        .iter()
        .filter(present)
        .flat_map(|m| {
            m.lines.iter().map(move |l| Wire::Line {
                points: l
                    .iter()
                    .map(|&q| D::to_xyz(m.motion.place(D::from_xyz(q), t)))
                    .collect(),
            })
        })
        .collect()
}

fn add(p: [f64; 3], d: [f64; 3], s: f64) -> [f64; 3] {
    [p[0] + s * d[0], p[1] + s * d[1], p[2] + s * d[2]]
}

fn sample(a: [f64; 3], b: [f64; 3]) -> Vec<[f64; 3]> {
    (0..=LINE_SAMPLES)
        .map(|i| {
            let f = i as f64 / LINE_SAMPLES as f64;
            [0, 1, 2].map(|k| a[k] + f * (b[k] - a[k]))
        })
        .collect()
}

fn closed(v: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut out = v.to_vec();
    if let Some(&first) = v.first() {
        out.push(first);
    }
    out
}

/// A closed outline with every edge sampled.
fn sample_loop(v: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for (i, &a) in v.iter().enumerate() {
        let b = v[(i + 1) % v.len()];
        let mut s = sample(a, b);
        s.pop();
        out.extend(s);
    }
    out.push(v[0]);
    out
}

/// Two unit vectors perpendicular to `a` and to each other.
fn basis(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let n = norm(a);
    let a = a.map(|x| x / n);
    let t = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = cross(a, t);
    let un = norm(u);
    let u = u.map(|x| x / un);
    (u, cross(a, u))
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn circle(c: [f64; 3], axis: [f64; 3], r: f64) -> Vec<[f64; 3]> {
    let (u, v) = basis(axis);
    (0..=CIRCLE_SAMPLES)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / CIRCLE_SAMPLES as f64;
            [0, 1, 2].map(|k| c[k] + r * (a.cos() * u[k] + a.sin() * v[k]))
        })
        .collect()
}

/// The parameter range of the line p + s·d inside the box (first `axes`
/// axes), or None when it misses the box or the box is not finite.
fn clip_line(
    p: [f64; 3],
    d: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
    axes: usize,
) -> Option<(f64, f64)> {
    let (mut s0, mut s1) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..axes {
        if !(lo[k].is_finite() && hi[k].is_finite()) {
            return None;
        }
        if d[k].abs() < 1e-12 {
            if p[k] < lo[k] || p[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (a, b) = ((lo[k] - p[k]) / d[k], (hi[k] - p[k]) / d[k]);
        s0 = s0.max(a.min(b));
        s1 = s1.min(a.max(b));
    }
    (s0 < s1).then_some((s0, s1))
}

/// The polygon where the plane through `p` with normal `n` cuts the box,
/// its corners in order around it; None when it misses.
fn plane_in_box(p: [f64; 3], n: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Option<Vec<[f64; 3]>> {
    if !lo.iter().chain(&hi).all(|x| x.is_finite()) {
        return None;
    }
    let corner = |i: usize| [0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] });
    let dist = |q: [f64; 3]| (0..3).map(|k| (q[k] - p[k]) * n[k]).sum::<f64>();
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let mut pts: Vec<[f64; 3]> = Vec::new();
    for i in 0..8usize {
        for k in 0..3 {
            let j = i | 1 << k;
            if j == i {
                continue;
            }
            let (a, b) = (corner(i), corner(j));
            let (da, db) = (dist(a), dist(b));
            if (da <= 0.0 && db >= 0.0) || (da >= 0.0 && db <= 0.0) {
                let f = if da == db { 0.0 } else { da / (da - db) };
                let q = [0, 1, 2].map(|m| a[m] + f * (b[m] - a[m]));
                if !pts.iter().any(|x| norm(sub(*x, q)) < 1e-9 * size) {
                    pts.push(q);
                }
            }
        }
    }
    if pts.len() < 3 {
        return None;
    }
    let c = [0, 1, 2].map(|k| pts.iter().map(|q| q[k]).sum::<f64>() / pts.len() as f64);
    let (u, v) = basis(n);
    let angle = |q: &[f64; 3]| {
        let d = sub(*q, c);
        let (x, y) = (
            (0..3).map(|k| d[k] * u[k]).sum::<f64>(),
            (0..3).map(|k| d[k] * v[k]).sum::<f64>(),
        );
        y.atan2(x)
    };
    pts.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
    Some(pts)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Motion;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    fn points(w: &Wire) -> &[[f64; 3]] {
        match w {
            Wire::Line { points } => points,
            Wire::Ball { .. } => panic!("a ball"),
        }
    }

    #[test]
    fn a_floor_plane_spans_the_box_and_rides_its_vibration() {
        let motion: Motion<D2> = serde_json::from_str(
            r#"{"type":"vibrate","direction":[0.0,1.0],"amplitude":0.5,"modulation":0.0,
                "wavelength":4.0,"frequency":1.0,"phase":0.0}"#,
        )
        .unwrap();
        let plate = Wall::new(
            "plate",
            Shape::Plane {
                point: DVec2::ZERO,
                normal: DVec2::Y,
            },
            motion,
        )
        .unwrap();
        // A quarter period in: lifted by the full amplitude.
        let w = wires_at(&[plate], 0.25, [0.0, 0.0, -0.5], [4.0, 10.0, 0.5]);
        let p = points(&w[0]);
        assert_eq!(p.len(), LINE_SAMPLES + 1);
        let xs: Vec<f64> = p.iter().map(|q| q[0]).collect();
        assert!((xs.iter().cloned().fold(f64::MAX, f64::min)).abs() < 1e-12);
        assert!((xs.iter().cloned().fold(f64::MIN, f64::max) - 4.0).abs() < 1e-12);
        assert!(p.iter().all(|q| (q[1] - 0.5).abs() < 1e-12), "{p:?}");
    }

    #[test]
    fn removed_walls_vanish_and_segments_keep_their_ends() {
        let seg = Wall::<D2>::new(
            "floor-left",
            Shape::Segment {
                a: DVec2::new(0.0, 0.0),
                b: DVec2::new(1.0, 0.0),
            },
            Motion::Fixed,
        )
        .unwrap()
        .with_remove_at(2.0)
        .unwrap();
        let lo = [0.0, 0.0, -0.5];
        let hi = [3.0, 3.0, 0.5];
        let w = wires_at(std::slice::from_ref(&seg), 1.0, lo, hi);
        assert_eq!(points(&w[0]), &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        assert!(wires_at(&[seg], 2.0, lo, hi).is_empty());
    }

    #[test]
    fn a_tilted_plane_cuts_the_unit_cube_in_a_hexagon() {
        // x + y + z = 1.5 cuts all six faces of the unit cube.
        let plane = Wall::<D3>::new(
            "cut",
            Shape::Plane {
                point: DVec3::splat(0.5),
                normal: DVec3::ONE,
            },
            Motion::Fixed,
        )
        .unwrap();
        let poly = plane_in_box([0.5; 3], [1.0; 3], [0.0; 3], [1.0; 3]).unwrap();
        assert_eq!(poly.len(), 6);
        for q in &poly {
            assert!((q.iter().sum::<f64>() - 1.5).abs() < 1e-12);
        }
        let w = wires_at(&[plane], 0.0, [0.0; 3], [1.0; 3]);
        let p = points(&w[0]);
        assert_eq!(p.first(), p.last());
        // A 3D cylinder along z gives two rings and four generators, cut to the box.
        let pipe = Wall::<D3>::new(
            "pipe",
            Shape::Cylinder {
                point: DVec3::new(0.5, 0.5, 0.0),
                axis: DVec3::Z,
                radius: 0.4,
                inside: true,
            },
            Motion::Fixed,
        )
        .unwrap();
        let w = wires_at(&[pipe], 0.0, [0.0; 3], [1.0, 1.0, 2.0]);
        assert_eq!(w.len(), 6);
        let top = points(&w[1]);
        assert!(top.iter().all(|q| (q[2] - 2.0).abs() < 1e-12));
        assert!(top
            .iter()
            .all(|q| ((q[0] - 0.5).hypot(q[1] - 0.5) - 0.4).abs() < 1e-12));
    }
}
