//! Inlets of rigid bodies (`shape` or `shapes` in `[[inlets]]`): which
//! shape each arriving body has (a mixture by number, drawn body by body),
//! its orientation (uniform on rotations, or fixed) and whether a spot
//! fits it: every sub-sphere must pass the clearance test an inlet gives a
//! sphere (clear of the grains, the other bodies' sub-spheres and the
//! walls, mesh walls included).
//!
//! Each body's shape and turn come from streams of (seed, inlet, body
//! number) of their own, so they are the same on any thread count and
//! after a resume, whatever the attempts its position took.

use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::rigid::shape::{placed, Props};
use crate::rigid::Shape;
use crate::scenario::clumps::{orientation, random_orientation};
use crate::scenario::schema::{InletSpec, Scenario};
use crate::scenario::shapes;
use glam::DQuat;
use rand::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Stream purposes (after the inlet's 11–13): a body's shape, its turn.
pub const STREAM_SHAPE: u64 = 14;
pub const STREAM_TURN: u64 = 15;

/// Whether an inlet brings bodies instead of spheres.
pub fn brings_bodies(spec: &InletSpec) -> bool {
    spec.shape.is_some() || !spec.shapes.is_empty()
}

/// Whether any inlet of `s` brings bodies.
pub fn any(s: &Scenario) -> bool {
    s.inlets.iter().any(brings_bodies)
}

/// The keys of an inlet of bodies checked (`key` is "inlets[i]"): its
/// shapes and their fractions by number, `None` for an inlet of spheres.
/// What does not apply to bodies is refused by name.
pub fn shares(s: &Scenario, spec: &InletSpec, key: &str) -> Result<Option<Vec<(usize, f64)>>> {
    if !brings_bodies(spec) {
        if spec.orientation.is_some() {
            return Err(Error::input(format!(
                "{key}.orientation orients bodies: set {key}.shape or {key}.shapes"
            )));
        }
        return Ok(None);
    }
    let refuse = |what: &str, why: &str| {
        Err(Error::input(format!(
            "{key}.{what} with an inlet of bodies: {why}"
        )))
    };
    if spec.shape.is_some() && !spec.shapes.is_empty() {
        return refuse(
            "shape and shapes",
            "both given; one shape, or a mixture of shapes",
        );
    }
    if spec.size.is_some() {
        return refuse(
            "size",
            "a size distribution draws sphere diameters; a body's size comes from its \
             shape (scale in [[shapes]])",
        );
    }
    if spec.materials.is_some() {
        return refuse(
            "materials",
            "a body's mass comes from its shape in particles.material; bodies of other \
             materials are not supported",
        );
    }
    if spec
        .kind
        .is_some_and(|k| s.particles.frozen_types.contains(&k))
    {
        return refuse(
            "kind",
            "particles.frozen_types holds it, and bodies cannot be frozen",
        );
    }
    if let Some(o) = &spec.orientation {
        orientation(o, s.dimension.axes(), &format!("{key}.orientation"))?;
    }
    if let Some(name) = &spec.shape {
        return Ok(Some(vec![(
            shapes::index(s, name, &format!("{key}.shape"))?,
            1.0,
        )]));
    }
    let mut out: Vec<(usize, f64)> = Vec::new();
    for (k, e) in spec.shapes.iter().enumerate() {
        let at = format!("{key}.shapes[{k}]");
        let i = shapes::index(s, &e.name, &format!("{at}.name"))?;
        if !(e.fraction.is_finite() && e.fraction > 0.0) {
            return Err(Error::input(format!(
                "{at}.fraction = {}: must be positive",
                e.fraction
            )));
        }
        if out.iter().any(|&(j, _)| j == i) {
            return Err(Error::input(format!(
                "{at}.name = \"{}\" appears twice in the mixture",
                e.name
            )));
        }
        out.push((i, e.fraction));
    }
    let sum: f64 = out.iter().map(|x| x.1).sum();
    if (sum - 1.0).abs() > 1e-6 {
        return Err(Error::input(format!(
            "{key}.shapes: the fractions sum to {sum}; they must sum to 1"
        )));
    }
    Ok(Some(out))
}

/// The bodies an inlet brings: their shapes, how they are drawn, their kind.
#[derive(Clone, Debug)]
pub struct BodyMix<D: Dim> {
    /// Shape index and the running sum of the fractions up to it.
    cumulative: Vec<(usize, f64)>,
    /// The run's shapes (all of them: an index is the engine's) and their
    /// bounding radii and input frames.
    pub shapes: Vec<Shape<D>>,
    props: Vec<Props>,
    /// A fixed orientation of the shape as written (`None`: random).
    fixed: Option<DQuat>,
    pub kind: u32,
}

impl<D: Dim> BodyMix<D> {
    /// The mixture of `shares` (from [`shares`]) over the run's shapes.
    pub fn new(
        spec: &InletSpec,
        key: &str,
        shares: &[(usize, f64)],
        shapes: &[Shape<D>],
        props: &[Props],
    ) -> Result<Self> {
        let mut sum = 0.0;
        let cumulative = (shares.iter())
            .map(|&(i, f)| {
                sum += f;
                (i, sum)
            })
            .collect();
        let fixed = match &spec.orientation {
            Some(o) => orientation(o, D::D, &format!("{key}.orientation"))?,
            None => None,
        };
        Ok(Self {
            cumulative,
            shapes: shapes.to_vec(),
            props: props.to_vec(),
            fixed,
            kind: spec.kind.unwrap_or(1),
        })
    }

    /// A body's shape, by number fraction, from its shape stream.
    pub fn pick(&self, rng: &mut Xoshiro256PlusPlus) -> usize {
        let u: f64 = rng.gen::<f64>() * self.cumulative.last().map_or(1.0, |c| c.1);
        (self.cumulative.iter())
            .find(|c| u < c.1)
            .or(self.cumulative.last())
            .map_or(0, |c| c.0)
    }

    /// A body's orientation (principal frame to space): the fixed one, or
    /// uniform on rotations (Shoemake's method) from its turn stream.
    pub fn turn(&self, shape: usize, rng: &mut Xoshiro256PlusPlus) -> DQuat {
        match self.fixed {
            Some(q) => q * self.props[shape].to_input,
            None => random_orientation(rng, D::D),
        }
    }

    /// The bounding radius of a shape (its centre of mass to its farthest
    /// sub-sphere surface).
    pub fn bound(&self, shape: usize) -> f64 {
        self.props[shape].bounding_radius
    }

    /// The shapes the inlet draws from.
    fn used(&self) -> impl Iterator<Item = &Shape<D>> + '_ {
        self.cumulative.iter().map(|c| &self.shapes[c.0])
    }

    /// The largest bounding radius of the shapes drawn.
    pub fn widest(&self) -> f64 {
        (self.cumulative.iter())
            .map(|c| self.bound(c.0))
            .fold(0.0, f64::max)
    }

    /// The largest sub-sphere radius of the shapes drawn.
    pub fn largest_sub(&self) -> f64 {
        (self.used().flat_map(|s| &s.spheres))
            .map(|s| s.radius)
            .fold(0.0, f64::max)
    }

    /// The smallest sub-sphere radius of the shapes drawn.
    pub fn smallest_sub(&self) -> f64 {
        (self.used().flat_map(|s| &s.spheres))
            .map(|s| s.radius)
            .fold(f64::INFINITY, f64::min)
    }

    /// The lightest body drawn (kg).
    pub fn lightest(&self) -> f64 {
        self.used().map(|s| s.mass).fold(f64::INFINITY, f64::min)
    }

    /// The shapes and fractions, for `grains check`.
    pub fn report(&self) -> serde_json::Value {
        let mut last = 0.0;
        let rows: Vec<_> = (self.cumulative.iter())
            .map(|&(i, c)| {
                let f = c - last;
                last = c;
                serde_json::json!({
                    "name": self.shapes[i].name,
                    "fraction": f,
                    "mass": self.shapes[i].mass,
                    "bounding_radius": self.bound(i),
                    "sub_spheres": self.shapes[i].spheres.len(),
                })
            })
            .collect();
        serde_json::Value::Array(rows)
    }
}

/// The sub-spheres of `shape` with its centre of mass at `p`, turned by `q`.
pub fn sub_spheres<D: Dim>(
    shape: &Shape<D>,
    p: D::V,
    q: DQuat,
) -> impl Iterator<Item = (D::V, f64)> + '_ {
    (shape.spheres.iter()).map(move |s| (placed::<D>(p, q, s.center), s.radius))
}
