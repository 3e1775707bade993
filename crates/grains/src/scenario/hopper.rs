//! The silo of `[hopper]`: side walls on the domain's faces and a floor
//! with a centred outlet, added to the scenario's walls before the engine
//! is built (the runner's flow events recycle the grains that leave, or
//! an outlet takes them out); with `gate`, a wall closing the orifice.

use super::schema::{Dimension, HopperSpec, MotionSpec, ShapeSpec, WallSpec};
use super::{Loaded, Scenario};
use crate::error::{Error, Result};
use std::borrow::Cow;

/// The scenario with the walls of `[hopper]` added (unchanged without one).
pub fn expand(loaded: &Loaded) -> Result<Cow<'_, Loaded>> {
    let Some(h) = &loaded.scenario.hopper else {
        return Ok(Cow::Borrowed(loaded));
    };
    if !h.recycle && loaded.scenario.outlets.is_empty() {
        return Err(Error::input(
            "hopper.recycle = false: the discharged grains must leave the run; add an \
             [[outlets]] entry below the orifice (e.g. plane = { point, normal } pointing down)",
        ));
    }
    let mut out = loaded.clone();
    out.scenario
        .walls
        .extend(hopper_walls(&loaded.scenario, h)?);
    Ok(Cow::Owned(out))
}

fn wall(name: &str, shape: ShapeSpec) -> WallSpec {
    WallSpec {
        name: name.into(),
        shape,
        motion: MotionSpec::Fixed,
        remove_at: None,
        material: None,
    }
}

/// Side walls on the domain's faces and a floor at `h.floor` with a centred
/// outlet: a slot of width D (2D) or a square hole of side D (3D).
fn hopper_walls(s: &Scenario, h: &HopperSpec) -> Result<Vec<WallSpec>> {
    let (lo, hi) = (&s.domain.lo, &s.domain.hi);
    let f = h.floor;
    let d = h.outlet;
    let width = hi[0] - lo[0];
    if !(d.is_finite() && d > 0.0 && d < width) {
        return Err(Error::input(format!(
            "hopper.outlet = {d}: must be positive and narrower than the domain ({width} m)"
        )));
    }
    if h.refill.len() != 2 || h.refill[0] >= h.refill[1] {
        return Err(Error::input(
            "hopper.refill must be [low, high] heights (m) with low < high",
        ));
    }
    let xc = 0.5 * (lo[0] + hi[0]);
    let (a, b) = (xc - 0.5 * d, xc + 0.5 * d);
    let plane = |p: Vec<f64>, n: Vec<f64>| ShapeSpec::Plane {
        point: p,
        normal: n,
    };
    let mut walls = match s.dimension {
        Dimension::Two => vec![
            wall("silo-left", plane(vec![lo[0], f], vec![1.0, 0.0])),
            wall("silo-right", plane(vec![hi[0], f], vec![-1.0, 0.0])),
            wall(
                "floor-left",
                ShapeSpec::Segment {
                    a: vec![lo[0], f],
                    b: vec![a, f],
                },
            ),
            wall(
                "floor-right",
                ShapeSpec::Segment {
                    a: vec![b, f],
                    b: vec![hi[0], f],
                },
            ),
        ],
        Dimension::Three => {
            let yc = 0.5 * (lo[1] + hi[1]);
            let (c, e) = (yc - 0.5 * d, yc + 0.5 * d);
            if e - c >= hi[1] - lo[1] {
                return Err(Error::input(format!(
                    "hopper.outlet = {d}: must be narrower than the domain along y"
                )));
            }
            // Four floor pieces around the orifice. Where two meet, the edge is
            // a seam (no contact from either side: the neighbour's face carries
            // the grain), so a grain on a seam is pushed once; only the
            // orifice rim acts as an edge.
            let poly = |v: &[[f64; 2]], seams: &[usize]| ShapeSpec::Polygon {
                vertices: v.iter().map(|p| vec![p[0], p[1], f]).collect(),
                seams: seams.to_vec(),
            };
            let (y0, y1, x0, x1) = (lo[1], hi[1], lo[0], hi[0]);
            vec![
                wall(
                    "silo-left",
                    plane(vec![lo[0], 0.0, 0.0], vec![1.0, 0.0, 0.0]),
                ),
                wall(
                    "silo-right",
                    plane(vec![hi[0], 0.0, 0.0], vec![-1.0, 0.0, 0.0]),
                ),
                wall(
                    "silo-front",
                    plane(vec![0.0, lo[1], 0.0], vec![0.0, 1.0, 0.0]),
                ),
                wall(
                    "silo-back",
                    plane(vec![0.0, hi[1], 0.0], vec![0.0, -1.0, 0.0]),
                ),
                wall(
                    "floor-left",
                    poly(
                        &[[x0, y0], [a, y0], [a, c], [a, e], [a, y1], [x0, y1]],
                        &[1, 3],
                    ),
                ),
                wall(
                    "floor-right",
                    poly(
                        &[[b, y0], [x1, y0], [x1, y1], [b, y1], [b, e], [b, c]],
                        &[3, 5],
                    ),
                ),
                wall(
                    "floor-front",
                    poly(&[[a, y0], [b, y0], [b, c], [a, c]], &[1, 3]),
                ),
                wall(
                    "floor-back",
                    poly(&[[a, e], [b, e], [b, y1], [a, y1]], &[1, 3]),
                ),
            ]
        }
    };
    if h.gate {
        // The gate's edges are seams: the floor's rim edges carry a grain
        // there, so none is pushed twice by the closed orifice.
        walls.push(match s.dimension {
            Dimension::Two => wall(
                "gate",
                ShapeSpec::Segment {
                    a: vec![a, f],
                    b: vec![b, f],
                },
            ),
            Dimension::Three => {
                let yc = 0.5 * (lo[1] + hi[1]);
                let (c, e) = (yc - 0.5 * d, yc + 0.5 * d);
                wall(
                    "gate",
                    ShapeSpec::Polygon {
                        vertices: vec![vec![a, c, f], vec![b, c, f], vec![b, e, f], vec![a, e, f]],
                        seams: vec![0, 1, 2, 3],
                    },
                )
            }
        });
    }
    Ok(walls)
}
