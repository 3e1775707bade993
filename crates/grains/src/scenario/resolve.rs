//! From the scenario's words to numbers: the contact law after presets, the
//! time step (given, or from the binary contact time), the run length and
//! the output interval, all checked for range.

use super::schema::{ContactPreset, ContactSpec, MotionSpec, Scenario, TimeStep};
use crate::boundary::Wall;
use crate::contact::binary::BinaryContact;
use crate::contact::{ContactLaw, MassScaling};
use crate::dim::Dim;
use crate::error::{Error, Result};

/// Everything `grains check` prints and the runner needs.
#[derive(Clone, Debug)]
pub struct Resolved {
    pub law: ContactLaw,
    pub dt: f64,
    /// Binary contact time of the two lightest grains (s).
    pub contact_time: f64,
    /// How dt was chosen, in words.
    pub dt_origin: String,
    /// Frequency of the first vibrating wall (Hz), if any.
    pub cycle_frequency: Option<f64>,
    pub relax_steps: u64,
    pub measure_steps: u64,
    /// Steps between thermo rows and frames.
    pub output_every: u64,
}

/// Resolves the contact law: the preset's values, then the explicit fields.
/// `lightest_mass` sets γ_n when the restitution coefficient is given.
pub fn contact_law(spec: &ContactSpec, lightest_mass: f64) -> Result<ContactLaw> {
    let base = match spec.preset {
        Some(ContactPreset::Seed) => ContactLaw {
            kn: 5.0e7,
            beta: 1.0,
            gamma_n: 200.0,
            gamma_t: 400.0,
            kt: 0.0,
            mu: f64::INFINITY,
            scaling: MassScaling::Seed,
            rotation: false,
        },
        Some(ContactPreset::LammpsHookeHistory) => ContactLaw {
            kn: 2.0e5,
            beta: 1.0,
            gamma_n: 50.0,
            gamma_t: 0.0,
            kt: 2.0 / 7.0 * 2.0e5,
            mu: 0.5,
            scaling: MassScaling::Reduced,
            rotation: true,
        },
        Some(ContactPreset::LammpsGranular) => {
            return Err(Error::input(
                "contact.preset = \"lammps-granular\" takes its law from [[materials]], not from coefficients",
            ))
        }
        None => {
            let Some(kn) = spec.kn else {
                return Err(Error::input(
                    "contact.kn is required unless contact.preset is given (\"seed\" or \"lammps-hooke-history\")",
                ));
            };
            ContactLaw {
                kn,
                beta: 1.0,
                gamma_n: 0.0,
                gamma_t: 0.0,
                kt: 0.0,
                mu: f64::INFINITY,
                scaling: MassScaling::Reduced,
                rotation: false,
            }
        }
    };
    let mut law = ContactLaw {
        kn: spec.kn.unwrap_or(base.kn),
        beta: spec.beta.unwrap_or(base.beta),
        gamma_n: spec.gamma_n.unwrap_or(base.gamma_n),
        gamma_t: spec.gamma_t.unwrap_or(base.gamma_t),
        kt: spec.kt.unwrap_or(base.kt),
        mu: spec.mu.unwrap_or(base.mu),
        scaling: spec.scaling.unwrap_or(base.scaling),
        rotation: spec.rotation.unwrap_or(base.rotation),
    };
    // LAMMPS's Kt = NULL means 2/7 Kn: follow a changed kn.
    if spec.preset == Some(ContactPreset::LammpsHookeHistory) && spec.kt.is_none() {
        law.kt = 2.0 / 7.0 * law.kn;
    }
    law.validate("contact")?;
    if let Some(e) = spec.restitution {
        if spec.gamma_n.is_some() {
            return Err(Error::input(
                "give either contact.gamma_n or contact.restitution, not both",
            ));
        }
        if !(e > 0.0 && e <= 1.0) {
            return Err(Error::input(format!(
                "contact.restitution = {e}: must be in (0, 1]"
            )));
        }
        if law.beta != 1.0 {
            return Err(Error::input(format!(
                "contact.restitution needs contact.beta = 1 (a power-law contact's restitution depends on the impact speed); give contact.gamma_n for beta = {}",
                law.beta
            )));
        }
        law.gamma_n = gamma_n_for_restitution(&law, e, lightest_mass);
    }
    Ok(law)
}

/// The γ_n that gives restitution `e` to a binary collision of two grains of
/// mass `m`: with ln e = −γ t_c/2 and t_c = π/√(ω0² − γ²/4), the damping
/// of the relative motion is γ = −2 ln(e) ω0 / √(π² + ln² e).
fn gamma_n_for_restitution(law: &ContactLaw, e: f64, m: f64) -> f64 {
    let unit = ContactLaw {
        gamma_n: 1.0,
        ..law.clone()
    };
    let b = BinaryContact::new(&unit, m, m);
    let ln_e = e.ln();
    let gamma = -2.0 * ln_e * b.kappa.sqrt() / (std::f64::consts::PI.powi(2) + ln_e * ln_e).sqrt();
    // b.gamma is the relative damping per unit γ_n (2 under seed scaling).
    gamma / b.gamma
}

/// The frequency of the first wall that vibrates or oscillates.
pub fn cycle_frequency(s: &Scenario) -> Option<f64> {
    s.walls.iter().find_map(|w| match &w.motion {
        MotionSpec::Vibrate { frequency, .. } | MotionSpec::Oscillate { frequency, .. }
            if *frequency > 0.0 =>
        {
            Some(*frequency)
        }
        _ => None,
    })
}

/// Fastest speed of any prescribed wall motion (m/s).
fn max_wall_speed(s: &Scenario) -> f64 {
    s.walls
        .iter()
        .map(|w| match &w.motion {
            MotionSpec::Vibrate {
                amplitude,
                frequency,
                modulation,
                ..
            } => 2.0 * std::f64::consts::PI * frequency * amplitude * (1.0 + modulation.abs()),
            MotionSpec::Oscillate {
                amplitude,
                frequency,
                ..
            } => {
                2.0 * std::f64::consts::PI
                    * frequency
                    * amplitude.iter().map(|a| a * a).sum::<f64>().sqrt()
            }
            MotionSpec::Translate { velocity } => {
                velocity.iter().map(|a| a * a).sum::<f64>().sqrt()
            }
            MotionSpec::Servo { max_speed, .. } => *max_speed,
            _ => 0.0,
        })
        .fold(0.0, f64::max)
}

fn positive(key: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::input(format!(
            "{key} = {v}: must be a positive number"
        )))
    }
}

fn span(
    key_s: &str,
    key_c: &str,
    seconds: Option<f64>,
    cycles: Option<f64>,
    f: Option<f64>,
) -> Result<f64> {
    match (seconds, cycles) {
        (Some(_), Some(_)) => Err(Error::input(format!(
            "give either {key_s} or {key_c}, not both"
        ))),
        (Some(0.0), None) => Ok(0.0),
        (Some(t), None) => positive(key_s, t),
        (None, Some(n)) => {
            let Some(f) = f else {
                return Err(Error::input(format!("{key_c} needs a vibrating wall (motion type \"vibrate\" or \"oscillate\") to define a cycle; give {key_s} in seconds instead")));
            };
            if n == 0.0 {
                return Ok(0.0);
            }
            Ok(positive(key_c, n)? / f)
        }
        (None, None) => Ok(0.0),
    }
}

/// Resolves timing; `lightest_mass` is the smallest mass of a mobile grain.
pub fn resolve(s: &Scenario, lightest_mass: f64) -> Result<Resolved> {
    super::materials::check_contact_keys(s)?;
    let law = if super::materials::uses_materials(s) {
        super::materials::equivalent_law(s)?
    } else {
        contact_law(&s.contact, lightest_mass)?
    };
    let g = s
        .gravity
        .as_ref()
        .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
        .unwrap_or(0.0);
    let v_impact = match s.run.impact_speed {
        Some(v) => positive("run.impact_speed", v)?,
        None => (g * s.particles.d0)
            .sqrt()
            .max(max_wall_speed(s))
            .max(s.particles.random_velocity)
            .max(1e-12),
    };
    let contact = BinaryContact::new(&law, lightest_mass, lightest_mass);
    let contact_time = contact.contact_time(v_impact);
    let safety = positive("run.dt_safety", s.run.dt_safety)?;
    let (dt, dt_origin) = match s.run.dt {
        TimeStep::Auto => {
            let how = if law.beta == 1.0 {
                format!("auto: t_c / {safety}")
            } else {
                format!("auto: t_c / {safety} at impact speed {v_impact:.3e} m/s")
            };
            // A heavily damped contact relaxes faster than it oscillates:
            // the explicit schemes then need dt well below 1/γ as well.
            let damping_limit = std::f64::consts::PI / (contact.gamma.max(1e-300) * safety);
            if damping_limit < contact_time / safety {
                (
                    damping_limit,
                    format!(
                        "auto: pi / (gamma_eff {:.3e} s^-1 x {safety}), the damping time",
                        contact.gamma
                    ),
                )
            } else {
                (contact_time / safety, how)
            }
        }
        TimeStep::Seconds(dt) => {
            let dt = positive("run.dt", dt)?;
            if dt * contact.gamma > 2.0 {
                return Err(Error::input(format!(
                    "run.dt = {dt:e} s is longer than 2/gamma = {:.3e} s for the contact damping \
                     (contact.gamma_n): the explicit integrators would blow up; lower run.dt or contact.gamma_n",
                    2.0 / contact.gamma
                )));
            }
            (dt, "given".to_string())
        }
    };
    if !(contact_time.is_finite() && contact_time > 0.0) {
        return Err(Error::input(format!(
            "the binary contact time is {contact_time}: check contact.kn, contact.gamma_n (overdamped?) and the grain masses"
        )));
    }
    let f = cycle_frequency(s);
    let relax = span(
        "run.relax",
        "run.relax_cycles",
        s.run.relax,
        s.run.relax_cycles,
        f,
    )?;
    let measure = span(
        "run.duration",
        "run.cycles",
        s.run.duration,
        s.run.cycles,
        f,
    )?;
    if measure == 0.0 {
        return Err(Error::input(
            "the run has no length: give run.duration (s) or run.cycles",
        ));
    }
    const MAX_STEPS: f64 = 1e11;
    if (relax + measure) / dt > MAX_STEPS {
        return Err(Error::input(format!(
            "the run would take {:.2e} steps of dt = {dt:.3e} s; check run.duration/run.cycles, run.dt and the contact parameters",
            (relax + measure) / dt
        )));
    }
    let steps = |t: f64| (t / dt).round() as u64;
    let every = match s.output.every {
        Some(e) => positive("output.every", e)?,
        None => measure / 100.0,
    };
    Ok(Resolved {
        law,
        dt,
        contact_time,
        dt_origin,
        cycle_frequency: f,
        relax_steps: steps(relax),
        measure_steps: steps(measure).max(1),
        output_every: steps(every).max(1),
    })
}

/// Marks the walls named in `contact.elastic_walls` elastic
/// ([`Wall::with_elastic`]); a name that is no wall's is an error listing
/// the walls there are.
pub fn elastic_walls<D: Dim>(names: &[String], walls: Vec<Wall<D>>) -> Result<Vec<Wall<D>>> {
    if let Some(bad) = names.iter().find(|n| !walls.iter().any(|w| &w.name == *n)) {
        let known: Vec<_> = walls.iter().map(|w| format!("\"{}\"", w.name)).collect();
        return Err(Error::input(format!(
            "contact.elastic_walls: no wall is named \"{bad}\"; the walls are [{}]",
            known.join(", ")
        )));
    }
    Ok(walls
        .into_iter()
        .map(|w| {
            let elastic = names.contains(&w.name);
            w.with_elastic(elastic)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restitution_gives_the_damping_that_produces_it() {
        for preset in [ContactPreset::Seed, ContactPreset::LammpsHookeHistory] {
            let spec = ContactSpec {
                preset: Some(preset),
                restitution: Some(0.7),
                ..Default::default()
            };
            let law = contact_law(&spec, 0.3).unwrap();
            let e = BinaryContact::new(&law, 0.3, 0.3)
                .linear_restitution()
                .unwrap();
            assert!((e - 0.7).abs() < 1e-12, "{preset:?}: {e}");
        }
    }

    #[test]
    fn restitution_out_of_range_is_refused() {
        for e in [0.0, 1.2, -0.5] {
            let spec = ContactSpec {
                preset: Some(ContactPreset::Seed),
                restitution: Some(e),
                ..Default::default()
            };
            let msg = contact_law(&spec, 1.0).unwrap_err().to_string();
            assert!(msg.contains("contact.restitution"), "{msg}");
        }
    }
}
