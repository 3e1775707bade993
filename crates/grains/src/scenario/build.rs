//! Turns a scenario into a ready MD engine: domain, grains, walls, settings.

use super::clumps::Clumps;
pub use super::keys::{angular, vector};
use super::memory;
use super::placement;
use super::resolve::{resolve, Resolved};
use super::schema::{FileFormat, MotionSpec, Placement, Scenario, ShapeSpec, WallSpec};
use super::sizes::SizeLaw;
use super::Loaded;
use crate::boundary::{Motion, Shape, Wall};
use crate::contact::hertz_mindlin::MaterialLaw;
use crate::contact::Law;
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::io::{read_lammps_data, read_particles_csv};
use crate::md::{Md, MdSettings};
use crate::particles::{MassModel, ParticleRecord, Particles, SizeBand};

/// Largest initial overlap accepted, as a fraction of the smaller radius.
pub const INITIAL_OVERLAP_TOLERANCE: f64 = 0.05;

fn domain<D: Dim>(s: &Scenario) -> Result<Domain<D>> {
    let lo = vector::<D>("domain.lo", &s.domain.lo)?;
    let hi = vector::<D>("domain.hi", &s.domain.hi)?;
    for a in 0..D::D {
        if D::get(hi, a) <= D::get(lo, a) {
            return Err(Error::input(format!(
                "domain.hi must exceed domain.lo on every axis (axis {a})"
            )));
        }
    }
    if s.domain.periodic.len() > D::D {
        return Err(Error::input(format!(
            "domain.periodic has {} entries; at most {}",
            s.domain.periodic.len(),
            D::D
        )));
    }
    let mut periodic = [false; 3];
    periodic[..s.domain.periodic.len()].copy_from_slice(&s.domain.periodic);
    let mut domain = Domain::new(lo, hi, periodic);
    if let Some(spec) = &s.domain.shear {
        domain.shear = Some(super::shear::shear(spec, s.dimension, &periodic)?);
    }
    Ok(domain)
}

fn grain<D: Dim>(id: u64, pos: D::V, d: f64, density: f64, model: MassModel) -> ParticleRecord<D> {
    let m = model.mass(density, d);
    ParticleRecord::new(id, pos, 0.5 * d, m, model.inertia(m, 0.5 * d))
}

/// The scenario's grains, in the store the engine runs on.
fn grains<D: Dim>(loaded: &Loaded, dom: &Domain<D>) -> Result<Particles<D>> {
    let s = &loaded.scenario;
    let ps = &s.particles;
    if !(ps.d0.is_finite() && ps.d0 > 0.0) {
        return Err(Error::input(format!(
            "particles.d0 = {}: must be a positive diameter in metres",
            ps.d0
        )));
    }
    if !(ps.width.is_finite() && (0.0..2.0).contains(&ps.width)) {
        return Err(Error::input(format!(
            "particles.width = {}: must be in [0, 2) (units of d0)",
            ps.width
        )));
    }
    if !(ps.density.is_finite() && ps.density > 0.0) {
        return Err(Error::input(format!(
            "particles.density = {}: must be positive (kg/m³)",
            ps.density
        )));
    }
    if !(ps.spacing.is_finite() && ps.spacing >= 1.0) {
        return Err(Error::input(format!(
            "particles.spacing = {}: must be >= 1 (units of the largest diameter)",
            ps.spacing
        )));
    }
    if matches!(ps.placement, Placement::Lattice | Placement::Random) {
        let bytes = memory::md_bytes_per_grain(D::D, loaded.scenario.run.integrator);
        memory::check("particles.count", ps.count, bytes)?;
    }
    // 2v must be finite too: velocities are drawn from [-v, v).
    if !((2.0 * ps.random_velocity).is_finite() && ps.random_velocity >= 0.0) {
        return Err(Error::input(format!(
            "particles.random_velocity = {}: must be a finite speed >= 0 (m/s)",
            ps.random_velocity
        )));
    }
    let band = SizeBand {
        d0: ps.d0,
        width: ps.width,
    };
    let (rlo, rhi) = match &ps.region {
        Some(r) => (
            vector::<D>("particles.region.lo", &r.lo)?,
            vector::<D>("particles.region.hi", &r.hi)?,
        ),
        None => (dom.lo, dom.hi),
    };
    if ps.packing.is_some() && ps.placement != Placement::Packed {
        return Err(Error::input(
            "particles.packing is the target of placement = \"packed\": set that placement or \
             leave packing out",
        ));
    }
    let density = super::materials::density(s, None)?;
    // Frozen before they enter the store, which gives a frozen grain no
    // inverse mass or inertia.
    let freeze = |g: &mut ParticleRecord<D>| {
        if ps.frozen_types.contains(&g.kind) {
            g.frozen = true;
        }
    };
    let mut out = match ps.placement {
        // Bodies instead of spheres: `clumps::bodies` places them.
        Placement::Lattice | Placement::Random if super::clumps::places_bodies(s) => {
            Particles::new()
        }
        // An empty box that inlets fill.
        Placement::Lattice | Placement::Random if ps.count == 0 && !s.inlets.is_empty() => {
            Particles::new()
        }
        Placement::Packed => {
            let (d, pos) = super::packed::grains::<D>(loaded, dom, rlo, rhi)?;
            let vel = placement::velocities::<D>(d.len(), ps.random_velocity, s.seed);
            let mut out = Particles::with_capacity(d.len() + ps.add.len());
            for k in 0..d.len() {
                let mut g = grain::<D>(k as u64 + 1, pos[k], d[k], density, ps.mass_model);
                g.vel = vel[k];
                freeze(&mut g);
                out.push_record(g);
            }
            out
        }
        Placement::Lattice | Placement::Random => {
            if ps.count == 0 {
                return Err(Error::input(
                    "particles.count must be at least 1 for lattice or random placement",
                ));
            }
            let (d, largest) = match &ps.size {
                Some(spec) => {
                    let law = SizeLaw::new(spec, ps.mass_model, &loaded.base_dir)?;
                    fits::<D>(&law, rlo, rhi)?;
                    (law.draw(ps.count, s.seed)?, law.max())
                }
                None => (placement::diameters(band, ps.count, s.seed), band.max()),
            };
            let pos = if ps.placement == Placement::Lattice {
                placement::lattice::<D>(rlo, rhi, largest * ps.spacing, ps.count)?
            } else {
                placement::random::<D>(rlo, rhi, &d, s.seed)?
            };
            let vel = placement::velocities::<D>(ps.count, ps.random_velocity, s.seed);
            // Straight into the store: a vector of records first would have
            // its pages (about 160 B per grain) faulted in once and freed.
            let mut out = Particles::with_capacity(ps.count + ps.add.len());
            for k in 0..ps.count {
                let mut g = grain::<D>(k as u64 + 1, pos[k], d[k], density, ps.mass_model);
                g.vel = vel[k];
                freeze(&mut g);
                out.push_record(g);
            }
            out
        }
        Placement::File => {
            let mut records = from_file::<D>(loaded)?;
            records.iter_mut().for_each(freeze);
            Particles::from_records(records)
        }
        Placement::None => Particles::new(),
    };
    let first_id = out.id.iter().copied().max().unwrap_or(0) + 1;
    // Entries with a shape are bodies, made by `clumps::bodies`.
    for (k, a) in ps.add.iter().enumerate().filter(|(_, a)| a.shape.is_none()) {
        let key = format!("particles.add[{k}]");
        let pos = vector::<D>(&format!("{key}.position"), &a.position)?;
        let d = a.diameter.unwrap_or(ps.d0);
        if !(d.is_finite() && d > 0.0) {
            return Err(Error::input(format!(
                "{key}.diameter = {d}: must be positive"
            )));
        }
        let rho = super::materials::density(s, Some(a))?;
        let mut g = grain::<D>(first_id + k as u64, pos, d, rho, ps.mass_model);
        if let Some(v) = &a.velocity {
            g.vel = vector::<D>(&format!("{key}.velocity"), v)?;
        }
        if let Some(w) = &a.omega {
            g.omega = angular::<D>(&format!("{key}.omega"), w)?;
        }
        g.frozen = a.frozen;
        g.kind = a.kind.unwrap_or(if a.frozen { 2 } else { 1 });
        freeze(&mut g);
        out.push_record(g);
    }
    if out.is_empty() && s.inlets.is_empty() && !super::clumps::uses_bodies(s) {
        return Err(Error::input(
            "the scenario places no grains: set particles.count, particles.add or [[inlets]]",
        ));
    }
    Ok(out)
}

/// Refuses a size law whose largest grain is wider than the region it fills.
fn fits<D: Dim>(law: &SizeLaw, lo: D::V, hi: D::V) -> Result<()> {
    for a in 0..D::D {
        let side = D::get(hi, a) - D::get(lo, a);
        if law.max() >= side {
            return Err(Error::input(format!(
                "particles.size.max = {:e} m is not below the placement region's side {side:e} m \
                 along axis {a}: enlarge particles.region (or the domain) or lower max",
                law.max()
            )));
        }
    }
    Ok(())
}

/// Names the scenario key when the initial-state file cannot be read.
fn file_error(e: Error, name: &str) -> Error {
    match e {
        Error::Io { path, source } => Error::input(format!(
            "particles.file = \"{name}\": cannot read {}: {source}",
            path.display()
        )),
        other => other,
    }
}

fn from_file<D: Dim>(loaded: &Loaded) -> Result<Vec<ParticleRecord<D>>> {
    let ps = &loaded.scenario.particles;
    let Some(name) = &ps.file else {
        return Err(Error::input(
            "particles.placement = \"file\" needs particles.file",
        ));
    };
    let path = loaded.path(name);
    let format = ps.format.unwrap_or(if name.ends_with(".csv") {
        FileFormat::Csv
    } else {
        FileFormat::Lammps
    });
    let mut out = Vec::new();
    match format {
        FileFormat::Lammps => {
            let data = read_lammps_data(&path).map_err(|e| file_error(e, name))?;
            if D::D == 2 && !data.is_planar() {
                return Err(Error::input(format!(
                    "{}: grains have non-zero z, but the scenario is 2d",
                    path.display()
                )));
            }
            for (k, a) in data.atoms.iter().enumerate() {
                // LAMMPS's density column is mass per volume of a sphere
                // (also in 2D); a disk mass model reads it per area instead.
                let mut g = grain::<D>(
                    a.id,
                    D::from_xyz(a.pos),
                    a.diameter,
                    a.density,
                    ps.mass_model,
                );
                g.kind = a.kind;
                if data.has_velocities {
                    let v = &data.velocities[k];
                    g.vel = D::from_xyz(v.v);
                    g.omega = D::ang_from_xyz(v.omega);
                }
                out.push(g);
            }
        }
        FileFormat::Csv => {
            let rows = read_particles_csv(&path, D::D).map_err(|e| file_error(e, name))?;
            for (k, c) in rows.into_iter().enumerate() {
                let id = c.id.unwrap_or(k as u64 + 1);
                let mut g = grain::<D>(
                    id,
                    D::from_xyz(c.pos),
                    2.0 * c.radius,
                    super::materials::density(&loaded.scenario, None)?,
                    ps.mass_model,
                );
                g.kind = c.kind.unwrap_or(1);
                g.vel = c.vel.map(D::from_xyz).unwrap_or_default();
                g.omega = c.omega.map(D::ang_from_xyz).unwrap_or_default();
                g.frozen = c.frozen.unwrap_or(false);
                out.push(g);
            }
        }
    }
    let mut ids: Vec<u64> = out.iter().map(|g| g.id).collect();
    ids.sort_unstable();
    if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::input(format!(
            "{}: grain id {} appears twice",
            path.display(),
            w[0]
        )));
    }
    Ok(out)
}

fn wall<D: Dim>(k: usize, w: &WallSpec, dom: &Domain<D>, loaded: &Loaded) -> Result<Wall<D>> {
    let key = format!("walls[{k}] ({})", w.name);
    let v = |field: &str, x: &[f64]| vector::<D>(&format!("{key}.{field}"), x);
    let shape = match &w.shape {
        ShapeSpec::Plane { point, normal } => Shape::Plane {
            point: v("shape.point", point)?,
            normal: v("shape.normal", normal)?,
        },
        ShapeSpec::Segment { a, b } => Shape::Segment {
            a: v("shape.a", a)?,
            b: v("shape.b", b)?,
        },
        ShapeSpec::Polygon { vertices, seams } => Shape::Polygon {
            vertices: vertices
                .iter()
                .enumerate()
                .map(|(i, x)| v(&format!("shape.vertices[{i}]"), x))
                .collect::<Result<_>>()?,
            seams: seams.clone(),
        },
        ShapeSpec::Cylinder {
            point,
            axis,
            radius,
            inside,
        } => Shape::Cylinder {
            point: v("shape.point", point)?,
            axis: match axis {
                Some(a) => v("shape.axis", a)?,
                None => D::unit(D::D - 1),
            },
            radius: *radius,
            inside: *inside,
        },
        ShapeSpec::Obstacle { center, diameter } => Shape::Obstacle {
            center: v("shape.center", center)?,
            diameter: *diameter,
        },
        ShapeSpec::Mesh { .. } => super::mesh_wall::shape::<D>(&key, &w.shape, loaded)?,
    };
    let motion = match &w.motion {
        MotionSpec::Servo { .. } => super::servo::motion(&key, &w.motion, &shape, dom)?,
        _ => motion::<D>(&key, &w.motion, dom)?,
    };
    let mut wall = Wall::new(w.name.clone(), shape, motion)
        .map_err(|e| Error::input(format!("{key}: {e}")))?;
    if let MotionSpec::Vibrate { surface, .. } = &w.motion {
        wall = wall.with_surface(*surface);
    }
    if let Some(t) = w.remove_at {
        wall = wall
            .with_remove_at(t)
            .map_err(|e| Error::input(format!("{key}: {e}")))?;
    }
    Ok(wall)
}

/// A wall motion from its scenario table; `key` names the wall in messages.
pub fn motion<D: Dim>(key: &str, spec: &MotionSpec, dom: &Domain<D>) -> Result<Motion<D>> {
    Ok(match spec {
        MotionSpec::Fixed => Motion::Fixed,
        MotionSpec::Vibrate {
            amplitude,
            frequency,
            modulation,
            wavelength,
            phase,
            direction,
            surface: _,
        } => Motion::Vibrate {
            direction: match direction {
                Some(d) => vector::<D>(&format!("{key}.motion.direction"), d)?,
                None => D::unit(D::vertical()),
            },
            amplitude: *amplitude,
            modulation: *modulation,
            wavelength: wavelength.unwrap_or(dom.length(0)),
            frequency: *frequency,
            phase: *phase,
        },
        MotionSpec::Oscillate {
            amplitude,
            frequency,
            phase,
        } => Motion::Oscillate {
            amplitude: vector::<D>(&format!("{key}.motion.amplitude"), amplitude)?,
            frequency: *frequency,
            phase: *phase,
        },
        MotionSpec::Rotate { center, omega } => Motion::Rotate {
            center: vector::<D>(&format!("{key}.motion.center"), center)?,
            omega: angular::<D>(&format!("{key}.motion.omega"), omega)?,
        },
        MotionSpec::Translate { velocity } => Motion::Translate {
            velocity: vector::<D>(&format!("{key}.motion.velocity"), velocity)?,
        },
        // Its area comes from its wall's shape: built with the wall.
        MotionSpec::Servo { .. } => {
            return Err(Error::input(format!(
                "{key}.motion: type \"servo\" is a motion of MD walls only"
            )))
        }
    })
}

/// Builds the engine of a scenario, with the numbers it was resolved to.
/// Input errors name the scenario they come from.
pub fn build_md<D: Dim>(loaded: &Loaded) -> Result<(Md<D>, Resolved)> {
    build_md_reporting(loaded, &mut |_| {})
}

/// [`build_md`], telling `report` how the set-up goes: one line per pass
/// (placement, the engine with its cell order and neighbour list, the
/// checks of the initial state), each with the seconds since the start.
pub fn build_md_reporting<D: Dim>(
    loaded: &Loaded,
    report: &mut dyn FnMut(&str),
) -> Result<(Md<D>, Resolved)> {
    let (mut md, resolved, clumps) = build_md_parts(loaded, report)?;
    if !clumps.bodies.is_empty() {
        md.add_bodies(clumps.shapes, clumps.bodies)
            .map_err(|e| super::in_scenario(e, &loaded.origin))?;
    } else if super::inlet::bodies::any(&loaded.scenario) {
        // Bodies arrive later, through an inlet: the engine holds their
        // shapes from the start.
        md.register_shapes(clumps.shapes)
            .map_err(|e| super::in_scenario(e, &loaded.origin))?;
    }
    Ok((md, resolved))
}

/// The engine of a scenario before its bodies are added, with the numbers
/// it was resolved to and the shapes and bodies to add (`grains check`
/// reports them).
pub fn build_md_parts<D: Dim>(
    loaded: &Loaded,
    report: &mut dyn FnMut(&str),
) -> Result<(Md<D>, Resolved, Clumps<D>)> {
    build_md_inner(loaded, report).map_err(|e| super::in_scenario(e, &loaded.origin))
}

fn build_md_inner<D: Dim>(
    loaded: &Loaded,
    report: &mut dyn FnMut(&str),
) -> Result<(Md<D>, Resolved, Clumps<D>)> {
    let start = std::time::Instant::now();
    let mut pass = |what: String| {
        report(&format!(
            "set-up: {what} ({:.1} s)",
            start.elapsed().as_secs_f64()
        ))
    };
    let s = &loaded.scenario;
    let dom = domain::<D>(s)?;
    let mut particles = grains::<D>(loaded, &dom)?;
    if s.domain.shear.as_ref().is_some_and(|sh| sh.start_profile) {
        super::shear::start_profile(&mut particles, &dom);
    }
    pass(format!("placed {} grains", particles.len()));
    let walls = s
        .walls
        .iter()
        .enumerate()
        .map(|(k, w)| wall::<D>(k, w, &dom, loaded))
        .collect::<Result<Vec<_>>>()?;
    let walls = super::resolve::elastic_walls(&s.contact.elastic_walls, walls)?;
    let clumps =
        super::clumps::bodies::<D>(loaded, &dom, &walls, &particles, INITIAL_OVERLAP_TOLERANCE)?;
    if !clumps.bodies.is_empty() {
        pass(format!("placed {} bodies", clumps.bodies.len()));
    }
    let lightest = (particles.mass.iter().zip(&particles.frozen))
        .filter(|&(_, &frozen)| !frozen)
        .map(|(&m, _)| m)
        .fold(f64::INFINITY, f64::min);
    // A body's sub-sphere counts as a grain of its own size for dt: its
    // contacts are stiffer than the whole body's mass would suggest.
    let rho = super::materials::density(s, None)?;
    let lightest = (clumps.bodies.iter())
        .flat_map(|b| &clumps.shapes[b.shape].spheres)
        .map(|sub| s.particles.mass_model.mass(rho, 2.0 * sub.radius))
        .fold(lightest, f64::min);
    // The inlets' grains count as placed ones for dt and the skin.
    let arriving = super::inlet::extent(loaded)?;
    let lightest = arriving.map_or(lightest, |(m, _)| lightest.min(m));
    let lightest = match particles.mass.first() {
        _ if lightest.is_finite() => lightest,
        Some(&m) => m,
        None => 1.0,
    };
    let resolved = resolve(s, lightest)?;
    let dmax = arriving
        .map_or(0.0, |(_, d)| d)
        .max(2.0 * particles.max_radius())
        .max(clumps.max_sub_diameter());
    if !(s.run.skin.is_finite() && s.run.skin > 0.0) {
        return Err(Error::input(format!(
            "run.skin = {}: must be positive (units of d0)",
            s.run.skin
        )));
    }
    if !(s.run.max_overlap.is_finite() && s.run.max_overlap > 0.0) {
        return Err(Error::input(format!(
            "run.max_overlap = {}: must be positive",
            s.run.max_overlap
        )));
    }
    let mut settings = MdSettings::<D>::new(
        resolved.dt,
        resolved.law.clone(),
        s.run.skin * s.particles.d0.min(dmax),
    );
    settings.integrator = s.run.integrator;
    settings.max_overlap_fraction = s.run.max_overlap;
    if let Some(spec) = &s.domain.shear {
        settings.barostat = super::shear::barostat(spec)?;
    }
    if let Some(g) = &s.gravity {
        settings.gravity = vector::<D>("gravity", g)?;
    }
    // The one law of the run: the materials' when the scenario has them,
    // with the stand-in the time step came from.
    let mut kinds = particles.kind.clone();
    kinds.extend(super::inlet::mixture::kinds(s)?);
    kinds.extend(clumps.bodies.iter().map(|b| b.kind));
    let hertz = super::materials::hertz_law(s, &kinds)?;
    if let Some(hertz) = hertz {
        settings.law = Law::Materials(MaterialLaw {
            hertz,
            estimate: resolved.law.clone(),
        });
    }
    if settings.law.materials().is_some() && !s.contact.elastic_walls.is_empty() {
        return Err(Error::input(format!(
            "{}: contact.elastic_walls is an option of the spring-dashpot laws; with \
             materials, give those walls a material (or a [[material_pairs]] entry) \
             with restitution = 1",
            loaded.origin
        )));
    }
    let md = Md::new(particles, dom, walls, settings).map_err(|e| match e {
        Error::Unstable(m) => Error::input(format!(
            "{}: the initial state is unusable: {m}",
            loaded.origin
        )),
        other => other,
    })?;
    pass("engine: cell order and neighbour list".to_string());
    let (frac, a, b) = md.worst_overlap();
    if frac > INITIAL_OVERLAP_TOLERANCE {
        let partner = b.map_or("a wall".to_string(), |b| format!("grain {b}"));
        return Err(Error::input(format!(
            "{}: initial grain {a} overlaps {partner} by {:.1}% of the smaller radius (at most {:.0}% allowed); \
             move the grains apart or enlarge particles.spacing / particles.region",
            loaded.origin,
            100.0 * frac,
            100.0 * INITIAL_OVERLAP_TOLERANCE
        )));
    }
    md.check_stability().map_err(|e| {
        Error::input(format!(
            "{}: the initial state is unusable: {e}",
            loaded.origin
        ))
    })?;
    pass("checked the initial overlaps and time step".to_string());
    Ok((md, resolved, clumps))
}

/// A one-grain scenario the tests below change.
#[cfg(test)]
mod tests_base {
    pub const BASE: &str = r#"name = "p"
dimension = "3d"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [10.0, 10.0, 10.0]
[particles]
count = 1
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-4
duration = 0.01
"#;
}

/// The `[parallel]` keys, checked by name when a scenario is loaded
/// ([`crate::settings::parallel`]).
#[cfg(test)]
mod parallel_keys {
    use super::tests_base::BASE;
    use crate::scenario::load_str;
    use std::path::PathBuf;

    fn error(parallel: &str) -> String {
        let text = format!("{BASE}[parallel]\n{parallel}\n");
        match load_str(&text, "p.toml", PathBuf::from("."), &[]) {
            Ok(_) => String::new(),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn parallel_keys_are_checked_by_name() {
        assert_eq!(error("rebalance = 0.2\ngrid = [1, 2, 2]"), "");
        assert_eq!(error("grid = \"slabs\""), "");
        let e = error("rebalance = -0.5");
        assert!(
            e.contains("p.toml") && e.contains("parallel.rebalance"),
            "{e}"
        );
        let e = error("grid = \"cubes\"");
        assert!(e.contains("\"auto\", \"slabs\""), "{e}");
        let e = error("grid = [2, 2]");
        assert!(
            e.contains("p.toml") && e.contains("give 3 rank counts"),
            "{e}"
        );
        let e = error("grid = [2, 0, 1]");
        assert!(e.contains("≥ 1 per axis"), "{e}");
        let e = error("rebalence = 0.1");
        assert!(e.contains("unknown field"), "{e}");
    }
}

/// `particles.frozen_types` freezes grains before they enter the store.
#[cfg(test)]
mod frozen_types {
    use super::build_md;
    use super::tests_base::BASE;
    use crate::dim::D3;
    use crate::scenario::load_str;
    use std::path::PathBuf;

    /// Lattice grains (kind 1) and one added grain of kind 3, with kind 3
    /// frozen by type: it has no inverse mass or inertia, the others keep
    /// theirs.
    #[test]
    fn frozen_by_type_has_no_inverse_mass() {
        let text = format!("{BASE}[[particles.add]]\nposition = [9.0, 9.0, 9.0]\nkind = 3\n");
        let sets = ["particles.count=8", "particles.frozen_types=[3]"].map(String::from);
        let loaded = load_str(&text, "f.toml", PathBuf::from("."), &sets).unwrap();
        let (md, _) = build_md::<D3>(&loaded).unwrap();
        let p = &md.particles;
        assert_eq!(p.len(), 9);
        for k in 0..p.len() {
            let frozen = p.kind[k] == 3;
            assert_eq!(p.frozen[k], frozen, "grain {k}");
            assert_eq!(p.inv_mass[k] == 0.0, frozen, "grain {k}");
            assert_eq!(p.inv_inertia[k] == 0.0, frozen, "grain {k}");
        }
        assert_eq!(p.kind.iter().filter(|&&k| k == 3).count(), 1);
    }
}
