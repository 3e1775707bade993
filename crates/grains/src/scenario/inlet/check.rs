//! What `grains check` prints of the inlets, and the lightest and widest
//! grain they can bring, which the time step and the neighbour skin of a
//! run must allow for.

use super::bodies::BodyMix;
use super::Inlet;
use crate::dim::Dim;
use crate::error::Result;
use crate::scenario::schema::{Dimension, InletRegion, InletSpec, OrientationSpec, Scenario};
use crate::scenario::Loaded;
use serde_json::{json, Value};
use std::path::Path;

/// The smallest mass and the largest diameter of the grains the inlets of
/// the scenario can bring (`None` without inlets; a body's sub-spheres
/// count as grains of their own size, as placed bodies' do): the time step
/// and the neighbour skin of a run must allow for them.
pub fn extent(loaded: &Loaded) -> Result<Option<(f64, f64)>> {
    let s = &loaded.scenario;
    let mut out: Option<(f64, f64)> = None;
    for (i, spec) in s.inlets.iter().enumerate() {
        let inlet = match s.dimension {
            Dimension::Two => extent_of::<crate::dim::D2>(loaded, i, spec)?,
            Dimension::Three => extent_of::<crate::dim::D3>(loaded, i, spec)?,
        };
        out = Some(match out {
            Some((m, d)) => (m.min(inlet.0), d.max(inlet.1)),
            None => inlet,
        });
    }
    Ok(out)
}

fn extent_of<D: Dim>(loaded: &Loaded, i: usize, spec: &InletSpec) -> Result<(f64, f64)> {
    let x = Inlet::<D>::new(&loaded.scenario, &loaded.base_dir, i, spec)?;
    match body_mix(loaded, &x, spec)? {
        None => Ok((x.model.mass(x.mix.lightest(), x.law.min()), x.law.max())),
        Some(b) => Ok((
            x.model.mass(x.mix.lightest(), 2.0 * b.smallest_sub()),
            2.0 * b.largest_sub(),
        )),
    }
}

/// An inlet's bodies on the scenario's shapes (`None`: it brings grains).
fn body_mix<D: Dim>(loaded: &Loaded, x: &Inlet<D>, spec: &InletSpec) -> Result<Option<BodyMix<D>>> {
    let Some(shares) = &x.shares else {
        return Ok(None);
    };
    let (shapes, props) = crate::scenario::shapes::build::<D>(loaded)?;
    BodyMix::new(spec, &x.key, shares, &shapes, &props).map(Some)
}

/// What `grains check` prints of an inlet of bodies: its shapes with
/// their fractions, masses and bounding radii (`None`: grains).
fn body_report(loaded: &Loaded, i: usize, spec: &InletSpec) -> Result<Option<Value>> {
    let (s, base) = (&loaded.scenario, &loaded.base_dir);
    Ok(match s.dimension {
        Dimension::Two => {
            let x = Inlet::<crate::dim::D2>::new(s, base, i, spec)?;
            body_mix(loaded, &x, spec)?.map(|b| b.report())
        }
        Dimension::Three => {
            let x = Inlet::<crate::dim::D3>::new(s, base, i, spec)?;
            body_mix(loaded, &x, spec)?.map(|b| b.report())
        }
    })
}

/// What `grains check` prints of the inlets: per inlet the rate, the count
/// expected by the end of a run of `duration` seconds, and the size law's
/// summary.
pub fn check_report(loaded: &Loaded, duration: f64) -> Result<Value> {
    let s = &loaded.scenario;
    let rows = (s.inlets.iter().enumerate())
        .map(|(i, spec)| {
            let x = Inlet::<crate::dim::D3>::new_any(s, &loaded.base_dir, i, spec)?;
            if let Some(shapes) = body_report(loaded, i, spec)? {
                let (unit, rate) = match (x.amount.by_mass, x.amount.per_second) {
                    (false, Some(q)) => ("bodies/s", Some(q)),
                    (true, Some(q)) => ("kg/s", Some(q)),
                    (_, None) => ("all at start", None),
                };
                return Ok(json!({
                    "rate": rate,
                    "rate_unit": unit,
                    "start": x.start,
                    "stop": x.stop.is_finite().then_some(x.stop),
                    "expected": x.target(duration),
                    "expected_unit": if x.amount.by_mass { "kg" } else { "bodies" },
                    "bodies": shapes,
                    "orientation": match &spec.orientation {
                        Some(OrientationSpec::Quaternion(_)) => "fixed",
                        _ => "random",
                    },
                }));
            }
            let size = x.law.summary();
            let (unit, rate) = match (x.amount.by_mass, x.amount.per_second) {
                (false, Some(q)) => ("grains/s", Some(q)),
                (true, Some(q)) => ("kg/s", Some(q)),
                (_, None) => ("all at start", None),
            };
            let expected = x.target(duration);
            Ok(json!({
                "rate": rate,
                "rate_unit": unit,
                "start": x.start,
                "stop": x.stop.is_finite().then_some(x.stop),
                "expected": expected,
                "expected_unit": if x.amount.by_mass { "kg" } else { "grains" },
                "size": {
                    "min": x.law.min(),
                    "max": x.law.max(),
                    "number_mean": size.number.mean,
                    "mass_mean": size.mass.mean,
                },
                "mixture": spec.materials.is_some().then(|| x.mix.report()),
            }))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Value::Array(rows))
}

impl Inlet<crate::dim::D3> {
    /// The inlet's keys checked in the scenario's own dimension, its
    /// numbers (region aside) read in 3D's: what `grains check` prints.
    fn new_any(s: &Scenario, base: &Path, i: usize, spec: &InletSpec) -> Result<Self> {
        if s.dimension == Dimension::Two {
            Inlet::<crate::dim::D2>::new(s, base, i, spec)?;
            let mut spec = spec.clone();
            spec.region = InletRegion::Box {
                lo: vec![0.0; 3],
                hi: vec![1.0; 3],
            };
            spec.velocity = None;
            return Inlet::new(s, base, i, &spec);
        }
        Inlet::new(s, base, i, spec)
    }
}
