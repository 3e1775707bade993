//! What `grains check` prints of a scenario's contact law under materials
//! (`contact.model = "hertz-mindlin"` or the `lammps-granular` preset): per
//! pair of materials that meet, the values the engine's law holds (E*, G*,
//! the damping coefficient, friction, rolling and cohesion) and the spread
//! of R* and m* over the grains that meet; then the time step's reasoning
//! and the memory estimate, for every law; [`md_report`] puts them
//! together with the run's plan.
//!
//! Every number is read from the built engine's objects (the law's pair
//! table, the grains' radii and masses) or computed by the functions the
//! contact law itself calls (`r_star`, the reduced mass, the pull-off
//! forces), never by a second formula.

use super::memory::md_bytes_per_grain;
use super::resolve::Resolved;
use super::schema::Scenario;
use super::Loaded;
use crate::contact::cohesion::{dmt_pull_off, CohesionModel};
use crate::contact::hertz_mindlin::HertzMindlin;
use crate::contact::material::r_star;
use crate::contact::rolling::{RollingModel, EPSD_DAMPING_RATIO};
use crate::contact::{jkr, MassScaling};
use crate::dim::Dim;
use crate::error::Result;
use crate::md::Md;
use serde_json::{json, Map, Value};

/// Smallest and largest radius and contact mass (infinite for a frozen
/// grain, as the pair loop takes it) of the grains of one material.
#[derive(Clone, Copy)]
struct Spread {
    r: (f64, f64),
    m: (f64, f64),
}

impl Spread {
    fn add(s: &mut Option<Spread>, r: f64, m: f64) {
        let x = s.get_or_insert(Spread {
            r: (r, r),
            m: (m, m),
        });
        x.r = (x.r.0.min(r), x.r.1.max(r));
        x.m = (x.m.0.min(m), x.m.1.max(m));
    }
}

/// A number, or "inf".
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        json!("inf")
    }
}

/// One value where `lo == hi`, else `{min, max}`.
fn range(lo: f64, hi: f64) -> Value {
    if lo == hi {
        num(lo)
    } else {
        json!({ "min": num(lo), "max": num(hi) })
    }
}

/// The material law of `md` (`law`, its `settings.law`'s materials) as JSON.
pub fn material_law<D: Dim>(s: &Scenario, md: &Md<D>, law: &HertzMindlin) -> Result<Value> {
    let names: Vec<String> = super::materials::materials(s)?
        .into_iter()
        .map(|m| m.name)
        .collect();
    let p = &md.particles;
    let mut spread: Vec<Option<Spread>> = vec![None; names.len()];
    for i in 0..p.n_owned() {
        let m = law.kind_materials()[p.kind[i] as usize] as usize;
        let mass = if p.frozen[i] {
            f64::INFINITY
        } else {
            p.mass[i]
        };
        Spread::add(&mut spread[m], p.radius[i], mass);
    }
    let reduced = |a: f64, b: f64| MassScaling::Reduced.damping_mass(a, b);
    let mut pairs = Vec::new();
    // Grains against grains: every pair of materials grains have.
    for a in 0..names.len() {
        for b in a..names.len() {
            let (Some(sa), Some(sb)) = (spread[a], spread[b]) else {
                continue;
            };
            let r = (r_star(sa.r.0, sb.r.0), r_star(sa.r.1, sb.r.1));
            let m = (reduced(sa.m.0, sb.m.0), reduced(sa.m.1, sb.m.1));
            pairs.push(pair_json(law, &names, (a, b), "grains", r, m));
        }
    }
    // Grains against walls: a wall is flat and immovable, R* = R_i, m* = m_i;
    // walls of one material are one entry.
    let mut by_material: Vec<(usize, Vec<String>)> = Vec::new();
    for (w, &mw) in law.wall_materials().iter().enumerate() {
        let name = md.walls.get(w).map_or(String::new(), |x| x.name.clone());
        match by_material.iter_mut().find(|(m, _)| *m == mw as usize) {
            Some((_, names)) => names.push(name),
            None => by_material.push((mw as usize, vec![name])),
        }
    }
    for (mw, wall_names) in &by_material {
        for (a, sa) in spread.iter().enumerate() {
            let Some(sa) = sa else { continue };
            let r = (r_star(sa.r.0, f64::INFINITY), r_star(sa.r.1, f64::INFINITY));
            let m = (
                reduced(sa.m.0, f64::INFINITY),
                reduced(sa.m.1, f64::INFINITY),
            );
            let between = format!("grains and walls {}", wall_names.join(", "));
            pairs.push(pair_json(law, &names, (a, *mw), &between, r, m));
        }
    }
    let model = if law.is_lammps_granular() {
        "lammps-granular"
    } else {
        "hertz-mindlin"
    };
    let mut rolling = Map::new();
    rolling.insert("model".into(), json!(law.rolling.name()));
    match (law.rolling, law.granular()) {
        (RollingModel::None, _) => {}
        (RollingModel::Epsd, Some(t)) => {
            let sds = t.rolling.unwrap_or_default();
            rolling.insert(
                "rule".into(),
                json!("LAMMPS rolling sds: spring and dashpot on the rolling displacement, capped at mu_r |F_n|"),
            );
            rolling.insert("stiffness".into(), json!(sds.stiffness));
            rolling.insert("damping".into(), json!(sds.damping));
        }
        (RollingModel::Constant, _) => {
            rolling.insert(
                "rule".into(),
                json!("constant torque mu_r R* |F_n| against the rolling (Ai et al. type A)"),
            );
        }
        (RollingModel::Epsd, None) => {
            rolling.insert(
                "rule".into(),
                json!("spring-dashpot k_r = 2.25 mu_r^2 S_n on the rolling displacement, S_n = 2 E* a, capped at mu_r |F_n| (Ai et al. type C)"),
            );
            rolling.insert("damping_ratio".into(), json!(EPSD_DAMPING_RATIO));
        }
    }
    let cohesion = match law.cohesion() {
        CohesionModel::None => json!({ "model": "none" }),
        CohesionModel::Dmt => json!({
            "model": "dmt",
            "rule": "a constant pull 2 pi Gamma R* while the surfaces touch",
        }),
        CohesionModel::Jkr => json!({
            "model": "jkr",
            "rule": "JKR force from the contact radius, pull-off 1.5 pi Gamma R*, kept to the breaking separation",
        }),
    };
    Ok(json!({
        "model": model,
        "rotation": law.rotation,
        "normal": "F_n = (4/3) E* sqrt(R*) xi^(3/2) - alpha sqrt(m* S_n) v_n, S_n = 2 E* a, a = sqrt(R* xi)",
        "damping": if law.is_lammps_granular() {
            "LAMMPS damping tsuji: alpha from the materials' restitution (LAMMPS's fit)"
        } else {
            "Tsuji: alpha solved from the pair's restitution"
        },
        "tangential": "k_t = 8 G* a (Mindlin) on the Cundall-Strack spring, damping alpha sqrt(m* k_t), capped at mu |F_n|",
        "rolling": rolling,
        "cohesion": cohesion,
        "pairs": pairs,
    }))
}

/// One pair of materials `(a, b)` meeting `between`, with the spreads of
/// R* and m* of its contacts.
fn pair_json(
    law: &HertzMindlin,
    names: &[String],
    (a, b): (usize, usize),
    between: &str,
    r: (f64, f64),
    m: (f64, f64),
) -> Value {
    let mut o = Map::new();
    o.insert("between".into(), json!(between));
    o.insert("materials".into(), json!([names[a], names[b]]));
    let (mu, mu_r) = law.friction(a, b);
    if let Some(t) = law.granular() {
        let g = &t.pairs[a * names.len() + b];
        o.insert("e_star".into(), json!(g.e_star()));
        o.insert("g_star".into(), json!(g.g_star()));
        o.insert("damping_alpha".into(), json!(g.alpha()));
        o.insert("friction".into(), json!(mu));
        o.insert("rolling_friction".into(), json!(mu_r));
    } else {
        let c = law.coefficients(a, b);
        o.insert("e_star".into(), json!(c.e_star));
        o.insert("g_star".into(), json!(c.g_star));
        o.insert("restitution".into(), json!(c.restitution));
        o.insert("damping_alpha".into(), json!(law.pair(a, b).alpha()));
        o.insert("friction".into(), json!(mu));
        if law.rolling != RollingModel::None {
            o.insert("rolling_friction".into(), json!(mu_r));
        }
        let gamma = c.surface_energy;
        match law.cohesion() {
            CohesionModel::None => {}
            CohesionModel::Dmt => {
                o.insert("surface_energy".into(), json!(gamma));
                let f = (dmt_pull_off(gamma, r.0), dmt_pull_off(gamma, r.1));
                o.insert("pull_off_force".into(), range(f.0, f.1));
            }
            CohesionModel::Jkr => {
                o.insert("surface_energy".into(), json!(gamma));
                let f = (jkr::pull_off(gamma, r.0), jkr::pull_off(gamma, r.1));
                o.insert("pull_off_force".into(), range(f.0, f.1));
                let d = (
                    jkr::separation(r.0, c.e_star, gamma),
                    jkr::separation(r.1, c.e_star, gamma),
                );
                o.insert("breaking_separation".into(), range(d.0, d.1));
            }
        }
    }
    o.insert("r_star".into(), range(r.0, r.1));
    o.insert("m_star".into(), range(m.0, m.1));
    Value::Object(o)
}

/// The time step's reasoning: the contact time it was taken from, what
/// that contact time is of, dt, the steps per contact and where dt came
/// from.
pub fn time_step<D: Dim>(md: &Md<D>, r: &Resolved) -> Value {
    let of = if md.settings.law.materials().is_some() {
        format!(
            "an undamped Hertz contact of two of the smallest grains (d = d0 (1 - width/2)) of the \
             stiffest material, k_n = (4/3) E* sqrt(R*) = {:.4e}, at the impact speed",
            r.law.kn
        )
    } else {
        "the binary contact of two of the lightest grains under contact's law".to_string()
    };
    json!({
        "contact_time": r.contact_time,
        "contact_time_of": of,
        "dt": r.dt,
        "steps_per_contact": r.contact_time / r.dt,
        "dt_origin": r.dt_origin,
    })
}

/// The memory the run needs: the figure per grain `scenario::memory`
/// refuses runs by, times the grains.
pub fn memory<D: Dim>(md: &Md<D>) -> Value {
    let each = md_bytes_per_grain(D::D, md.settings.integrator);
    let n = md.particles.n_owned() as u64;
    let bytes = each * n;
    json!({
        "grains": n,
        "bytes_per_grain": each,
        "estimate_bytes": bytes,
        "estimate": format!("{:.1} MiB", bytes as f64 / 1048576.0),
    })
}

/// What `grains check` prints of an MD scenario: the engine built (its
/// flow's settings checked) and reported, and its clumps, which are
/// placed and checked but not added: what the engine makes of them is
/// its own to check when run.
pub fn md_check<D: Dim>(loaded: &Loaded) -> Result<Value> {
    let (mut md, r, clumps) = super::build::build_md_parts::<D>(loaded, &mut |_| {})?;
    if super::inlet::bodies::any(&loaded.scenario) {
        // As a run: the shapes the inlets' bodies are made of.
        md.register_shapes(clumps.shapes.clone())?;
    }
    super::flow::FlowRun::begin(loaded, &md)?;
    let mut v = md_report(loaded, &md, &r)?;
    if !clumps.shapes.is_empty() {
        v["clumps"] = clumps.report(&loaded.scenario);
    }
    Ok(v)
}

/// What `grains check` prints of an MD scenario built as `md` with the
/// resolved settings `r`.
pub fn md_report<D: Dim>(loaded: &Loaded, md: &Md<D>, r: &Resolved) -> Result<Value> {
    let law = &r.law;
    // Under materials the law is the pair table's; `r.law` is only the
    // stand-in the time step was taken from.
    let contact = match md.settings.law.materials() {
        Some(m) => material_law(&loaded.scenario, md, m)?,
        None => json!({
            "kn": law.kn, "beta": law.beta, "gamma_n": law.gamma_n, "gamma_t": law.gamma_t,
            "kt": law.kt, "mu": if law.mu.is_finite() { json!(law.mu) } else { json!("inf") },
            "scaling": format!("{:?}", law.scaling).to_lowercase(), "rotation": law.rotation,
        }),
    };
    Ok(json!({
        "scenario": loaded.scenario.name,
        "source": loaded.origin,
        "dimension": D::NAME,
        "particles": md.particles.n_owned(),
        "sizes": crate::scenario::sizes::report(loaded)?,
        "inlets": crate::scenario::inlet::check_report(
            loaded,
            (r.relax_steps + r.measure_steps) as f64 * r.dt,
        )?,
        "frozen": md.particles.n_owned() - md.particles.n_mobile(),
        "walls": md.walls.iter().map(|w| w.name.clone()).collect::<Vec<_>>(),
        "contact": contact,
        "integrator": md.settings.integrator.name(),
        "time_step": time_step(md, r),
        "contact_time": r.contact_time,
        "dt": r.dt,
        "dt_origin": r.dt_origin,
        "steps_per_contact": r.contact_time / r.dt,
        "cycle_frequency": r.cycle_frequency,
        "relax_steps": r.relax_steps,
        "measure_steps": r.measure_steps,
        "output_every_steps": r.output_every,
        "skin": md.settings.skin,
        "memory": memory(md),
    }))
}
