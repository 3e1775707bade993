//! The contact keys of a scenario checked against each other.
//!
//! Before any law is made: the `lammps-granular` preset's keys, cohesion
//! and rolling resistance only with the material law (and what they need
//! besides), material keys only with materials.

use super::{lammps_granular, uses_materials};
use crate::contact::cohesion::CohesionModel;
use crate::contact::rolling::RollingModel;
use crate::error::{Error, Result};
use crate::scenario::schema::{ContactModelKind, ContactSpec, Scenario, ShapeSpec};

/// The keys of the `lammps-granular` preset: the model it implies, its
/// rolling model (`sds` is `"epsd"`) and the `rolling sds` coefficients,
/// which mean nothing without it.
fn check_granular_preset(s: &Scenario) -> Result<()> {
    let c = &s.contact;
    let sds = [
        ("rolling_stiffness", c.rolling_stiffness),
        ("rolling_damping", c.rolling_damping),
    ];
    if !lammps_granular(s) {
        if let Some((key, _)) = sds.iter().find(|(_, v)| v.is_some()) {
            return Err(Error::input(format!(
                "contact.{key} is a coefficient of LAMMPS's rolling sds: it needs \
                 contact.preset = \"lammps-granular\" and contact.rolling = \"epsd\""
            )));
        }
        return Ok(());
    }
    if c.model == Some(ContactModelKind::SpringDashpot) {
        return Err(Error::input(
            "contact.preset = \"lammps-granular\" is a Hertz law from [[materials]]: leave out \
             contact.model or set it to \"hertz-mindlin\" (not \"spring-dashpot\")",
        ));
    }
    let cohesion = c.cohesion.unwrap_or_default();
    if cohesion != CohesionModel::None {
        return Err(Error::input(format!(
            "contact.cohesion = \"{}\" with contact.preset = \"lammps-granular\": the preset is \
             hertz/material without cohesion; allowed: \"none\"",
            cohesion.name()
        )));
    }
    match c.rolling.unwrap_or_default() {
        RollingModel::None => {
            if let Some((key, _)) = sds.iter().find(|(_, v)| v.is_some()) {
                return Err(Error::input(format!(
                    "contact.{key} is given but contact.rolling is \"none\": set contact.rolling = \
                     \"epsd\" (LAMMPS's rolling sds) or drop the key"
                )));
            }
        }
        RollingModel::Constant => return Err(Error::input(
            "contact.rolling = \"constant\" with contact.preset = \"lammps-granular\": LAMMPS's \
                 pair granular has no such model; allowed: \"none\", \"epsd\" (rolling sds)",
        )),
        RollingModel::Epsd => {
            for (key, v) in sds {
                match v {
                    None => {
                        return Err(Error::input(format!(
                            "contact.rolling = \"epsd\" with contact.preset = \"lammps-granular\" \
                             is LAMMPS's rolling sds k_r γ_r μ_r: contact.{key} is required"
                        )))
                    }
                    Some(v)
                        if !(v.is_finite() && v >= 0.0)
                            || (key == "rolling_stiffness" && v == 0.0) =>
                    {
                        return Err(Error::input(format!(
                            "contact.{key} = {v}: must be {}",
                            if key == "rolling_stiffness" {
                                "positive"
                            } else {
                                ">= 0"
                            }
                        )))
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(())
}

/// The `material` keys used without `contact.model = "hertz-mindlin"`, or
/// the coefficient keys used with it: both are mistakes.
pub fn check_contact_keys(s: &Scenario) -> Result<()> {
    check_granular_preset(s)?;
    check_rolling(s)?;
    let cohesion = s.contact.cohesion.unwrap_or_default();
    if cohesion != CohesionModel::None && !uses_materials(s) {
        return Err(Error::input(format!(
            "contact.cohesion = \"{}\" needs contact.model = \"hertz-mindlin\" (the [[materials]]' \
             surface_energy gives Γ); the spring-dashpot law, under the seed or the reduced scaling, \
             has no cohesion: allowed there: \"none\"",
            cohesion.name()
        )));
    }
    if !uses_materials(s) {
        let named = s.particles.material.is_some()
            || s.particles.add.iter().any(|a| a.material.is_some())
            || s.walls.iter().any(|w| w.material.is_some());
        if named {
            return Err(Error::input(
                "particles.material / walls.material name materials, but contact.model is not \
                 \"hertz-mindlin\": set contact.model = \"hertz-mindlin\" (allowed: \"spring-dashpot\", \"hertz-mindlin\")",
            ));
        }
        return Ok(());
    }
    let c: &ContactSpec = &s.contact;
    let coefficients = [
        ("preset", c.preset.is_some() && !lammps_granular(s)),
        ("kn", c.kn.is_some()),
        ("beta", c.beta.is_some()),
        ("gamma_n", c.gamma_n.is_some()),
        ("restitution", c.restitution.is_some()),
        ("gamma_t", c.gamma_t.is_some()),
        ("kt", c.kt.is_some()),
        ("mu", c.mu.is_some()),
        ("scaling", c.scaling.is_some()),
    ];
    if let Some((key, _)) = coefficients.iter().find(|(_, given)| *given) {
        return Err(Error::input(format!(
            "contact.{key} has no meaning with contact.model = \"hertz-mindlin\": the [[materials]] \
             give the stiffness, damping and friction (contact.rotation is the one other key)"
        )));
    }
    if s.materials.is_empty() {
        return Err(Error::input(
            "contact.model = \"hertz-mindlin\" needs at least one [[materials]] entry",
        ));
    }
    check_cohesion(s)
}

/// Cohesion needs a surface energy somewhere; JKR keeps a mark per
/// contact where epsd keeps its rolling spring, and mesh walls keep none.
fn check_cohesion(s: &Scenario) -> Result<()> {
    let cohesion = s.contact.cohesion.unwrap_or_default();
    if cohesion == CohesionModel::None {
        return Ok(());
    }
    let name = cohesion.name();
    let some_energy = s.materials.iter().any(|m| m.surface_energy > 0.0)
        || s.material_pairs
            .iter()
            .any(|p| p.surface_energy.is_some_and(|g| g > 0.0));
    if !some_energy {
        return Err(Error::input(format!(
            "contact.cohesion = \"{name}\" but no [[materials]] surface_energy (nor \
             [[material_pairs]] surface_energy) is positive: give the materials a surface_energy \
             (J/m²) or set contact.cohesion = \"none\""
        )));
    }
    if cohesion != CohesionModel::Jkr {
        return Ok(());
    }
    if s.contact.rolling == Some(RollingModel::Epsd) {
        return Err(Error::input(
            "contact.cohesion = \"jkr\" with contact.rolling = \"epsd\": not supported yet (both \
             keep a history per contact in the same place); use contact.rolling = \"constant\" or \
             \"none\", or contact.cohesion = \"dmt\"",
        ));
    }
    if let Some((k, w)) = s
        .walls
        .iter()
        .enumerate()
        .find(|(_, w)| matches!(w.shape, ShapeSpec::Mesh { .. }))
    {
        return Err(Error::input(format!(
            "contact.cohesion = \"jkr\" with the mesh wall walls[{k}] (\"{}\"): mesh walls do not \
             keep JKR contacts beyond touching yet; use contact.cohesion = \"dmt\"",
            w.name
        )));
    }
    Ok(())
}

/// Rolling resistance needs the material law and rotation (every wall,
/// meshes included, keeps epsd's rolling springs).
fn check_rolling(s: &Scenario) -> Result<()> {
    let model = s.contact.rolling.unwrap_or_default();
    if model == RollingModel::None {
        return Ok(());
    }
    let name = model.name();
    if !uses_materials(s) {
        return Err(Error::input(format!(
            "contact.rolling = \"{name}\" needs contact.model = \"hertz-mindlin\" (the \
             [[materials]]' rolling_friction gives μ_r); allowed with the spring-dashpot law: \"none\""
        )));
    }
    if s.contact.rotation == Some(false) {
        return Err(Error::input(format!(
            "contact.rolling = \"{name}\" with contact.rotation = false: rolling resistance is a \
             torque; set contact.rotation = true or contact.rolling = \"none\""
        )));
    }
    Ok(())
}
