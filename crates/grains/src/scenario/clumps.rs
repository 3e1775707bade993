//! Bodies made of `[[shapes]]`: which shape each placed body has (one, or
//! a mixture by number), its orientation (fixed, or uniform on rotations),
//! its position on a lattice or at random with no sub-sphere overlapping
//! another body, a grain or a wall, and the bodies of `particles.add`.
//! What a run with bodies does not do is refused here by name.

use super::keys::{angular, vector};
use super::placement::{lattice, stream, velocities, STREAM_POSITIONS};
use super::schema::{OrientationSpec, Placement, Scenario};
use super::shapes;
use super::Loaded;
use crate::boundary::Wall;
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::particles::Particles;
use crate::rigid::shape::{placed, wxyz, Props};
use crate::rigid::{BodySpec, Shape};
use glam::DQuat;
use rand::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde_json::{json, Map, Value};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Stream purposes (see `placement::stream`): the orientations of placed
/// bodies and the order of a mixture's shapes.
pub const STREAM_ORIENTATIONS: u64 = 4;
pub const STREAM_SHAPES: u64 = 5;

/// Largest departure of a written quaternion's norm from 1 that is taken
/// for rounding and normalised away.
pub const UNIT_TOLERANCE: f64 = 1e-3;

/// The shapes of a run and the bodies to make of them.
#[derive(Clone, Debug)]
pub struct Clumps<D: Dim> {
    pub shapes: Vec<Shape<D>>,
    pub props: Vec<Props>,
    pub bodies: Vec<BodySpec<D>>,
}

impl<D: Dim> Clumps<D> {
    /// The widest sub-sphere of any shape (m), 0 without shapes.
    pub fn max_sub_diameter(&self) -> f64 {
        (self.shapes.iter().flat_map(|s| &s.spheres))
            .map(|s| 2.0 * s.radius)
            .fold(0.0, f64::max)
    }

    /// What `grains check` prints: each shape, and how many bodies of it.
    pub fn report(&self, s: &Scenario) -> Value {
        let mut count = vec![0usize; self.shapes.len()];
        for b in &self.bodies {
            count[b.shape] += 1;
        }
        let list: Vec<Value> = (self.shapes.iter().zip(&self.props).zip(&count))
            .map(|((sh, p), &n)| shapes::report(sh, p, s.particles.mass_model, n))
            .collect();
        let mut by_name = Map::new();
        for (sh, &n) in self.shapes.iter().zip(&count) {
            by_name.insert(sh.name.clone(), json!(n));
        }
        json!({ "shapes": list, "bodies": by_name, "total": self.bodies.len() })
    }
}

/// Whether the scenario makes bodies.
pub fn uses_bodies(s: &Scenario) -> bool {
    places_bodies(s)
        || s.particles.add.iter().any(|a| a.shape.is_some())
        || (s.inlets.iter()).any(|i| i.shape.is_some() || !i.shapes.is_empty())
}

/// Whether lattice or random placement makes bodies instead of spheres.
pub fn places_bodies(s: &Scenario) -> bool {
    s.particles.shape.is_some() || !s.particles.shapes.is_empty()
}

/// The keys of clumps checked when the scenario is loaded, and what a run
/// with bodies does not do refused by name.
pub fn check(s: &Scenario) -> Result<()> {
    shapes::check_names(s)?;
    let ps = &s.particles;
    for (k, a) in ps.add.iter().enumerate() {
        if a.shape.is_none() && a.orientation.is_some() {
            return Err(Error::input(format!(
                "particles.add[{k}].orientation is a body's: give the entry a shape"
            )));
        }
        if let Some(name) = &a.shape {
            shapes::index(s, name, &format!("particles.add[{k}].shape"))?;
        }
    }
    if !places_bodies(s) && ps.orientation.is_some() {
        return Err(Error::input(
            "particles.orientation orients placed bodies: set particles.shape or particles.shapes",
        ));
    }
    if !uses_bodies(s) {
        return Ok(());
    }
    let refuse = |what: &str, why: &str| {
        Err(Error::input(format!(
            "{what} with bodies of [[shapes]]: {why}"
        )))
    };
    if s.method == crate::settings::Method::Dsmc {
        return refuse(
            "method = \"dsmc\"",
            "clumps are grains of the MD engine only",
        );
    }
    if s.hopper.as_ref().is_some_and(|h| h.recycle) {
        return refuse(
            "[hopper] with recycle = true",
            "its recycling moves grains one by one and would tear a body apart; \
             set hopper.recycle = false and take bodies out through [[outlets]]",
        );
    }
    if s.run.events.as_ref().is_some_and(|e| e.sink.is_some()) {
        return refuse(
            "run.events.sink",
            "it parks grains one by one and would tear a body apart; take bodies out \
             through [[outlets]]",
        );
    }
    if s.domain.shear.is_some() {
        return refuse(
            "domain.shear",
            "its start profile and barostat move grains one by one, not whole bodies",
        );
    }
    if ps.shape.is_some() && !ps.shapes.is_empty() {
        return Err(Error::input(
            "particles.shape and particles.shapes both given: one shape, or a mixture",
        ));
    }
    if places_bodies(s) {
        match ps.placement {
            Placement::Lattice | Placement::Random => {}
            Placement::File => {
                return refuse(
                    "particles.placement = \"file\"",
                    "particle files hold spheres; place bodies on a lattice, at random or \
                     by particles.add",
                )
            }
            Placement::Packed => {
                return refuse(
                    "particles.placement = \"packed\"",
                    "the packed fill grows spheres, not bodies; place bodies on a lattice, \
                     at random or by particles.add",
                )
            }
            Placement::None => {
                return Err(Error::input(
                    "particles.shape: placement = \"none\" places no bodies; \
                     use \"lattice\" or \"random\", or particles.add entries with a shape",
                ))
            }
        }
        if ps.size.is_some() || ps.width != 0.0 {
            return Err(Error::input(
                "particles.size and particles.width draw sphere diameters; bodies take their \
                 size from [[shapes]] (scale)",
            ));
        }
        if let Some(name) = &ps.shape {
            shapes::index(s, name, "particles.shape")?;
        }
        mixture(s)?;
        if let Some(o) = &ps.orientation {
            orientation(o, s.dimension.axes(), "particles.orientation")?;
        }
        if ps.frozen_types.contains(&1) {
            return Err(Error::input(
                "particles.frozen_types holds 1, the kind of placed bodies: bodies cannot be frozen",
            ));
        }
    }
    for (k, a) in ps.add.iter().enumerate().filter(|(_, a)| a.shape.is_some()) {
        let key = format!("particles.add[{k}]");
        if a.diameter.is_some() {
            return Err(Error::input(format!(
                "{key}.diameter: a body's size comes from its shape"
            )));
        }
        if a.frozen || a.kind.is_some_and(|t| ps.frozen_types.contains(&t)) {
            return Err(Error::input(format!(
                "{key}.frozen: bodies cannot be frozen (a frozen clump is a wall: use a mesh wall)"
            )));
        }
        if a.material.is_some() && a.material != ps.material {
            return Err(Error::input(format!(
                "{key}.material: a body's mass comes from its shape in particles.material; \
                 bodies of another material are not supported"
            )));
        }
        if let Some(q) = &a.orientation {
            let q = OrientationSpec::Quaternion(q.clone());
            orientation(&q, s.dimension.axes(), &format!("{key}.orientation"))?;
        }
    }
    Ok(())
}

/// The mixture's shape indices and fractions, checked.
fn mixture(s: &Scenario) -> Result<Vec<(usize, f64)>> {
    let ps = &s.particles;
    if let Some(name) = &ps.shape {
        return Ok(vec![(shapes::index(s, name, "particles.shape")?, 1.0)]);
    }
    let mut out = Vec::new();
    for (k, e) in ps.shapes.iter().enumerate() {
        let key = format!("particles.shapes[{k}]");
        let i = shapes::index(s, &e.name, &format!("{key}.name"))?;
        if !(e.fraction.is_finite() && e.fraction > 0.0) {
            return Err(Error::input(format!(
                "{key}.fraction = {}: must be positive",
                e.fraction
            )));
        }
        if out.iter().any(|&(j, _)| j == i) {
            return Err(Error::input(format!(
                "{key}.name = \"{}\" appears twice in the mixture",
                e.name
            )));
        }
        out.push((i, e.fraction));
    }
    let sum: f64 = out.iter().map(|x| x.1).sum();
    if (sum - 1.0).abs() > 1e-6 {
        return Err(Error::input(format!(
            "particles.shapes: the fractions sum to {sum}; they must sum to 1"
        )));
    }
    Ok(out)
}

/// A fixed orientation checked (four finite numbers of norm 1 within
/// [`UNIT_TOLERANCE`], normalised; in 2D a turn about z), or `None` for
/// "random".
pub fn orientation(o: &OrientationSpec, axes: usize, key: &str) -> Result<Option<DQuat>> {
    match o {
        OrientationSpec::Word(w) if w == "random" => Ok(None),
        OrientationSpec::Word(w) => Err(Error::input(format!(
            "{key} = \"{w}\": allowed are \"random\" or a unit quaternion [w, x, y, z]"
        ))),
        OrientationSpec::Quaternion(q) => {
            if q.len() != 4 || q.iter().any(|x| !x.is_finite()) {
                return Err(Error::input(format!(
                    "{key} = {q:?}: a quaternion is four finite numbers [w, x, y, z]"
                )));
            }
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > UNIT_TOLERANCE {
                return Err(Error::input(format!(
                    "{key} = {q:?} has norm {norm}: a rotation is a unit quaternion \
                     (w² + x² + y² + z² = 1, within {UNIT_TOLERANCE})"
                )));
            }
            if axes == 2 && (q[1] != 0.0 || q[2] != 0.0) {
                return Err(Error::input(format!(
                    "{key} = {q:?}: a 2d body turns about z only, so x = y = 0 \
                     ([cos(θ/2), 0, 0, sin(θ/2)] for a turn by θ)"
                )));
            }
            Ok(Some(
                crate::rigid::shape::quat([q[0], q[1], q[2], q[3]]).normalize(),
            ))
        }
    }
}

/// A rotation uniform on rotations: Shoemake's method (Graphics Gems III,
/// 1992, "Uniform random rotations") from three uniform numbers in 3D, a
/// uniform turn about z in 2D.
pub fn random_orientation(rng: &mut Xoshiro256PlusPlus, axes: usize) -> DQuat {
    if axes == 2 {
        let theta = 2.0 * PI * rng.gen::<f64>();
        return DQuat::from_rotation_z(theta);
    }
    let (u1, u2, u3): (f64, f64, f64) = (rng.gen(), rng.gen(), rng.gen());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (t2, t3) = (2.0 * PI * u2, 2.0 * PI * u3);
    DQuat::from_xyzw(a * t2.sin(), a * t2.cos(), b * t3.sin(), b * t3.cos())
}

/// Shape indices for `count` bodies: each shape's count the nearest to
/// its fraction (largest remainders), the order shuffled from the
/// scenario's shape stream.
pub fn assign(mix: &[(usize, f64)], count: usize, seed: u64) -> Vec<usize> {
    let exact: Vec<f64> = mix.iter().map(|m| m.1 * count as f64).collect();
    let mut n: Vec<usize> = exact.iter().map(|x| x.floor() as usize).collect();
    let mut order: Vec<usize> = (0..mix.len()).collect();
    order.sort_by(|&i, &j| (exact[j] - n[j] as f64).total_cmp(&(exact[i] - n[i] as f64)));
    let short = count.saturating_sub(n.iter().sum());
    for &i in order.iter().take(short) {
        n[i] += 1;
    }
    let mut out: Vec<usize> = (mix.iter().zip(&n))
        .flat_map(|(m, &k)| std::iter::repeat_n(m.0, k))
        .collect();
    let mut rng = stream(seed, STREAM_SHAPES);
    for i in (1..out.len()).rev() {
        let j = rng.gen_range(0..=i);
        out.swap(i, j);
    }
    out
}

/// The scenario's shapes and bodies; `grains` are the spheres already
/// placed and `walls` the run's walls, which no body may overlap by more
/// than `tolerance` of the smaller radius (random bodies not at all).
pub fn bodies<D: Dim>(
    loaded: &Loaded,
    dom: &Domain<D>,
    walls: &[Wall<D>],
    grains: &Particles<D>,
    tolerance: f64,
) -> Result<Clumps<D>> {
    let s = &loaded.scenario;
    let ps = &s.particles;
    let (shapes, props) = shapes::build::<D>(loaded)?;
    let mut bodies = Vec::new();
    if !uses_bodies(s) {
        return Ok(Clumps {
            shapes,
            props,
            bodies,
        });
    }
    let mut room = Room::<D>::new(&shapes, grains);
    if places_bodies(s) && ps.count == 0 {
        return Err(Error::input(
            "particles.count must be at least 1 for lattice or random placement of bodies",
        ));
    }
    if places_bodies(s) {
        let (lo, hi) = match &ps.region {
            Some(r) => (
                vector::<D>("particles.region.lo", &r.lo)?,
                vector::<D>("particles.region.hi", &r.hi)?,
            ),
            None => (dom.lo, dom.hi),
        };
        let which = assign(&mixture(s)?, ps.count, s.seed);
        let fixed = match &ps.orientation {
            Some(o) => orientation(o, D::D, "particles.orientation")?,
            None => None,
        };
        let mut turns = stream(s.seed, STREAM_ORIENTATIONS);
        let turn: Vec<DQuat> = (which.iter())
            .map(|_| fixed.unwrap_or_else(|| random_orientation(&mut turns, D::D)))
            .collect();
        let pos = if ps.placement == Placement::Lattice {
            let widest = (which.iter())
                .map(|&i| props[i].bounding_radius)
                .fold(0.0, f64::max);
            lattice::<D>(lo, hi, 2.0 * widest * ps.spacing, ps.count)?
        } else {
            let mut rng = stream(s.seed, STREAM_POSITIONS);
            let mut out = Vec::with_capacity(which.len());
            for (n, (&i, &q)) in which.iter().zip(&turn).enumerate() {
                let q = q * props[i].to_input;
                let bound = props[i].bounding_radius;
                out.push(room.random_spot(&shapes[i], bound, q, (lo, hi), walls, &mut rng, n)
                    .ok_or_else(|| Error::input(format!(
                        "could not place body {} of {} (shape \"{}\") at random without overlap; \
                         the region is too dense: enlarge particles.region or lower particles.count",
                        n + 1, which.len(), shapes[i].name
                    )))?);
            }
            out
        };
        let vel = velocities::<D>(ps.count, ps.random_velocity, s.seed);
        for (k, &i) in which.iter().enumerate() {
            bodies.push(BodySpec {
                shape: i,
                kind: 1,
                pos: pos[k],
                orientation: wxyz(turn[k] * props[i].to_input),
                vel: vel[k],
                omega: D::ang_from_xyz([0.0; 3]),
            });
        }
    }
    for (k, a) in ps.add.iter().enumerate() {
        let Some(name) = &a.shape else { continue };
        let key = format!("particles.add[{k}]");
        let i = shapes::index(s, name, &format!("{key}.shape"))?;
        let q = match &a.orientation {
            Some(q) => orientation(
                &OrientationSpec::Quaternion(q.clone()),
                D::D,
                &format!("{key}.orientation"),
            )?
            .unwrap_or(DQuat::IDENTITY),
            None => DQuat::IDENTITY,
        };
        bodies.push(BodySpec {
            shape: i,
            kind: a.kind.unwrap_or(1),
            pos: vector::<D>(&format!("{key}.position"), &a.position)?,
            orientation: wxyz(q * props[i].to_input),
            vel: match &a.velocity {
                Some(v) => vector::<D>(&format!("{key}.velocity"), v)?,
                None => D::zero(),
            },
            omega: match &a.omega {
                Some(w) => angular::<D>(&format!("{key}.omega"), w)?,
                None => D::ang_from_xyz([0.0; 3]),
            },
        });
    }
    // Random bodies are clear of everything by construction; lattice and
    // added ones are not: all are checked, in a room of the grains alone.
    Room::<D>::new(&shapes, grains).check(&shapes, &bodies, walls, tolerance)?;
    Ok(Clumps {
        shapes,
        props,
        bodies,
    })
}

/// Spheres in space on a hash grid of cells as wide as the widest sphere,
/// for the overlap tests of placement.
struct Room<D: Dim> {
    cell: f64,
    grid: HashMap<[i64; 3], Vec<usize>>,
    /// Centre, radius and owner (a body index, or `usize::MAX` for a grain).
    spheres: Vec<(D::V, f64, usize)>,
}

impl<D: Dim> Room<D> {
    fn new(shapes: &[Shape<D>], grains: &Particles<D>) -> Self {
        let widest = (shapes.iter().flat_map(|s| &s.spheres))
            .map(|s| 2.0 * s.radius)
            .fold(2.0 * grains.max_radius(), f64::max);
        let mut room = Room {
            cell: widest.max(1e-300),
            grid: HashMap::new(),
            spheres: Vec::new(),
        };
        for i in 0..grains.n_owned() {
            room.insert(grains.pos[i], grains.radius[i], usize::MAX);
        }
        room
    }

    fn key(&self, p: D::V) -> [i64; 3] {
        let mut k = [0; 3];
        for (a, c) in k.iter_mut().enumerate().take(D::D) {
            *c = (D::get(p, a) / self.cell).floor() as i64;
        }
        k
    }

    fn insert(&mut self, p: D::V, r: f64, owner: usize) {
        let k = self.key(p);
        self.grid.entry(k).or_default().push(self.spheres.len());
        self.spheres.push((p, r, owner));
    }

    /// The deepest overlap of a sphere with those of other owners, as a
    /// fraction of the smaller radius, and that owner.
    fn worst(&self, p: D::V, r: f64, owner: usize) -> Option<(f64, usize)> {
        let k = self.key(p);
        let mut worst: Option<(f64, usize)> = None;
        for o in 0..3usize.pow(D::D as u32) {
            let mut kk = k;
            let mut rest = o;
            for c in kk.iter_mut().take(D::D) {
                *c += (rest % 3) as i64 - 1;
                rest /= 3;
            }
            for &j in self.grid.get(&kk).into_iter().flatten() {
                let (q, rq, who) = self.spheres[j];
                if who == owner && owner != usize::MAX {
                    continue;
                }
                let depth = (r + rq - D::norm(p - q)) / r.min(rq);
                if depth > 0.0 && worst.is_none_or(|w| depth > w.0) {
                    worst = Some((depth, who));
                }
            }
        }
        worst
    }

    /// A centre of mass in [lo + R, hi − R] (R the bounding radius) where
    /// the body turned by `q` overlaps nothing, from `rng`; its spheres
    /// are then in the room as `owner`'s.
    #[allow(clippy::too_many_arguments)]
    fn random_spot(
        &mut self,
        shape: &Shape<D>,
        bound: f64,
        q: DQuat,
        (lo, hi): (D::V, D::V),
        walls: &[Wall<D>],
        rng: &mut Xoshiro256PlusPlus,
        owner: usize,
    ) -> Option<D::V> {
        for _attempt in 0..10_000 {
            let mut p = D::zero();
            for a in 0..D::D {
                let (l, h) = (D::get(lo, a) + bound, D::get(hi, a) - bound);
                if h <= l {
                    return None;
                }
                D::set(&mut p, a, rng.gen_range(l..h));
            }
            let clear = shape.spheres.iter().all(|s| {
                let c = placed::<D>(p, q, s.center);
                self.worst(c, s.radius, owner).is_none()
                    && walls.iter().all(|w| w.contact(c, s.radius, 0.0).is_none())
            });
            if clear {
                for s in &shape.spheres {
                    self.insert(placed::<D>(p, q, s.center), s.radius, owner);
                }
                return Some(p);
            }
        }
        None
    }

    /// Every body's sub-spheres against the grains, the other bodies and
    /// the walls, within `tol` of the smaller radius.
    fn check(
        &mut self,
        shapes: &[Shape<D>],
        bodies: &[BodySpec<D>],
        walls: &[Wall<D>],
        tol: f64,
    ) -> Result<()> {
        for (b, body) in bodies.iter().enumerate() {
            let q = crate::rigid::shape::quat(body.orientation);
            for s in &shapes[body.shape].spheres {
                let c = placed::<D>(body.pos, q, s.center);
                if let Some((depth, who)) = self.worst(c, s.radius, b) {
                    if depth > tol {
                        let other = if who == usize::MAX {
                            "a grain".to_string()
                        } else {
                            format!("body {}", who + 1)
                        };
                        return Err(Error::input(format!(
                            "body {} (shape \"{}\") overlaps {other} by {:.1}% of the smaller \
                             radius (at most {:.0}% allowed); move them apart or enlarge \
                             particles.spacing / particles.region",
                            b + 1,
                            shapes[body.shape].name,
                            100.0 * depth,
                            100.0 * tol
                        )));
                    }
                }
                for w in walls {
                    if let Some(wc) = w.contact(c, s.radius, 0.0) {
                        if wc.overlap / s.radius > tol {
                            return Err(Error::input(format!(
                                "body {} (shape \"{}\") overlaps wall \"{}\" by {:.1}% of a \
                                 sub-sphere's radius (at most {:.0}% allowed); move it or the wall",
                                b + 1,
                                shapes[body.shape].name,
                                w.name,
                                100.0 * wc.overlap / s.radius,
                                100.0 * tol
                            )));
                        }
                    }
                }
            }
            for s in &shapes[body.shape].spheres {
                self.insert(placed::<D>(body.pos, q, s.center), s.radius, b);
            }
        }
        Ok(())
    }
}
