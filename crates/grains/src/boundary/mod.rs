//! Walls and obstacles: geometry, prescribed motions, contacts with grains.
//!
//! A grain touching a wall feels the same forces as if it met a grain of
//! diameter d0 at the contact point; the wall does not respond. This module
//! only finds the contact (overlap, normal, point) and the wall's velocity
//! there; the force law lives in [`crate::contact`].
//!
//! A [`Wall`] is a [`Shape`] in its reference (t = 0) position plus a
//! [`Motion`]. A contact at time t is found by carrying the particle into the
//! wall's reference frame (undoing the motion's translation and rotation),
//! meeting it with the reference shape, and carrying the normal and contact
//! point back; the velocity is the motion's velocity at the contact point.
//! Internally every computation is done on 3-vectors, 2D ones lying in the
//! z = 0 plane, so each shape has one implementation for both dimensions.
//!
//! Conventions: a particle exactly touching (overlap 0) is not in contact.
//! Planes and cylinders are one-sided surfaces; a particle whose centre has
//! crossed one is pushed back, but one wholly behind it (signed distance
//! below −r) is treated as lost and feels nothing. Segments, polygons,
//! obstacles and meshes are two-sided. A mesh answers with several contacts
//! where it bends ([`PlacedWall::mesh_contacts`]).

mod flat;
mod geom;
mod mesh;
mod motion;
mod round;
mod shape;

pub use mesh::{Mesh, MeshCandidates, MeshPlacement, MeshScratch, CREASE_DEG};
use motion::Pose;
pub use motion::{Motion, PlateSurface, ServoState};
pub use shape::Shape;

use crate::dim::Dim;
use crate::error::{Error, Result};
use geom::{from3, to3};
use serde::{Deserialize, Serialize};

/// A grain touching a wall.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallContact<D: Dim> {
    /// Positive overlap: radius minus the distance from the centre to the
    /// wall surface (for obstacles r + d1/2 − |p − c|).
    pub overlap: f64,
    /// Unit vector from the wall toward the particle centre.
    pub normal: D::V,
    /// Contact point on the wall surface.
    pub point: D::V,
    /// The wall's velocity at the contact point (prescribed motion).
    pub velocity: D::V,
}

/// A wall: a named shape with a prescribed motion, possibly removed at a time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(bound(
    serialize = "D::V: Serialize, D::A: Serialize",
    deserialize = "D::V: Deserialize<'de>, D::A: Deserialize<'de>"
))]
pub struct Wall<D: Dim> {
    pub name: String,
    pub shape: Shape<D>,
    pub motion: Motion<D>,
    /// Seconds: the wall disappears at this time (e.g. the side wall taken
    /// away in an angle-of-repose run). `None`: it stays.
    pub remove_at: Option<f64>,
    /// How the plate meets a grain under a modulated vibration. Left out
    /// of the serialized form when it is the default, as `elastic` is, so
    /// that files written from walls read as they did before the option.
    #[serde(default, skip_serializing_if = "PlateSurface::is_curved")]
    surface: PlateSurface,
    /// Whether contacts with this wall have no normal damping (γ_n = 0)
    /// whatever the grains' law (their shear friction stays).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    elastic: bool,
}

impl<D: Dim> Wall<D> {
    /// A wall that is never removed. Checks the shape and motion, normalizes
    /// normals, axes and directions, and names the wall in any error.
    pub fn new(name: impl Into<String>, shape: Shape<D>, motion: Motion<D>) -> Result<Self> {
        let name = name.into();
        let mut shape = shape;
        let mut motion = motion;
        shape.validate().map_err(|e| {
            Error::input(format!("wall '{name}' ({} {}): {e}", D::NAME, shape.kind()))
        })?;
        motion
            .validate()
            .map_err(|e| Error::input(format!("wall '{name}' ({} motion): {e}", motion.kind())))?;
        if let Motion::Servo { normal, .. } = &mut motion {
            // The servo moves the plane along its own normal.
            let Shape::Plane { normal: n, .. } = &shape else {
                return Err(Error::input(format!(
                    "wall '{name}': motion type \"servo\" needs a wall of shape type \"plane\" \
                     (a line in 2D), moved along its normal; this one is a {} {}",
                    D::NAME,
                    shape.kind()
                )));
            };
            *normal = *n;
        }
        if motion.is_modulated() {
            let flat_across_x =
                matches!(&shape, Shape::Plane { normal, .. } if D::get(*normal, 0).abs() < 1e-12);
            if !flat_across_x {
                return Err(Error::input(format!(
                    "wall '{name}': a modulated vibration (modulation ≠ 0) needs a plane wall \
                     whose normal is perpendicular to x (a bottom plate); this one is a {} {}",
                    D::NAME,
                    shape.kind()
                )));
            }
        }
        Ok(Self {
            name,
            shape,
            motion,
            remove_at: None,
            surface: PlateSurface::default(),
            elastic: false,
        })
    }

    /// The same wall with the plate reading `surface` (it matters only
    /// under a modulated vibration; any other wall is unchanged by it).
    pub fn with_surface(mut self, surface: PlateSurface) -> Self {
        self.surface = surface;
        self
    }

    /// The same wall, elastic (`true`: its contacts have γ_n = 0) or
    /// damped like the grains' contacts (`false`, the default).
    pub fn with_elastic(mut self, elastic: bool) -> Self {
        self.elastic = elastic;
        self
    }

    /// Whether contacts with this wall have no normal damping.
    pub fn is_elastic(&self) -> bool {
        self.elastic
    }

    /// The same wall, removed at time `t` (seconds).
    pub fn with_remove_at(mut self, t: f64) -> Result<Self> {
        if t.is_nan() {
            return Err(Error::input(format!(
                "wall '{}': removal time is not a number",
                self.name
            )));
        }
        self.remove_at = Some(t);
        Ok(self)
    }

    /// Whether the wall exists at time `t` (it is gone from `remove_at` on).
    pub fn is_active(&self, t: f64) -> bool {
        match self.remove_at {
            Some(tr) => t < tr,
            None => true,
        }
    }

    /// Contact of a particle at `p` with radius `r` at time `t`; `None` when
    /// not touching (overlap ≤ 0), lost behind a one-sided surface, or the
    /// wall has been removed. For many grains at one time, place the wall
    /// once with [`Wall::at`].
    pub fn contact(&self, p: D::V, r: f64, t: f64) -> Option<WallContact<D>> {
        self.at(t).contact(p, r)
    }

    /// The wall at time `t`, with what its motion gives the same for every
    /// grain (its pose, its velocity where that is uniform, whether it is
    /// still there) worked out once: a force evaluation meets every grain
    /// with it, and a sine or a rotation per grain would cost more than the
    /// geometry.
    pub fn at(&self, t: f64) -> PlacedWall<'_, D> {
        // A modulated vibration's pose depends on the grain's x; every other
        // motion's pose is the same at any x.
        let uniform = !self.motion.is_modulated();
        let pose = uniform.then(|| self.motion.pose(t, 0.0));
        PlacedWall {
            wall: self,
            t,
            active: self.is_active(t),
            pose,
            velocity: self.motion.uniform_velocity(t),
            quick: self.quick_test(pose.is_some()),
        }
    }

    /// The wall's quick test ([`QuickTest`]); `placed`: whether it has one
    /// pose for all grains.
    fn quick_test(&self, placed: bool) -> Option<QuickTest> {
        match &self.shape {
            Shape::Plane { point, normal } if placed => Some(QuickTest::Plane(PlaneTest {
                point: to3::<D>(*point),
                normal: to3::<D>(*normal),
            })),
            Shape::Plane { .. } => self.lifted_test().map(QuickTest::Lifted),
            Shape::Cylinder {
                point,
                axis,
                radius,
                inside,
            } if placed => Some(QuickTest::Cylinder(CylinderTest {
                point: to3::<D>(*point),
                axis: if D::D == 2 {
                    glam::DVec3::Z
                } else {
                    to3::<D>(*axis)
                },
                radius: *radius,
                inside: *inside,
            })),
            Shape::Cylinder { .. } => None,
            _ if placed => self
                .shape
                .bounding_box()
                .map(|b| QuickTest::Reach(ReachBox::around(b))),
            _ => None,
        }
    }

    /// The quick test of a plate under a modulated vibration, `None` for
    /// any other wall.
    fn lifted_test(&self) -> Option<LiftedTest> {
        let (Shape::Plane { point, normal }, Some((lift, slope))) =
            (&self.shape, self.motion.modulation_bounds())
        else {
            return None;
        };
        let along = D::dot(self.motion.vibration_direction()?, *normal).abs();
        let tilt = slope * along;
        Some(LiftedTest {
            point: to3::<D>(*point),
            normal: to3::<D>(*normal),
            // Inflated as the margins of [`LiftedTest`] say.
            lift: lift * along * (1.0 + 1e-9),
            root: (1.0 + tilt * tilt).sqrt() * (1.0 + 1e-9),
        })
    }

    /// Contact with a plate under a modulated vibration: the lifted, tilted
    /// plane of [`flat::lifted_plane`]. `new` admits modulation on planes
    /// whose normal is perpendicular to x only.
    fn modulated_contact(&self, p: D::V, r: f64, t: f64, slope: f64) -> Option<WallContact<D>> {
        let Shape::Plane { point, normal } = &self.shape else {
            return None;
        };
        let n = to3::<D>(*normal);
        let along = D::dot(self.motion.vibration_direction()?, *normal);
        let lift = self.motion.pose(t, D::get(p, 0)).shift.dot(n);
        let touch = flat::lifted_plane(to3::<D>(p), to3::<D>(*point), n, lift, slope * along, r)?;
        let point = from3::<D>(touch.point);
        Some(WallContact {
            overlap: touch.overlap,
            normal: from3::<D>(touch.normal),
            point,
            velocity: self.motion.velocity_at(point, t),
        })
    }

    /// Displacement of the wall's reference point
    /// ([`Shape::reference_point`]) at time `t`, for output and drawing.
    pub fn displacement(&self, t: f64) -> D::V {
        let x = self.shape.reference_point();
        self.motion.place(x, t) - x
    }

    /// Velocity at time `t` of the wall material at position `q`.
    pub fn velocity_at(&self, q: D::V, t: f64) -> D::V {
        self.motion.velocity_at(q, t)
    }
}

/// A wall at one time ([`Wall::at`]).
#[derive(Clone, Copy, Debug)]
pub struct PlacedWall<'a, D: Dim> {
    wall: &'a Wall<D>,
    t: f64,
    active: bool,
    /// The pose, unless it depends on the grain (modulated vibration).
    pose: Option<Pose>,
    /// The velocity, where it is the same at every point of the wall.
    velocity: Option<D::V>,
    quick: Option<QuickTest>,
}

/// What tells most grains apart from a wall at once, for the wall pass to
/// mark the grains a wall may touch in a tight loop over all of them
/// ([`PlacedWall::mark_near`]).
#[derive(Clone, Copy, Debug)]
enum QuickTest {
    /// A plane with one pose: its own exact test, in the reference frame.
    Plane(PlaneTest),
    /// A cylinder with one pose: its own exact test too.
    Cylinder(CylinderTest),
    /// A plate under a modulated vibration, in the world frame.
    Lifted(LiftedTest),
    /// A finite shape (segment, polygon, obstacle): its bounding box, in
    /// the reference frame.
    Reach(ReachBox),
}

/// The distance test of [`flat::plane`], on the grain carried into the
/// reference frame as the exact path carries it, so that it rejects
/// exactly the grains that path would.
#[derive(Clone, Copy, Debug)]
struct PlaneTest {
    point: glam::DVec3,
    normal: glam::DVec3,
}

impl PlaneTest {
    #[inline]
    fn misses(&self, local: glam::DVec3, r: f64) -> bool {
        flat::plane(local, self.point, self.normal, r).is_none()
    }
}

/// The distance test of [`round::cylinder`], run as [`PlaneTest`] runs
/// the plane's (same frame, same arithmetic, so the same grains turned
/// down). A drum or a pipe touches only its outer ring of grains, but
/// without this every grain went through the exact contact and its pose
/// at every step.
#[derive(Clone, Copy, Debug)]
struct CylinderTest {
    point: glam::DVec3,
    axis: glam::DVec3,
    radius: f64,
    inside: bool,
}

impl CylinderTest {
    #[inline]
    fn misses(&self, local: glam::DVec3, r: f64) -> bool {
        round::cylinder(local, self.point, self.axis, self.radius, self.inside, r).is_none()
    }
}

/// A plate under a modulated vibration cannot reach a grain farther in
/// front of its rest plane than the largest lift plus r √(1 + σ²), σ the
/// largest tilt ([`flat::lifted_plane`]: the distance to the tangent plane
/// is the distance to the lifted plane divided by that root). Grains are
/// turned down on those bounds alone, before the sines and cosines of the
/// exact test: most grains of a vibrated bed are far from its plate.
/// Margins of 1e-9 (relative, on the lift and on r √(1 + σ²)) keep the
/// test from turning down a grain that the exact test, with its own
/// rounding, would find touching; they assume a unit normal, as
/// [`Wall::new`] makes it.
#[derive(Clone, Copy, Debug)]
struct LiftedTest {
    point: glam::DVec3,
    normal: glam::DVec3,
    /// The largest lift along the normal, |A0| (1 + |B|) |d · n|, with
    /// its margin.
    lift: f64,
    /// √(1 + σ²) for the largest slope σ along the normal, with its margin.
    root: f64,
}

impl LiftedTest {
    #[inline]
    fn misses(&self, p: glam::DVec3, r: f64) -> bool {
        (p - self.point).dot(self.normal) - self.lift >= r * self.root
    }
}

/// A finite shape, and every contact point its test can find, lies inside
/// its bounding box ([`Shape::bounding_box`]): a grain (carried into the
/// wall's reference frame) more than r outside the box along some axis
/// cannot touch it, and is turned down before the shape's own test (a
/// polygon's is its normal and the closest point of its outline). The box
/// is widened by 1e-9 of its largest coordinate and the reach by 1e-9 of r,
/// so that the shape's test with its own rounding cannot find a contact the
/// box turned down.
#[derive(Clone, Copy, Debug)]
struct ReachBox {
    lo: glam::DVec3,
    hi: glam::DVec3,
}

impl ReachBox {
    fn around((lo, hi): (glam::DVec3, glam::DVec3)) -> Self {
        let pad = 1e-9 * lo.abs().max(hi.abs()).max_element();
        Self {
            lo: lo - glam::DVec3::splat(pad),
            hi: hi + glam::DVec3::splat(pad),
        }
    }

    #[inline]
    fn misses(&self, p: glam::DVec3, r: f64) -> bool {
        let reach = r * (1.0 + 1e-9);
        let below = (self.lo - p).max_element();
        let above = (p - self.hi).max_element();
        below >= reach || above >= reach
    }
}

impl<D: Dim> PlacedWall<'_, D> {
    /// Whether the wall moves by the grains' load on it (a servo), so that
    /// the force pass sums that load.
    pub fn is_servo(&self) -> bool {
        self.wall.motion.is_servo()
    }

    /// The wall's angular velocity: a rotating wall's ω, else zero.
    pub fn spin(&self) -> D::A {
        match &self.wall.motion {
            Motion::Rotate { omega, .. } => *omega,
            _ => D::A::default(),
        }
    }

    /// Sets `near` (one entry per grain of `pos` and `radius`) for the
    /// grains this wall may touch: those [`PlacedWall::contact`] does not
    /// turn down at once. The wall's [`QuickTest`] runs here over all the
    /// grains in a loop of its own, which the compiler keeps tight; a wall
    /// without one (a modulated cylinder, say) marks every grain.
    pub fn mark_near(&self, pos: &[D::V], radius: &[f64], near: &mut [bool]) {
        if !self.active {
            return;
        }
        let marks = (pos, radius, near);
        match (&self.quick, &self.pose) {
            (Some(QuickTest::Lifted(t)), _) => mark::<D>(marks, |p, r| t.misses(p, r)),
            (Some(QuickTest::Plane(t)), Some(pose)) => {
                mark_in_frame::<D>(marks, pose, |p, r| t.misses(p, r))
            }
            (Some(QuickTest::Cylinder(t)), Some(pose)) => {
                mark_in_frame::<D>(marks, pose, |p, r| t.misses(p, r))
            }
            (Some(QuickTest::Reach(b)), Some(pose)) => {
                mark_in_frame::<D>(marks, pose, |p, r| b.misses(p, r))
            }
            _ => marks.2.fill(true),
        }
    }

    /// Whether contacts with this wall have no normal damping
    /// ([`Wall::with_elastic`]).
    pub fn is_elastic(&self) -> bool {
        self.wall.elastic
    }

    /// [`Wall::contact`] at the time the wall was placed at.
    pub fn contact(&self, p: D::V, r: f64) -> Option<WallContact<D>> {
        if !self.active {
            return None;
        }
        let (wall, t) = (self.wall, self.t);
        let Some(pose) = self.pose else {
            if let Some(QuickTest::Lifted(test)) = &self.quick {
                if test.misses(to3::<D>(p), r) {
                    return None;
                }
            }
            let slope = wall.motion.modulation_slope(D::get(p, 0), t)?;
            return wall.modulated_contact(p, r, t, wall.surface.tilt(slope));
        };
        let local = pose.invert(to3::<D>(p));
        // A plane's or a cylinder's quick test is its exact test: not run
        // twice here.
        if let Some(QuickTest::Reach(b)) = &self.quick {
            if b.misses(local, r) {
                return None;
            }
        }
        let touch = wall.shape.touch(local, r)?;
        let point = from3::<D>(pose.apply(touch.point));
        Some(WallContact {
            overlap: touch.overlap,
            normal: from3::<D>(pose.turn(touch.normal)),
            point,
            velocity: match self.velocity {
                Some(v) => v,
                None => wall.motion.velocity_at(point, t),
            },
        })
    }
}

/// Marks in `near` the grains of `pos` and `radius` that `misses` does not
/// turn down (compiled for each test, so that the loop stays tight).
#[inline(always)]
fn mark<D: Dim>(
    (pos, radius, near): (&[D::V], &[f64], &mut [bool]),
    misses: impl Fn(glam::DVec3, f64) -> bool,
) {
    for ((m, &p), &r) in near.iter_mut().zip(pos).zip(radius) {
        *m |= !misses(to3::<D>(p), r);
    }
}

/// [`mark`] with `misses` in the wall's reference frame: grains carried
/// back by the shift alone when the pose is a translation (what
/// [`Pose::invert`] does then, without asking per grain).
#[inline(always)]
fn mark_in_frame<D: Dim>(
    marks: (&[D::V], &[f64], &mut [bool]),
    pose: &Pose,
    misses: impl Fn(glam::DVec3, f64) -> bool,
) {
    match pose.translation() {
        Some(shift) => mark::<D>(marks, |p, r| misses(p - shift, r)),
        None => mark::<D>(marks, |p, r| misses(pose.invert(p), r)),
    }
}

#[cfg(test)]
mod tests;
