//! Rigid clumps in the MD engine: bodies whose sub-spheres are grains.
//!
//! Each sub-sphere is a grain of the store (neighbour lists, walls, meshes
//! and outputs see spheres), tied to its body by its id. Per step, as
//! LAMMPS's `fix rigid/small`: the bodies' half-kick, drift and NO_SQUISH
//! rotation, then every sub-sphere put where its body says (position,
//! v + ω × r, ω) before the grain integrators run, which leave sub-spheres
//! alone; after the forces, each body sums its sub-spheres' forces and
//! torques, takes its second half-kick and gives its sub-spheres their new
//! velocities. Pairs within a body are dropped from the neighbour list.

use super::Md;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::io::BodyRow;
use crate::particles::ParticleRecord;
use crate::rigid::bodies::{Bodies, Body, BodyShape};
use crate::rigid::no_squish::{self, Turned};
use crate::rigid::{BodySpec, Shape};
use glam::DVec3;
use std::collections::HashMap;

/// A grain that belongs to no body.
pub(crate) const NO_BODY: u32 = u32::MAX;

/// The bodies of a run and their ties to the grain store.
#[derive(Clone, Debug, Default)]
pub(crate) struct Clumps {
    pub bodies: Bodies,
    /// Sub-sphere grain id → (body, sub-sphere in shape order).
    by_id: HashMap<u64, (u32, u32)>,
    /// Per grain in store order: its body, or [`NO_BODY`].
    pub grain_body: Vec<u32>,
    /// Each body's sub-spheres' grain indices, in shape order, body after
    /// body (body b's from `start[b]`; `start` ends with the total).
    members: Vec<u32>,
    start: Vec<usize>,
    /// Per grain: frozen or a sub-sphere, what the grain integrators leave
    /// alone (swapped in for `frozen` while they run) and gravity skips in
    /// the field pass (a body takes M g once, at its centre of mass).
    pub held: Vec<bool>,
    /// Per grain: the mass the contact laws see, a sub-sphere's body's.
    pub contact_mass: Vec<f64>,
    /// Per body: its rotation matrix and spin as its sub-spheres are
    /// placed (scratch, from the drift's turns or computed anew).
    turned: Vec<Turned>,
}

fn xyz<D: Dim>(v: D::V) -> DVec3 {
    DVec3::from_array(D::to_xyz(v))
}

fn ang<D: Dim>(a: D::A) -> DVec3 {
    DVec3::from_array(D::ang_to_xyz(a))
}

/// A shape in 3D terms, checked: positive mass and moments (in 2D the z
/// moment, the in-plane ones set to 0 so that bodies turn about z only).
fn body_shape<D: Dim>(s: Shape<D>) -> Result<BodyShape> {
    let bad = |what: String| Err(Error::input(format!("[[shapes]] \"{}\": {what}", s.name)));
    if s.spheres.is_empty() {
        return bad("has no spheres".into());
    }
    let inertia = if D::D == 2 {
        [0.0, 0.0, s.inertia[2]]
    } else {
        s.inertia
    };
    let moments = if D::D == 2 {
        &inertia[2..]
    } else {
        &inertia[..]
    };
    if !(s.mass.is_finite() && s.mass > 0.0) || moments.iter().any(|m| !(m.is_finite() && *m > 0.0))
    {
        return bad(format!(
            "mass {} and principal moments {:?} must be positive and finite",
            s.mass, s.inertia
        ));
    }
    if let Some(b) = s
        .spheres
        .iter()
        .find(|b| !(b.radius.is_finite() && b.radius > 0.0 && D::is_finite(b.center)))
    {
        return bad(format!("a sphere of radius {} is not a sphere", b.radius));
    }
    Ok(BodyShape {
        name: s.name.clone(),
        centers: s.spheres.iter().map(|b| xyz::<D>(b.center)).collect(),
        radii: s.spheres.iter().map(|b| b.radius).collect(),
        mass: s.mass,
        inertia,
    })
}

/// Checks each body against the new shapes: its shape index, a unit
/// quaternion (normalized), a finite motion; gives each its orientation
/// and space-frame spin.
fn check_bodies<D: Dim>(
    shapes: &[BodyShape],
    bodies: &[BodySpec<D>],
) -> Result<Vec<(no_squish::Quat, DVec3)>> {
    let mut out = Vec::with_capacity(bodies.len());
    for (k, spec) in bodies.iter().enumerate() {
        let bad = |what: String| Err(Error::input(format!("body {k}: {what}")));
        if spec.shape >= shapes.len() {
            return bad(format!(
                "shape index {} beyond the {} [[shapes]]",
                spec.shape,
                shapes.len()
            ));
        }
        let q = spec.orientation;
        let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        if norm.is_nan() || (norm - 1.0).abs() >= 1e-6 {
            return bad(format!(
                "orientation {q:?} is not a unit quaternion (w, x, y, z)"
            ));
        }
        let omega = ang::<D>(spec.omega);
        if !(D::is_finite(spec.pos) && D::is_finite(spec.vel) && omega.is_finite()) {
            return bad("position, velocity and spin must be finite".into());
        }
        out.push((q.map(|c| c / norm), omega));
    }
    Ok(out)
}

impl<D: Dim> Md<D> {
    /// Refuses clumps where this engine cannot move them: under Gear-5
    /// and in a sheared box (input errors naming the key).
    fn refuse_clumps_here(&self) -> Result<()> {
        if self.settings.integrator == Integrator::Gear5 {
            return Err(Error::input(
                "run.integrator = \"gear5\": rigid clumps ([[shapes]]) move by velocity Verlet and \
                 NO_SQUISH only; set run.integrator = \"verlet\"",
            ));
        }
        if self.domain.shear.is_some() {
            return Err(Error::input(
                "domain.shear: rigid clumps ([[shapes]]) in a sheared box are not implemented \
                 (their sub-spheres would cross the sliding images apart from their body)",
            ));
        }
        Ok(())
    }

    /// Adds rigid clumps of the given shapes to the engine: each body's
    /// sub-spheres become grains with fresh ids (consecutive per body),
    /// after the grains already there, moving with their body from now on.
    /// Fails (input error naming the key) under Gear-5, in a sheared box,
    /// beside ghosts, on a bad shape, index, quaternion or motion.
    pub fn add_bodies(&mut self, shapes: Vec<Shape<D>>, bodies: Vec<BodySpec<D>>) -> Result<()> {
        self.refuse_clumps_here()?;
        if self.particles.n_owned() != self.particles.len() {
            return Err(Error::input(
                "rigid clumps cannot be added beside ghosts (a distributed run)",
            ));
        }
        let shapes = shapes
            .into_iter()
            .map(body_shape)
            .collect::<Result<Vec<_>>>()?;
        let made = check_bodies(&shapes, &bodies)?;
        let mut clumps = self.clumps.take().map(|c| *c).unwrap_or_default();
        let offset = clumps.bodies.shapes.len();
        clumps.bodies.shapes.extend(shapes);
        let mut next_id = self.particles.id.iter().max().map_or(1, |m| m + 1);
        for (spec, (quat, omega)) in bodies.iter().zip(made) {
            let shape_index = offset + spec.shape;
            let shape = &clumps.bodies.shapes[shape_index];
            // L = R I Rᵀ ω, the spin's angular momentum.
            let r = no_squish::matrix(quat);
            let wb = r.transpose() * omega;
            let [i1, i2, i3] = shape.inertia;
            let ang_mom = r * DVec3::new(i1 * wb.x, i2 * wb.y, i3 * wb.z);
            let b = clumps.bodies.bodies.len() as u32;
            // Each sub-sphere's share of the body's mass, by volume: what
            // the measurements (densities, temperatures) count it as.
            let volume: f64 = shape.radii.iter().map(|r| r.powi(3)).sum();
            for (s, &radius) in shape.radii.iter().enumerate() {
                let m = shape.mass * radius.powi(3) / volume;
                let inertia = 0.4 * m * radius * radius;
                let mut g =
                    ParticleRecord::<D>::new(next_id + s as u64, spec.pos, radius, m, inertia);
                g.kind = spec.kind;
                clumps.by_id.insert(g.id, (b, s as u32));
                self.particles.push_record(g);
            }
            clumps.bodies.bodies.push(Body {
                shape: shape_index as u32,
                first_id: next_id,
                pos: xyz::<D>(spec.pos),
                quat,
                vel: xyz::<D>(spec.vel),
                ang_mom,
                force: DVec3::ZERO,
                torque: DVec3::ZERO,
            });
            next_id += shape.radii.len() as u64;
        }
        if !clumps.bodies.bodies.is_empty() {
            self.clumps = Some(Box::new(clumps));
        }
        self.refresh_clumps();
        self.place_sub_spheres(true);
        // As a freshly built engine: the list and the forces of now.
        self.neighbors.invalidate();
        self.rebuild_neighbors()?;
        self.compute_forces(false);
        Ok(())
    }

    /// Registers the shapes of bodies that arrive later (an inlet's) in an
    /// engine built without bodies: the run then counts as one with clumps
    /// (its frames carry `body`, its energies the bodies' terms). Fails as
    /// [`Md::add_bodies`] does under Gear-5, in a sheared box or on a bad
    /// shape.
    pub fn register_shapes(&mut self, shapes: Vec<Shape<D>>) -> Result<()> {
        if self.clumps.is_some() || shapes.is_empty() {
            return Ok(());
        }
        self.refuse_clumps_here()?;
        let mut clumps = Clumps::default();
        clumps.bodies.shapes = shapes
            .into_iter()
            .map(body_shape)
            .collect::<Result<Vec<_>>>()?;
        self.clumps = Some(Box::new(clumps));
        self.refresh_clumps();
        Ok(())
    }

    /// Inserts bodies of the registered shapes into a running engine (an
    /// inlet's), each with its sub-spheres' consecutive ids from the given
    /// first id, after the grains already there. As [`Md::insert_grains`]
    /// does for spheres: the grains there keep their state, the list is
    /// rebuilt at the next step, and a new body starts as in a freshly
    /// built engine that finds it touching nothing (the caller places it
    /// clear): its force is its weight, its torque zero, its sub-spheres
    /// at X + R c with velocity v + ω × R c. Fails (input error) without
    /// registered shapes, beside ghosts, on a taken id, a bad shape index,
    /// quaternion or motion.
    pub fn insert_bodies(&mut self, bodies: Vec<(u64, BodySpec<D>)>) -> Result<()> {
        if bodies.is_empty() {
            return Ok(());
        }
        if self.particles.n_owned() != self.particles.len() {
            return Err(Error::input(
                "bodies cannot be inserted beside ghosts (a distributed run)",
            ));
        }
        let gravity = xyz::<D>(self.settings.gravity);
        let Some(mut clumps) = self.clumps.take() else {
            return Err(Error::input(
                "bodies inserted into an engine without [[shapes]] registered",
            ));
        };
        let specs: Vec<BodySpec<D>> = bodies.iter().map(|b| b.1).collect();
        let made = match check_bodies(&clumps.bodies.shapes, &specs) {
            Ok(m) => m,
            Err(e) => {
                self.clumps = Some(clumps);
                return Err(e);
            }
        };
        let mut ids: std::collections::HashSet<u64> = self.particles.id.iter().copied().collect();
        for ((first, spec), (quat, omega)) in bodies.iter().zip(made) {
            let shape = &clumps.bodies.shapes[spec.shape];
            let n = shape.radii.len() as u64;
            if let Some(id) = (*first..first + n).find(|id| !ids.insert(*id)) {
                self.clumps = Some(clumps);
                return Err(Error::input(format!(
                    "inserted body: grain id {id} is already taken: ids are never reused"
                )));
            }
            let r = no_squish::matrix(quat);
            let wb = r.transpose() * omega;
            let [i1, i2, i3] = shape.inertia;
            let ang_mom = r * DVec3::new(i1 * wb.x, i2 * wb.y, i3 * wb.z);
            let b = clumps.bodies.bodies.len() as u32;
            let (pos, vel) = (xyz::<D>(spec.pos), xyz::<D>(spec.vel));
            let volume: f64 = shape.radii.iter().map(|r| r.powi(3)).sum();
            for (s, (&radius, &center)) in shape.radii.iter().zip(&shape.centers).enumerate() {
                let m = shape.mass * radius.powi(3) / volume;
                let arm = r * center;
                let x = D::from_xyz((pos + arm).to_array());
                let mut g = ParticleRecord::<D>::new(
                    first + s as u64,
                    x,
                    radius,
                    m,
                    0.4 * m * radius * radius,
                );
                g.kind = spec.kind;
                g.vel = D::from_xyz((vel + omega.cross(arm)).to_array());
                g.omega = D::ang_from_xyz(omega.to_array());
                clumps.by_id.insert(g.id, (b, s as u32));
                // A sub-sphere's force holds its contacts only: none yet.
                self.particles.push_record(g);
            }
            clumps.bodies.bodies.push(Body {
                shape: spec.shape as u32,
                first_id: *first,
                pos,
                quat,
                vel,
                ang_mom,
                force: gravity * shape.mass,
                torque: DVec3::ZERO,
            });
        }
        self.clumps = Some(clumps);
        self.neighbors.invalidate();
        self.refresh_clumps();
        Ok(())
    }

    /// The number of sub-spheres of each registered shape (empty without
    /// clumps).
    pub fn shape_sizes(&self) -> Vec<usize> {
        self.bodies().map_or(Vec::new(), |b| {
            b.shapes.iter().map(|s| s.radii.len()).collect()
        })
    }

    /// Whether the run has rigid clumps.
    pub fn has_bodies(&self) -> bool {
        self.clumps.is_some()
    }

    /// The body store (none without clumps).
    pub fn bodies(&self) -> Option<&Bodies> {
        self.clumps.as_ref().map(|c| &c.bodies)
    }

    /// Each grain's body in store order (`None` for a free grain), or
    /// `None` without clumps.
    pub fn grain_bodies(&self) -> Option<Vec<Option<u32>>> {
        let c = self.clumps.as_ref()?;
        Some(
            c.grain_body
                .iter()
                .map(|&b| (b != NO_BODY).then_some(b))
                .collect(),
        )
    }

    /// The first `n` grains' bodies for a frame, numbered from 1 so that 0
    /// marks a free sphere (the `mol` convention of a LAMMPS dump), or
    /// `None` without clumps.
    pub(crate) fn frame_bodies(&self, n: usize) -> Option<Vec<u64>> {
        let c = self.clumps.as_ref()?;
        let number = |&b: &u32| if b == NO_BODY { 0 } else { u64::from(b) + 1 };
        Some(c.grain_body[..n].iter().map(number).collect())
    }

    /// The masses the contact laws see, per grain: a sub-sphere's body's
    /// mass, as LAMMPS's granular pair styles take the rigid body's mass
    /// for a contact of one of its atoms.
    pub(crate) fn contact_mass(&self) -> &[f64] {
        match &self.clumps {
            Some(c) => &c.contact_mass,
            None => &self.particles.mass,
        }
    }

    /// Rebuilds the per-grain ties from the grains' ids, after the store
    /// was reordered, grown or cut.
    pub(crate) fn refresh_clumps(&mut self) {
        let Some(c) = self.clumps.as_deref_mut() else {
            return;
        };
        let p = &self.particles;
        let n = p.len();
        c.grain_body.clear();
        c.grain_body.resize(n, NO_BODY);
        c.held.clear();
        c.held.extend_from_slice(&p.frozen);
        c.contact_mass.clear();
        c.contact_mass.extend_from_slice(&p.mass);
        c.start.clear();
        let mut total = 0;
        for b in 0..c.bodies.bodies.len() {
            c.start.push(total);
            total += c.bodies.shape(b).radii.len();
        }
        c.start.push(total);
        let total = c.start[c.bodies.bodies.len()];
        c.members.clear();
        c.members.resize(total, u32::MAX);
        for (i, id) in p.id.iter().enumerate() {
            if let Some(&(b, s)) = c.by_id.get(id) {
                c.grain_body[i] = b;
                c.held[i] = true;
                c.contact_mass[i] = c.bodies.shape(b as usize).mass;
                c.members[c.start[b as usize] + s as usize] = i as u32;
            }
        }
    }

    /// Drops the listed pairs of two sub-spheres of one body.
    pub(crate) fn drop_pairs_within_bodies(&mut self) {
        if let Some(c) = &self.clumps {
            let body = &c.grain_body;
            self.neighbors.retain_pairs(|i, j| {
                let b = body[i as usize];
                b == NO_BODY || b != body[j as usize]
            });
        }
    }

    /// Wraps the bodies' centres of mass into a periodic box (the grain
    /// rebuild wraps the sub-spheres).
    pub(crate) fn wrap_bodies(&mut self) {
        if let Some(c) = self.clumps.as_deref_mut() {
            for b in &mut c.bodies.bodies {
                b.pos = xyz::<D>(self.domain.wrap(D::from_xyz(b.pos.to_array())));
            }
        }
    }

    /// Puts every sub-sphere where its body says: velocity v + ω × r and
    /// spin ω, and with `positions` its centre X + R c, in the periodic
    /// image nearest to where it was (the grains are wrapped at rebuilds
    /// only, their bodies' centres too).
    pub(crate) fn place_sub_spheres(&mut self, positions: bool) {
        let Some(c) = self.clumps.as_deref_mut() else {
            return;
        };
        c.turned.clear();
        for (b, body) in c.bodies.bodies.iter().enumerate() {
            let r = c.bodies.rotation(b);
            let omega = no_squish::omega_turned(r, body.ang_mom, c.bodies.shape(b).inertia);
            c.turned.push(Turned { r, omega });
        }
        self.place_turned(positions);
    }

    /// [`Md::place_sub_spheres`] by the bodies' matrices and spins in
    /// [`Clumps::turned`].
    fn place_turned(&mut self, positions: bool) {
        let Some(c) = self.clumps.as_deref() else {
            return;
        };
        let p = &mut self.particles;
        // The periodic lengths, looked up once: a sub-sphere is moved by a
        // period only when its body's centre was wrapped away from it.
        let mut period = [None; 3];
        for (a, l) in period.iter_mut().enumerate().take(D::D) {
            if self.domain.is_periodic(a) {
                *l = Some(self.domain.length(a));
            }
        }
        for (b, (body, turned)) in c.bodies.bodies.iter().zip(&c.turned).enumerate() {
            let Turned { r, omega: w } = *turned;
            let shape = c.bodies.shape(b);
            let members = &c.members[c.start[b]..c.start[b + 1]];
            for (&i, &center) in members.iter().zip(&shape.centers) {
                let i = i as usize;
                let arm = r * center;
                if positions {
                    let mut x = body.pos + arm;
                    let old = xyz::<D>(p.pos[i]);
                    for (a, l) in period.iter().enumerate() {
                        if let Some(l) = *l {
                            let d = old[a] - x[a];
                            if d.abs() >= 0.5 * l {
                                x[a] += (d / l).round() * l;
                            }
                        }
                    }
                    p.pos[i] = D::from_xyz(x.to_array());
                }
                p.vel[i] = D::from_xyz((body.vel + w.cross(arm)).to_array());
                p.omega[i] = D::ang_from_xyz(w.to_array());
            }
        }
    }

    /// The bodies' part of the step before the forces: half-kick, drift
    /// and rotation, and their sub-spheres placed.
    pub(crate) fn predict_bodies(&mut self) {
        let dt = self.settings.dt;
        if let Some(c) = self.clumps.as_deref_mut() {
            c.bodies.kick(0.5 * dt);
            c.bodies.drift(dt, &mut c.turned);
            self.place_turned(true);
        }
    }

    /// The bodies' part after the forces: their forces and torques summed,
    /// the second half-kick, the sub-spheres' new velocities.
    pub(crate) fn correct_bodies(&mut self) {
        if self.kick_bodies() {
            self.place_sub_spheres(false);
        }
    }

    /// The bodies' second half-kick alone (false without bodies): in the
    /// fused step the sub-spheres are placed once, by the prediction that
    /// follows at once.
    pub(crate) fn kick_bodies(&mut self) -> bool {
        let dt = self.settings.dt;
        let Some(c) = self.clumps.as_deref_mut() else {
            return false;
        };
        c.bodies.kick(0.5 * dt);
        true
    }

    /// Each body's force and torque about its centre of mass from its
    /// sub-spheres' (summed in shape order: the same bits on any threads).
    /// A sub-sphere's force holds its contacts only (the field pass weighs
    /// it not: it is [`Clumps::held`]): the body's weight is added
    /// once, at its centre of mass.
    pub(crate) fn gather_body_forces(&mut self) {
        let gravity = xyz::<D>(self.settings.gravity);
        let Some(c) = self.clumps.as_deref_mut() else {
            return;
        };
        let p = &self.particles;
        let rotation = self.settings.law.rotation();
        for b in 0..c.bodies.bodies.len() {
            let r = c.bodies.rotation(b);
            let shape = &c.bodies.shapes[c.bodies.bodies[b].shape as usize];
            let weight = gravity * shape.mass;
            let members = &c.members[c.start[b]..c.start[b + 1]];
            let (mut force, mut torque) = (DVec3::ZERO, DVec3::ZERO);
            for (&i, &center) in members.iter().zip(&shape.centers) {
                let i = i as usize;
                let f = xyz::<D>(p.force[i]);
                force += f;
                // F at the sphere's centre and T about it are the contact
                // force at the contact point: about the centre of mass
                // r × F + T.
                torque += (r * center).cross(f);
                if rotation {
                    torque += ang::<D>(p.torque[i]);
                }
            }
            let body = &mut c.bodies.bodies[b];
            body.force = force + weight;
            // A 2D body turns about z only.
            body.torque = if D::D == 2 {
                DVec3::new(0.0, 0.0, torque.z)
            } else {
                torque
            };
        }
    }

    /// Swaps the integrators' mask in for `frozen` (and back): while the
    /// grain integrators run, sub-spheres count as frozen, so that they
    /// skip them with the selection they already make for frozen grains
    /// (no test added to the free grains' loop).
    pub(crate) fn swap_held(&mut self) {
        if let Some(c) = self.clumps.as_deref_mut() {
            std::mem::swap(&mut self.particles.frozen, &mut c.held);
        }
    }

    /// Translational kinetic energy: ½ m v² of the free grains and ½ M V²
    /// of the bodies.
    pub fn kinetic_energy(&self) -> f64 {
        match &self.clumps {
            None => self.particles.kinetic_energy(),
            Some(c) => {
                let p = &self.particles;
                let free = p.kinetic_energy_of(|i| !p.frozen[i] && c.grain_body[i] == NO_BODY);
                free + c.bodies.translational_energy()
            }
        }
    }

    /// Rotational kinetic energy: ½ I ω² of the free grains and ½ L·ω of
    /// the bodies (their full inertia tensor).
    pub fn rotational_energy(&self) -> f64 {
        match &self.clumps {
            None => self.particles.rotational_energy(),
            Some(c) => {
                let p = &self.particles;
                let free = p.rotational_energy_of(|i| !p.frozen[i] && c.grain_body[i] == NO_BODY);
                free + c.bodies.rotational_energy()
            }
        }
    }

    /// Takes out of the body store every body whose sub-spheres are in
    /// `ids` (sorted), before those grains leave the store; refuses (and
    /// changes nothing) when a body is only partly listed: a body leaves
    /// whole or not at all. The bodies left keep their order; their ties
    /// to the grains are rebuilt by the neighbour rebuild that follows.
    pub(crate) fn drop_whole_bodies(&mut self, ids: &[u64]) -> Result<()> {
        let Some(c) = self.clumps.as_deref_mut() else {
            return Ok(());
        };
        let mut gone = vec![false; c.bodies.bodies.len()];
        for id in ids {
            if let Some(&(b, _)) = c.by_id.get(id) {
                gone[b as usize] = true;
            }
        }
        for b in (0..gone.len()).filter(|&b| gone[b]) {
            let first = c.bodies.bodies[b].first_id;
            let n = c.bodies.shape(b).radii.len() as u64;
            if let Some(id) = (first..first + n).find(|id| ids.binary_search(id).is_err()) {
                return Err(Error::input(format!(
                    "grain {id} of rigid body {} would stay while others of its sub-spheres \
                     leave: a body is removed whole",
                    b + 1
                )));
            }
        }
        if !gone.contains(&true) {
            return Ok(());
        }
        let mut k = 0;
        c.bodies.bodies.retain(|_| {
            k += 1;
            !gone[k - 1]
        });
        c.by_id.clear();
        for (b, body) in c.bodies.bodies.iter().enumerate() {
            let n = c.bodies.shapes[body.shape as usize].radii.len() as u32;
            for s in 0..n {
                c.by_id.insert(body.first_id + u64::from(s), (b as u32, s));
            }
        }
        Ok(())
    }

    /// The grain ids of the body whose first sub-sphere has id `first`
    /// (`None`: no body starts there).
    pub fn body_grain_ids(&self, first: u64) -> Option<std::ops::Range<u64>> {
        let c = self.clumps.as_ref()?;
        match c.by_id.get(&first) {
            Some(&(b, 0)) => Some(first..first + c.bodies.shape(b as usize).radii.len() as u64),
            _ => None,
        }
    }

    /// Each body's first grain id, centre of mass and mass, in body order
    /// (empty without clumps): what outlets and sensors look at.
    pub fn body_centres(&self) -> Vec<(u64, D::V, f64)> {
        let Some(c) = self.clumps.as_ref() else {
            return Vec::new();
        };
        (c.bodies.bodies.iter().enumerate())
            .map(|(k, b)| {
                let x = D::from_xyz(b.pos.to_array());
                (b.first_id, x, c.bodies.shape(k).mass)
            })
            .collect()
    }

    /// The free grains and the bodies, each once: (id, position, mass),
    /// a body by its first grain id, centre of mass and mass; in id order.
    /// Without clumps, the grains (the mass balance's and the sensors'
    /// units).
    pub fn units(&self) -> Vec<(u64, D::V, f64)> {
        let p = &self.particles;
        let owner = self.clumps.as_ref().map(|c| &c.grain_body);
        let mut out: Vec<(u64, D::V, f64)> = (0..p.n_owned())
            .filter(|&i| owner.is_none_or(|o| o[i] == NO_BODY))
            .map(|i| (p.id[i], p.pos[i], p.mass[i]))
            .collect();
        out.extend(self.body_centres());
        out.sort_unstable_by_key(|u| u.0);
        out
    }

    /// Checks a checkpoint's bodies against the engine's: as many, each of
    /// the same shape and first grain id.
    pub(crate) fn check_bodies_state(&self, saved: &[Body]) -> Result<()> {
        let mine = self.bodies().map_or(&[][..], |b| &b.bodies[..]);
        let same = |(a, b): (&Body, &Body)| a.shape == b.shape && a.first_id == b.first_id;
        if saved.len() != mine.len() || !saved.iter().zip(mine).all(same) {
            return Err(Error::input(format!(
                "checkpoint state: {} rigid bodies, but the scenario makes {} (or of other \
                 shapes or grains)",
                saved.len(),
                mine.len()
            )));
        }
        Ok(())
    }

    /// Takes the bodies' states of a checkpoint (checked by
    /// [`Md::check_bodies_state`]) and ties the grains to them again.
    pub(crate) fn set_bodies_state(&mut self, saved: Vec<Body>) {
        if let Some(c) = self.clumps.as_deref_mut() {
            c.bodies.bodies = saved;
        }
        self.refresh_clumps();
    }

    /// The first `n` grains' orientations for a frame: a sub-sphere's
    /// body's quaternion (principal frame to space), the identity for a
    /// free sphere; `None` without clumps.
    pub(crate) fn frame_orientations(&self, n: usize) -> Option<Vec<[f64; 4]>> {
        let c = self.clumps.as_ref()?;
        let quat = |&b: &u32| match b {
            NO_BODY => [1.0, 0.0, 0.0, 0.0],
            b => c.bodies.bodies[b as usize].quat,
        };
        Some(c.grain_body[..n].iter().map(quat).collect())
    }

    /// Every body's row of bodies.csv, numbered from 1 as in frames, or
    /// `None` without clumps.
    pub fn body_rows(&self) -> Option<Vec<BodyRow>> {
        let c = self.clumps.as_ref()?;
        let b = &c.bodies;
        let rows = b.bodies.iter().enumerate().map(|(k, body)| BodyRow {
            id: k as u64 + 1,
            shape: b.shape(k).name.clone(),
            pos: body.pos.to_array(),
            quat: body.quat,
            vel: body.vel.to_array(),
            ang_mom: body.ang_mom.to_array(),
            omega: b.omega(k).to_array(),
        });
        Some(rows.collect())
    }
}
