//! `domain.shear`: a box sheared by Lees–Edwards boundaries (Lees &
//! Edwards 1972), its keys checked against the rest of the scenario, the
//! domain's [`Shear`] built from them, and the linear start profile.

use super::schema::{Device, Dimension, Scenario, ShearSpec};
use crate::dim::Dim;
use crate::domain::{Domain, Shear};
use crate::error::{Error, Result};
use crate::md::barostat::Barostat;
use crate::particles::Particles;

/// Steps between the barostat's readings unless `pressure_every` says.
const PRESSURE_EVERY: u64 = 20;

/// The axis named `name` ("x", "y", "z") of a `dims`-dimensional box.
fn axis(key: &str, name: &str, dims: usize) -> Result<usize> {
    let a = match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => dims,
    };
    if a >= dims {
        let allowed = ["\"x\"", "\"y\"", "\"z\""][..dims].join(", ");
        return Err(Error::input(format!(
            "domain.shear.{key} = \"{name}\": allowed in {dims}D: {allowed}"
        )));
    }
    Ok(a)
}

/// The scenario's shear checked (without `domain.shear`, only that
/// nothing needs it): what does not run sheared is refused by name.
pub fn check(s: &Scenario) -> Result<()> {
    let Some(spec) = &s.domain.shear else {
        if s.measure.rheology {
            return Err(Error::input(
                "measure.rheology needs a sheared box: domain.shear = \
                 { axis, gradient_axis, rate }",
            ));
        }
        return Ok(());
    };
    if s.method == crate::settings::Method::Dsmc {
        return Err(Error::input(
            "domain.shear: the DSMC engine has no Lees–Edwards boundaries; use method = \"md\"",
        ));
    }
    if s.run.device != Device::Cpu {
        return Err(Error::input(
            "domain.shear: the GPU pipeline (run.device = \"gpu\" or \"mirror\") has no \
             Lees–Edwards boundaries; use run.device = \"cpu\"",
        ));
    }
    shear(spec, s.dimension, &s.domain.periodic)?;
    barostat(spec).map(|_| ())
}

/// The pressure control of `domain.shear` (`None`: constant volume):
/// `pressure` and `relax_time` positive, together, `pressure_every` at
/// least one step.
pub fn barostat(spec: &ShearSpec) -> Result<Option<Barostat>> {
    let Some(pressure) = spec.pressure else {
        for (key, given) in [
            ("relax_time", spec.relax_time.is_some()),
            ("pressure_every", spec.pressure_every.is_some()),
        ] {
            if given {
                return Err(Error::input(format!(
                    "domain.shear.{key} is a setting of the fixed-pressure box: give \
                     domain.shear.pressure (Pa) too, or leave {key} out (constant volume)"
                )));
            }
        }
        return Ok(None);
    };
    if !(pressure.is_finite() && pressure > 0.0) {
        return Err(Error::input(format!(
            "domain.shear.pressure = {pressure}: must be a positive normal stress (Pa)"
        )));
    }
    let Some(relax_time) = spec.relax_time else {
        return Err(Error::input(
            "domain.shear.pressure needs domain.shear.relax_time, the relaxation time τ_p (s) \
             of the box length: dL/dt = L (σ_gg − P) / (P τ_p)",
        ));
    };
    if !(relax_time.is_finite() && relax_time > 0.0) {
        return Err(Error::input(format!(
            "domain.shear.relax_time = {relax_time}: must be a positive time (s)"
        )));
    }
    let every = spec.pressure_every.unwrap_or(PRESSURE_EVERY);
    if every == 0 {
        return Err(Error::input(
            "domain.shear.pressure_every = 0: must be at least 1 (steps between readings)",
        ));
    }
    Ok(Some(Barostat {
        pressure,
        relax_time,
        every,
    }))
}

/// The domain's [`Shear`] from its keys.
pub fn shear(spec: &ShearSpec, dim: Dimension, periodic: &[bool]) -> Result<Shear> {
    let dims = dim.axes();
    let a = axis("axis", &spec.axis, dims)?;
    let g = axis("gradient_axis", &spec.gradient_axis, dims)?;
    if a != 0 {
        return Err(Error::input(format!(
            "domain.shear.axis = \"{}\": only \"x\" is supported (the flow direction)",
            spec.axis
        )));
    }
    if g == a {
        return Err(Error::input(
            "domain.shear: axis and gradient_axis are the same axis; give two different axes",
        ));
    }
    for (key, name, k) in [
        ("axis", &spec.axis, a),
        ("gradient_axis", &spec.gradient_axis, g),
    ] {
        if !periodic.get(k).copied().unwrap_or(false) {
            return Err(Error::input(format!(
                "domain.shear.{key} = \"{name}\": that axis must be periodic \
                 (domain.periodic) for Lees–Edwards boundaries"
            )));
        }
    }
    if !spec.rate.is_finite() {
        return Err(Error::input(format!(
            "domain.shear.rate = {}: must be a finite shear rate (1/s)",
            spec.rate
        )));
    }
    Ok(Shear {
        axis: a,
        gradient: g,
        rate: spec.rate,
    })
}

/// Adds the linear profile γ̇ (y − y_mid) along the shear axis to the
/// velocity of every mobile grain: the steady profile of a homogeneous
/// shear flow, continuous across the sliding images.
pub fn start_profile<D: Dim>(p: &mut Particles<D>, domain: &Domain<D>) {
    let Some(s) = domain.shear else {
        return;
    };
    let mid = 0.5 * (D::get(domain.lo, s.gradient) + D::get(domain.hi, s.gradient));
    for i in 0..p.len() {
        if p.frozen[i] {
            continue;
        }
        let u = D::get(p.vel[i], s.axis) + s.rate * (D::get(p.pos[i], s.gradient) - mid);
        D::set(&mut p.vel[i], s.axis, u);
    }
}
