//! From `[[materials]]`, `[[material_pairs]]` and the `material` keys of
//! grains and walls to the Hertz–Mindlin law of a scenario, every value
//! checked and every name resolved.
//!
//! Grains are matched to materials by kind (the LAMMPS type): every grain of
//! one kind has one material, as in LAMMPS's `pair_coeff` per type pair.

mod checks;

pub use checks::check_contact_keys;

use super::schema::{ContactModelKind, ContactPreset, GrainSpec, Scenario};
use crate::contact::hertz_mindlin::HertzMindlin;
use crate::contact::lammps_granular::{GranularTable, RollingSds};
use crate::contact::material::{Material, PairCoefficients, PairOverride};
use crate::contact::rolling::RollingModel;
use crate::contact::{ContactLaw, MassScaling};
use crate::error::{Error, Result};
use std::collections::BTreeMap;

/// Whether the scenario's contacts come from materials (Hertz–Mindlin, or
/// LAMMPS's `pair granular` through its preset).
pub fn uses_materials(s: &Scenario) -> bool {
    s.contact.model == Some(ContactModelKind::HertzMindlin) || lammps_granular(s)
}

/// Whether the scenario asks for `contact.preset = "lammps-granular"`.
pub fn lammps_granular(s: &Scenario) -> bool {
    s.contact.preset == Some(ContactPreset::LammpsGranular)
}

/// The `[[materials]]`, checked.
pub fn materials(s: &Scenario) -> Result<Vec<Material>> {
    let mut out: Vec<Material> = Vec::new();
    for (k, m) in s.materials.iter().enumerate() {
        let key = |f: &str| format!("materials[{k}].{f} (material \"{}\")", m.name);
        let bad = |f: &str, v: f64, allowed: &str| {
            Err(Error::input(format!("{} = {v}: must be {allowed}", key(f))))
        };
        if out.iter().any(|o| o.name == m.name) {
            return Err(Error::input(format!(
                "materials[{k}].name = \"{}\" is defined twice",
                m.name
            )));
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let non_negative = |v: f64| v.is_finite() && v >= 0.0;
        if !positive(m.density) {
            return bad("density", m.density, "positive (kg/m³)");
        }
        if !positive(m.youngs_modulus) {
            return bad("youngs_modulus", m.youngs_modulus, "positive (Pa)");
        }
        if !(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
            return bad("poisson_ratio", m.poisson_ratio, "in (-1, 0.5)");
        }
        if !(m.restitution > 0.0 && m.restitution <= 1.0) {
            return bad("restitution", m.restitution, "in (0, 1]");
        }
        if !non_negative(m.friction) {
            return bad("friction", m.friction, "a finite number >= 0");
        }
        if !non_negative(m.rolling_friction) {
            return bad("rolling_friction", m.rolling_friction, ">= 0");
        }
        if !non_negative(m.surface_energy) {
            return bad("surface_energy", m.surface_energy, ">= 0 (J/m²)");
        }
        out.push(Material {
            name: m.name.clone(),
            density: m.density,
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            restitution: m.restitution,
            friction: m.friction,
            rolling_friction: m.rolling_friction,
            surface_energy: m.surface_energy,
        });
    }
    Ok(out)
}

/// The index of material `name`, named by `key` in errors.
fn find(materials: &[Material], name: &str, key: &str) -> Result<usize> {
    materials
        .iter()
        .position(|m| m.name == name)
        .ok_or_else(|| {
            let known: Vec<String> = materials
                .iter()
                .map(|m| format!("\"{}\"", m.name))
                .collect();
            Error::input(format!(
                "{key} = \"{name}\": no such material; [[materials]] defines {}",
                if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                }
            ))
        })
}

/// The materials of the inlets' mixtures: per entry its kind, its
/// material's index and its key (`inlets[i].materials[j]`). A kind not
/// given is 1 + the material's place in `[[materials]]`.
pub fn mixture_kinds(s: &Scenario) -> Result<Vec<(u32, usize, String)>> {
    let mut out = Vec::new();
    for (i, inlet) in s.inlets.iter().enumerate() {
        let Some(mix) = &inlet.materials else {
            continue;
        };
        if !uses_materials(s) {
            return Err(Error::input(format!(
                "inlets[{i}].materials needs [[materials]] and contact.model = \"hertz-mindlin\" \
                 (or contact.preset = \"lammps-granular\"); without them give inlets[{i}].kind"
            )));
        }
        let all = materials(s)?;
        for (j, m) in mix.iter().enumerate() {
            let key = format!("inlets[{i}].materials[{j}]");
            let index = find(&all, &m.name, &format!("{key}.name"))?;
            out.push((m.kind.unwrap_or(index as u32 + 1), index, key));
        }
    }
    Ok(out)
}

/// The density of grains of `material` (an entry's, or `particles.material`).
pub fn density(s: &Scenario, entry: Option<&GrainSpec>) -> Result<f64> {
    let (name, key) = match entry.and_then(|a| a.material.as_ref()) {
        Some(n) => (Some(n), "particles.add[].material"),
        None => (s.particles.material.as_ref(), "particles.material"),
    };
    match name {
        Some(n) if uses_materials(s) => {
            let all = materials(s)?;
            Ok(all[find(&all, n, key)?].density)
        }
        _ => Ok(s.particles.density),
    }
}

/// The Hertz–Mindlin law of the scenario, for grains of the given kinds
/// (`None` when the scenario does not use materials).
pub fn hertz_law(s: &Scenario, kinds: &[u32]) -> Result<Option<HertzMindlin>> {
    if !uses_materials(s) {
        return Ok(None);
    }
    let all = materials(s)?;
    let default = match &s.particles.material {
        Some(n) => Some(find(&all, n, "particles.material")?),
        None => None,
    };
    // Each kind's material: particles.add entries name theirs, the rest
    // take particles.material.
    let mut of_kind: BTreeMap<u32, (usize, String)> = BTreeMap::new();
    let mut named: BTreeMap<u32, usize> = BTreeMap::new();
    for (k, a) in s.particles.add.iter().enumerate() {
        let Some(name) = &a.material else { continue };
        let key = format!("particles.add[{k}].material");
        let m = find(&all, name, &key)?;
        let kind = a.kind.unwrap_or(if a.frozen { 2 } else { 1 });
        if let Some((other, by)) = of_kind.get(&kind) {
            if *other != m {
                return Err(Error::input(format!(
                    "{key} = \"{name}\", but {by} gave kind {kind} material \"{}\": grains of one kind \
                     share one material; give this entry its own kind",
                    all[*other].name
                )));
            }
        }
        of_kind.insert(kind, (m, key));
        *named.entry(kind).or_insert(0) += 1;
    }
    // The inlets' mixtures name a material for each of their kinds.
    for (kind, m, key) in mixture_kinds(s)? {
        if let Some((other, by)) = of_kind.get(&kind) {
            if *other != m {
                return Err(Error::input(format!(
                    "{key} makes kind {kind} \"{}\", but {by} gave kind {kind} material \"{}\": \
                     grains of one kind share one material; give {key}.kind another kind",
                    all[m].name, all[*other].name
                )));
            }
        }
        of_kind.insert(kind, (m, key));
        *named.entry(kind).or_insert(0) += 1;
    }
    // Grains of such a kind that named no material would take
    // particles.material: a second material for the kind.
    for (kind, (m, key)) in &of_kind {
        let grains = kinds.iter().filter(|&&k| k == *kind).count();
        match default {
            Some(d) if d != *m && grains > named[kind] => {
                return Err(Error::input(format!(
                    "{key} = \"{}\" makes kind {kind} {}, but other grains of kind {kind} take \
                     particles.material = \"{}\": grains of one kind share one material; give \
                     the entry its own kind",
                    all[*m].name, all[*m].name, all[d].name
                )));
            }
            _ => {}
        }
    }
    let largest = kinds.iter().copied().max().unwrap_or(0) as usize;
    let mut material_of_kind = vec![0u32; largest + 1];
    let mut seen = vec![false; largest + 1];
    for &kind in kinds {
        seen[kind as usize] = true;
    }
    for (kind, used) in seen.iter().enumerate() {
        if !used {
            continue;
        }
        let m = match (of_kind.get(&(kind as u32)), default) {
            (Some((m, _)), _) => *m,
            (None, Some(m)) => m,
            (None, None) => {
                return Err(Error::input(format!(
                    "grains of kind {kind} have no material: set particles.material (or \
                     particles.add[].material) to one of the [[materials]]"
                )))
            }
        };
        material_of_kind[kind] = m as u32;
    }
    let mut wall_material = Vec::with_capacity(s.walls.len());
    for (k, w) in s.walls.iter().enumerate() {
        let m = match (&w.material, default) {
            (Some(n), _) => find(&all, n, &format!("walls[{k}].material"))?,
            (None, Some(m)) => m,
            (None, None) => {
                return Err(Error::input(format!(
                    "walls[{k}] (\"{}\") has no material: set walls[{k}].material or particles.material",
                    w.name
                )))
            }
        };
        wall_material.push(m as u32);
    }
    let mut overrides = Vec::new();
    for (k, p) in s.material_pairs.iter().enumerate() {
        let a = find(&all, &p.a, &format!("material_pairs[{k}].a"))?;
        let b = find(&all, &p.b, &format!("material_pairs[{k}].b"))?;
        let check = |f: &str, v: Option<f64>, ok: fn(f64) -> bool, allowed: &str| match v {
            Some(v) if !ok(v) => Err(Error::input(format!(
                "material_pairs[{k}].{f} = {v}: must be {allowed}"
            ))),
            _ => Ok(()),
        };
        check(
            "restitution",
            p.restitution,
            |v| v > 0.0 && v <= 1.0,
            "in (0, 1]",
        )?;
        check(
            "friction",
            p.friction,
            |v| v.is_finite() && v >= 0.0,
            ">= 0",
        )?;
        check(
            "rolling_friction",
            p.rolling_friction,
            |v| v.is_finite() && v >= 0.0,
            ">= 0",
        )?;
        check(
            "surface_energy",
            p.surface_energy,
            |v| v.is_finite() && v >= 0.0,
            ">= 0",
        )?;
        let over = PairOverride {
            restitution: p.restitution,
            friction: p.friction,
            rolling_friction: p.rolling_friction,
            surface_energy: p.surface_energy,
        };
        overrides.push(((a, b), over));
    }
    let rotation = s.contact.rotation.unwrap_or(true);
    let mut law = HertzMindlin::new(&all, &overrides, material_of_kind, wall_material, rotation);
    if lammps_granular(s) {
        let rolling = match s.contact.rolling.unwrap_or_default() {
            RollingModel::Epsd => Some(RollingSds {
                stiffness: s.contact.rolling_stiffness.unwrap_or(0.0),
                damping: s.contact.rolling_damping.unwrap_or(0.0),
            }),
            _ => None,
        };
        let table = GranularTable::new(&all, &overrides, rolling);
        return Ok(Some(law.with_lammps_granular(table)));
    }
    law.rolling = s.contact.rolling.unwrap_or_default();
    Ok(Some(
        law.with_cohesion(s.contact.cohesion.unwrap_or_default()),
    ))
}

/// A power-law stand-in for the time step and the run's summary: Hertz's
/// k_n = (4/3) E* √R* of two of the smallest grains of the stiffest
/// material, β = 3/2, reduced masses, no damping.
pub fn equivalent_law(s: &Scenario) -> Result<ContactLaw> {
    let all = materials(s)?;
    let e_star = all
        .iter()
        .map(|m| PairCoefficients::mix(m, m, &PairOverride::default()).e_star)
        .fold(0.0, f64::max);
    let mu = all.iter().map(|m| m.friction).fold(0.0, f64::max);
    // A size law's bounds are filled in when the scenario is read.
    let r_min = match s.particles.size.as_ref().and_then(|z| z.min) {
        Some(d) => 0.5 * d,
        None => 0.5 * s.particles.d0 * (1.0 - 0.5 * s.particles.width),
    };
    Ok(ContactLaw {
        kn: 4.0 / 3.0 * e_star * (0.5 * r_min).sqrt(),
        beta: 1.5,
        gamma_n: 0.0,
        gamma_t: 0.0,
        kt: 0.0,
        mu,
        scaling: MassScaling::Reduced,
        rotation: s.contact.rotation.unwrap_or(true),
    })
}

#[cfg(test)]
mod tests {
    use crate::dim::D3;
    use crate::scenario::build::build_md;
    use crate::scenario::load_str;

    /// One glass sphere above a steel floor, with `extra` appended and
    /// `sets` applied; the error message when the build fails.
    fn build(extra: &str, sets: &[&str]) -> std::result::Result<(), String> {
        build_with("[{ position = [0.005, 0.005, 0.002] }]", extra, sets)
    }

    /// As [`build`], with `add` as `particles.add`.
    fn build_with(add: &str, extra: &str, sets: &[&str]) -> std::result::Result<(), String> {
        let text = format!(
            r#"
name = "t"
dimension = "3d"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
[particles]
placement = "none"
d0 = 1.0e-3
material = "glass"
add = {add}
[contact]
model = "hertz-mindlin"
[[materials]]
name = "glass"
density = 2500.0
youngs_modulus = 6.3e10
poisson_ratio = 0.23
restitution = 0.9
friction = 0.3
[[materials]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
poisson_ratio = 0.3
restitution = 0.8
friction = 0.4
[[walls]]
name = "floor"
material = "steel"
shape = {{ type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[run]
duration = 1.0e-4
{extra}
"#
        );
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let loaded = load_str(&text, "t.toml", ".".into(), &sets).map_err(|e| e.to_string())?;
        build_md::<D3>(&loaded)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    fn refused(extra: &str, sets: &[&str], words: &[&str]) {
        refused_with(build(extra, sets), words);
    }

    fn refused_with(r: std::result::Result<(), String>, words: &[&str]) {
        let e = r.expect_err("must be refused");
        for w in words {
            assert!(e.contains(w), "{w:?} not in: {e}");
        }
    }

    #[test]
    fn cohesion_needs_the_material_law() {
        build(
            "",
            &[
                "materials.0.surface_energy=0.05",
                "contact.cohesion=\"dmt\"",
            ],
        )
        .unwrap();
        refused(
            "",
            &[
                "contact.model=\"spring-dashpot\"",
                "contact.preset=\"seed\"",
                "contact.cohesion=\"dmt\"",
            ],
            &["contact.cohesion", "seed", "hertz-mindlin"],
        );
    }

    #[test]
    fn jkr_refusals_name_the_keys() {
        let jkr = "contact.cohesion=\"jkr\"";
        build("", &["materials.0.surface_energy=0.05", jkr]).unwrap();
        // A skin shorter than the pull-off separation.
        refused(
            "",
            &["materials.0.surface_energy=1e4", "run.skin=1e-6", jkr],
            &["contact.cohesion", "jkr", "run.skin"],
        );
        refused(
            "",
            &[
                "contact.model=\"spring-dashpot\"",
                "contact.preset=\"seed\"",
                jkr,
            ],
            &["contact.cohesion", "jkr", "hertz-mindlin"],
        );
        refused(
            "",
            &["materials.0.surface_energy=0.0", jkr],
            &["contact.cohesion", "surface_energy"],
        );
        refused(
            "",
            &[
                "materials.0.surface_energy=0.05",
                "contact.rolling=\"epsd\"",
                jkr,
            ],
            &["contact.cohesion", "jkr", "contact.rolling", "epsd"],
        );
        refused(
            "",
            &["contact.cohesion=\"sticky\""],
            &["none", "dmt", "jkr"],
        );
    }

    #[test]
    fn rolling_needs_rotation_and_the_material_law() {
        build("", &["contact.rolling=\"epsd\""]).unwrap();
        refused(
            "",
            &["contact.rolling=\"constant\"", "contact.rotation=false"],
            &["contact.rolling", "contact.rotation"],
        );
        refused(
            "",
            &["contact.rolling=\"sticky\""],
            &["rolling", "none", "constant", "epsd"],
        );
    }

    #[test]
    fn lammps_granular_preset_keys() {
        let preset = "contact.preset=\"lammps-granular\"";
        build("", &[preset]).unwrap();
        build(
            "",
            &[
                preset,
                "contact.rolling=\"epsd\"",
                "contact.rolling_stiffness=100.0",
                "contact.rolling_damping=1.0",
            ],
        )
        .unwrap();
        refused(
            "",
            &[
                preset,
                "contact.rolling=\"epsd\"",
                "contact.rolling_damping=1.0",
            ],
            &["contact.rolling_stiffness", "required"],
        );
        refused(
            "",
            &[preset, "contact.rolling=\"constant\""],
            &["contact.rolling", "none", "epsd"],
        );
        refused(
            "",
            &["contact.rolling_stiffness=100.0"],
            &["contact.rolling_stiffness", "lammps-granular"],
        );
        refused(
            "",
            &[preset, "contact.model=\"spring-dashpot\""],
            &["lammps-granular", "spring-dashpot"],
        );
        refused(
            "",
            &[preset, "contact.cohesion=\"dmt\""],
            &["contact.cohesion", "none"],
        );
        refused(
            "",
            &[
                preset,
                "contact.rolling=\"epsd\"",
                "contact.rolling_stiffness=-1.0",
                "contact.rolling_damping=1.0",
            ],
            &["contact.rolling_stiffness = -1", "positive"],
        );
    }

    #[test]
    fn a_material_scenario_builds_with_the_material_density() {
        build("", &[]).unwrap();
        let loaded = load_str(
            &std::fs::read_to_string(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("../../scenarios/impact-sphere-plane.toml"),
            )
            .unwrap(),
            "impact.toml",
            ".".into(),
            &[],
        )
        .unwrap();
        let (md, _) = build_md::<D3>(&loaded).unwrap();
        // 2700 kg/m³ × (4/3) π (0.1 m)³, not particles.density's default.
        let m = 2700.0 * 4.0 / 3.0 * std::f64::consts::PI * 1e-3;
        assert!((md.particles.mass[0] / m - 1.0).abs() < 1e-12);
        assert!(md.settings.law.materials().is_some());
    }

    #[test]
    fn bad_materials_are_refused_by_key() {
        refused(
            "",
            &["particles.material=\"sand\""],
            &["particles.material", "\"sand\"", "\"glass\", \"steel\""],
        );
        refused(
            "",
            &["walls.0.material=\"wood\""],
            &["walls[0].material", "wood"],
        );
        refused(
            "",
            &["materials.0.poisson_ratio=0.5"],
            &["materials[0].poisson_ratio", "(-1, 0.5)"],
        );
        refused(
            "",
            &["materials.1.poisson_ratio=-1.0"],
            &["materials[1].poisson_ratio"],
        );
        refused(
            "",
            &["materials.0.youngs_modulus=-1.0"],
            &["materials[0].youngs_modulus", "positive"],
        );
        refused(
            "",
            &["materials.0.restitution=0.0"],
            &["materials[0].restitution", "(0, 1]"],
        );
        refused(
            "",
            &["materials.0.friction=-0.1"],
            &["materials[0].friction"],
        );
        refused("", &["contact.kn=1000.0"], &["contact.kn", "hertz-mindlin"]);
        refused(
            "",
            &["contact.model=\"spring-dashpot\"", "contact.kn=1000.0"],
            &["contact.model", "hertz-mindlin"],
        );
        refused(
            "[[material_pairs]]\na = \"glass\"\nb = \"rubber\"\nfriction = 0.5\n",
            &[],
            &["material_pairs[0].b", "rubber"],
        );
        refused(
            "[[material_pairs]]\na = \"glass\"\nb = \"steel\"\nrestitution = 1.5\n",
            &[],
            &["material_pairs[0].restitution", "(0, 1]"],
        );
        refused("[[materials]]\nname = \"glass\"\ndensity = 1.0\nyoungs_modulus = 1.0\npoisson_ratio = 0.2\nrestitution = 0.5\nfriction = 0.1\n", &[], &["materials[2].name", "twice"]);
    }

    #[test]
    fn one_kind_one_material() {
        let glass = "{ position = [0.005, 0.005, 0.002] }";
        let steel = "{ position = [0.002, 0.002, 0.002], material = \"steel\" }";
        // Both grains are kind 1: the first takes particles.material.
        refused_with(
            build_with(&format!("[{glass}, {steel}]"), "", &[]),
            &["particles.add[1].material", "kind 1", "own kind"],
        );
        let steel3 = "{ position = [0.002, 0.002, 0.002], material = \"steel\", kind = 3 }";
        build_with(&format!("[{glass}, {steel3}]"), "", &[]).unwrap();
    }
}
