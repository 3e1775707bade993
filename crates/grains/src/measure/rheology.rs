//! Rheology of a sheared cell (`measure.rheology`): per sample, the stress
//! of the whole box from its contacts and the grains' motion, the shear
//! stress τ, the pressure P, the friction coefficient μ = τ/P and the
//! inertial number I = |γ̇| d / √(P/ρ) (GDR MiDi 2004; da Cruz et al.
//! 2005), with the packing fraction and the coordination number.
//!
//! The stress is the virial one over the box volume V, compression
//! positive: σ = (Σ_grains m δv ⊗ δv + Σ_contacts r ⊗ f) / V, with δv the
//! velocity less the mean shear flow γ̇ (y − y_mid) along the shear axis
//! (and the mean drift), over the mobile grains, r the branch vector from the second grain's image
//! to the first and f the force on the first. τ = −sgn(γ̇) (σ_xg + σ_gx)/2
//! for the shear axis x and gradient axis g, P = tr σ / D.

use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::write_atomic;
use crate::view::GrainView;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::Path;

/// One sample: time, τ, P, μ, I, packing fraction, coordination number.
pub type Row = [f64; 7];

/// The rheology samples of a run.
#[derive(Clone, Debug, Default)]
pub struct Rheology {
    rows: Vec<Row>,
}

impl Rheology {
    /// Refuses a box that is not sheared (τ, μ and I need a shear rate)
    /// and an engine that cannot tell its contact forces.
    pub fn begin<D: Dim>(view: &GrainView<D>) -> Result<Self> {
        if view.domain.shear.is_none() {
            return Err(Error::input(
                "measure.rheology needs a sheared box: domain.shear = \
                 { axis, gradient_axis, rate }",
            ));
        }
        if view.contact_virial().is_none() {
            return Err(Error::input(
                "measure.rheology: this engine does not report its contact forces",
            ));
        }
        Ok(Self::default())
    }

    /// Adds the sample of the grains now.
    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        if let (Some(virial), Some(_)) = (view.contact_virial(), view.domain.shear) {
            self.rows.push(row(view, &virial));
        }
    }

    /// The samples taken.
    pub fn rows(&self) -> &[Row] {
        &self.rows
    }

    pub fn save(&self, e: &mut Enc) {
        e.len(self.rows.len());
        for r in &self.rows {
            r.iter().for_each(|&x| e.f64(x));
        }
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let n = d.len(56, "rheology samples")?;
        let mut rows = Vec::with_capacity(n);
        for _ in 0..n {
            let mut r = [0.0; 7];
            for x in &mut r {
                *x = d.f64("rheology sample")?;
            }
            rows.push(r);
        }
        Ok(Self { rows })
    }

    /// Writes `rheology.csv`, one row per sample.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut csv = String::from(
            "time,shear_stress,pressure,mu,inertial_number,packing_fraction,coordination\n",
        );
        for r in &self.rows {
            let cells: Vec<String> = r.iter().map(|x| x.to_string()).collect();
            let _ = writeln!(csv, "{}", cells.join(","));
        }
        write_atomic(&dir.join("rheology.csv"), csv.as_bytes())
    }

    /// Time averages for summary.json: ⟨τ⟩, ⟨P⟩, μ = ⟨τ⟩/⟨P⟩, I from ⟨P⟩
    /// (through the mean of I √P, which holds γ̇ d √ρ), ⟨φ⟩, ⟨Z⟩.
    pub fn scalars(&self, summary: &mut Map<String, Value>) {
        let n = self.rows.len() as f64;
        let mean = |k: usize| self.rows.iter().map(|r| r[k]).sum::<f64>() / n;
        let (tau, p) = (mean(1), mean(2));
        // I √P = |γ̇| d √ρ is the same in every sample (where P > 0: a
        // sample with no contacts and no fluctuation yet has P = 0).
        let scale = (self.rows.iter())
            .map(|r| r[4] * r[2].sqrt())
            .find(|x| x.is_finite())
            .unwrap_or(f64::NAN);
        summary.insert("rheology_samples".into(), json!(self.rows.len()));
        summary.insert("shear_stress".into(), json!(tau));
        summary.insert("pressure".into(), json!(p));
        summary.insert("mu".into(), json!(tau / p));
        summary.insert("inertial_number".into(), json!(scale / p.sqrt()));
        summary.insert("packing_fraction".into(), json!(mean(5)));
        summary.insert("coordination".into(), json!(mean(6)));
    }
}

/// One sample from the grains and the contact virial `[Σ r ⊗ f, contacts]`.
fn row<D: Dim>(view: &GrainView<D>, virial: &([[f64; 3]; 3], usize)) -> Row {
    let Some(shear) = view.domain.shear else {
        return [f64::NAN; 7];
    };
    let (a, g) = (shear.axis, shear.gradient);
    let p = &view.grains;
    let mid = 0.5 * (D::get(view.domain.lo, g) + D::get(view.domain.hi, g));
    // The mean flow: γ̇ (y − y_mid) plus the mass-weighted drift along x.
    let (mut mass, mut drift) = (0.0, 0.0);
    let mobile = || (0..p.len()).filter(|&i| !p.frozen[i]);
    for i in mobile() {
        let u = shear.rate * (D::get(p.pos[i], g) - mid);
        mass += p.mass[i];
        drift += p.mass[i] * (D::get(p.vel[i], a) - u);
    }
    let drift = drift / mass;
    let mut s = virial.0;
    let (mut volume_grains, mut diameters) = (0.0, 0.0);
    let mut n = 0.0;
    for i in mobile() {
        n += 1.0;
        let mut dv = D::to_xyz(p.vel[i]);
        dv[a] -= shear.rate * (D::get(p.pos[i], g) - mid) + drift;
        for (x, row) in s.iter_mut().enumerate() {
            for (y, cell) in row.iter_mut().enumerate() {
                *cell += p.mass[i] * dv[x] * dv[y];
            }
        }
        let r = p.radius[i];
        volume_grains += if D::D == 2 {
            std::f64::consts::PI * r * r
        } else {
            4.0 / 3.0 * std::f64::consts::PI * r * r * r
        };
        diameters += 2.0 * r;
    }
    let volume: f64 = (0..D::D).map(|k| view.domain.length(k)).product();
    let sigma = |x: usize, y: usize| s[x][y] / volume;
    let pressure = (0..D::D).map(|k| sigma(k, k)).sum::<f64>() / D::D as f64;
    let tau = -shear.rate.signum() * 0.5 * (sigma(a, g) + sigma(g, a));
    let density = mass / volume_grains;
    let inertial = shear.rate.abs() * (diameters / n) / (pressure / density).sqrt();
    [
        view.time,
        tau,
        pressure,
        tau / pressure,
        inertial,
        volume_grains / volume,
        2.0 * virial.1 as f64 / n,
    ]
}
