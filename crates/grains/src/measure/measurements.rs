//! The MD measurements a scenario asks for (`[measure]`), accumulated
//! between steps (the run loop's measurement hook drives them), saved in
//! and loaded from a checkpoint, written at the end.

use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::measure::impact::Impacts;
use crate::measure::phase::drive;
use crate::measure::{
    Convection, DisplacementField, FlowField, PhaseSnapshots, Profiles, Rheology, Tracer,
    Trajectories,
};
use crate::scenario::Loaded;
use crate::view::GrainView;
use serde_json::{json, Map, Value};
use std::path::Path;

/// Measurements the scenario asked for.
pub(crate) struct Measurements {
    pub(crate) displacement: Option<DisplacementField>,
    convection: Option<Convection>,
    phases: Option<PhaseSnapshots>,
    tracer: Option<Tracer>,
    profiles: Option<Profiles>,
    trajectories: Option<Trajectories>,
    flow_field: Option<FlowField>,
    impact: Option<Impacts>,
    fields: Option<crate::measure::fields::FieldsMeasure>,
    rheology: Option<Rheology>,
}

impl Measurements {
    /// `remaining`: steps of the measurement; `dt` the time step.
    pub(crate) fn begin<D: Dim>(
        loaded: &Loaded,
        view: &GrainView<D>,
        remaining: u64,
        dt: f64,
    ) -> Result<Self> {
        let m = &loaded.scenario.measure;
        let d0 = loaded.scenario.particles.d0;
        let phases = match &m.phases {
            Some(p) => Some(
                PhaseSnapshots::begin(view, &p.phases, p.segment_time, p.displacement_after)
                    .ok_or_else(|| {
                        Error::input("measure.phases needs a vibrating or oscillating wall")
                    })?,
            ),
            None => None,
        };
        let trajectories = match &m.trajectories {
            Some(t) => {
                let f = drive(view.walls).map(|d| d.0).ok_or_else(|| {
                    Error::input("measure.trajectories needs a vibrating or oscillating wall")
                })?;
                let window = (t.cycles / (f * dt)).round() as u64;
                Some(Trajectories::new(view, t.every, remaining, window))
            }
            None => None,
        };
        if let Some(p) = &m.profiles {
            if !(p.bin.is_finite() && p.bin > 0.0) {
                return Err(Error::input(format!(
                    "measure.profiles.bin = {}: must be positive (units of d0)",
                    p.bin
                )));
            }
        }
        let flow_field = match &m.flow_field {
            Some(f) => Some(FlowField::for_md(view, &f.cells, f.from, f.top)?),
            None => None,
        };
        let impact = match m.impact {
            true => Some(Impacts::begin(view)?),
            false => None,
        };
        let fields = m
            .fields
            .as_ref()
            .map(|f| fields_begin(f, d0, view))
            .transpose()?;
        let rheology = match m.rheology {
            true => Some(Rheology::begin(view)?),
            false => None,
        };
        Ok(Self {
            fields,
            rheology,
            impact,
            flow_field,
            displacement: m.displacement.then(|| DisplacementField::begin(view)),
            convection: m.convection.as_ref().map(|c| Convection::new(c.band)),
            phases,
            tracer: m.tracer.as_ref().map(|t| Tracer::new(t.id)),
            profiles: m.profiles.as_ref().map(|p| Profiles::new(view, p.bin * d0)),
            trajectories,
        })
    }

    /// The accumulators as checkpoint bytes: for each measurement in a
    /// fixed order a presence flag, then its state.
    pub(crate) fn save(&self) -> Vec<u8> {
        let mut e = Enc::default();
        fn one<T>(e: &mut Enc, m: &Option<T>, save: impl Fn(&T, &mut Enc)) {
            e.bool(m.is_some());
            if let Some(m) = m {
                save(m, e);
            }
        }
        one(&mut e, &self.displacement, DisplacementField::save);
        one(&mut e, &self.convection, Convection::save);
        one(&mut e, &self.phases, PhaseSnapshots::save);
        one(&mut e, &self.tracer, Tracer::save);
        one(&mut e, &self.profiles, Profiles::save);
        one(&mut e, &self.trajectories, Trajectories::save);
        // Last, so that checkpoints from before it existed still load.
        if let Some(f) = &self.flow_field {
            e.bool(true);
            f.save(&mut e);
        }
        // After it, the impacts (and the flow field's flag, false, before
        // them when it is absent): checkpoints without them are unchanged.
        if let Some(i) = &self.impact {
            if self.flow_field.is_none() {
                e.bool(false);
            }
            e.bool(true);
            i.save(&mut e);
        }
        // Last, the time the displacement field began (for its picture),
        // after both flags, false where absent: older checkpoints end
        // before it and load with the time unknown.
        let t0 = self.displacement.as_ref().and_then(|d| d.t0);
        if let Some(t0) = t0 {
            if self.flow_field.is_none() && self.impact.is_none() {
                e.bool(false);
            }
            if self.impact.is_none() {
                e.bool(false);
            }
            e.f64(t0);
        }
        // Last, the rheology: every flag before it written (false where
        // absent) and the start time where there is a displacement field
        // (NaN unknown), so that checkpoints without it are unchanged.
        if let Some(r) = &self.rheology {
            if t0.is_none() {
                if self.flow_field.is_none() && self.impact.is_none() {
                    e.bool(false);
                }
                if self.impact.is_none() {
                    e.bool(false);
                }
                if self.displacement.is_some() {
                    e.f64(f64::NAN);
                }
            }
            e.bool(true);
            r.save(&mut e);
        }
        // Last, the fields' windows, after every flag before them (false
        // where absent), so that checkpoints without them are unchanged.
        if let Some(f) = &self.fields {
            if self.rheology.is_none() {
                if t0.is_none() {
                    if self.flow_field.is_none() && self.impact.is_none() {
                        e.bool(false);
                    }
                    if self.impact.is_none() {
                        e.bool(false);
                    }
                    if self.displacement.is_some() {
                        e.f64(f64::NAN);
                    }
                }
                e.bool(false);
            }
            e.bool(true);
            f.save(&mut e);
        }
        e.buf
    }

    /// The accumulators saved by [`Measurements::save`]; each must be present
    /// exactly when the scenario asks for it.
    pub(crate) fn load<D: Dim>(
        loaded: &Loaded,
        view: &GrainView<D>,
        bytes: &[u8],
    ) -> std::result::Result<Self, String> {
        let m = &loaded.scenario.measure;
        let mut d = Dec::new(bytes);
        fn one<T>(
            d: &mut Dec,
            name: &str,
            want: bool,
            load: impl Fn(&mut Dec) -> DecResult<T>,
        ) -> DecResult<Option<T>> {
            let has = d.bool(name)?;
            if has != want {
                return Err(format!(
                    "measurement {name}: {} in the checkpoint but {} in the scenario",
                    if has { "present" } else { "absent" },
                    if want { "asked for" } else { "not asked for" }
                ));
            }
            has.then(|| load(d)).transpose()
        }
        let out = Self {
            displacement: one(
                &mut d,
                "displacement",
                m.displacement,
                DisplacementField::load,
            )?,
            convection: one(
                &mut d,
                "convection",
                m.convection.is_some(),
                Convection::load,
            )?,
            phases: one(&mut d, "phases", m.phases.is_some(), PhaseSnapshots::load)?,
            tracer: one(&mut d, "tracer", m.tracer.is_some(), Tracer::load)?,
            profiles: one(&mut d, "profiles", m.profiles.is_some(), Profiles::load)?,
            trajectories: one(
                &mut d,
                "trajectories",
                m.trajectories.is_some(),
                Trajectories::load,
            )?,
            flow_field: None,
            impact: None,
            // Fresh here; its windows follow the rheology's.
            fields: m
                .fields
                .as_ref()
                .map(|f| fields_begin(f, loaded.scenario.particles.d0, view))
                .transpose()
                .map_err(|e| e.to_string())?,
            rheology: None,
        };
        let mut out = out;
        // Written only when asked for (see `save`).
        let has_flow = d.remaining() > 0 && d.bool("flow_field")?;
        match (&m.flow_field, has_flow) {
            (Some(f), true) => {
                let fresh =
                    FlowField::for_md(view, &f.cells, f.from, f.top).map_err(|e| e.to_string())?;
                out.flow_field = Some(fresh.load(&mut d)?);
            }
            (None, false) => {}
            (want, _) => {
                return Err(format!(
                    "measurement flow_field: {} in the checkpoint but {} in the scenario",
                    if has_flow { "present" } else { "absent" },
                    if want.is_some() {
                        "asked for"
                    } else {
                        "not asked for"
                    }
                ))
            }
        }
        let has_impact = d.remaining() > 0 && d.bool("impact")?;
        if has_impact != m.impact {
            return Err(format!(
                "measurement impact: {} in the checkpoint but {} in the scenario",
                if has_impact { "present" } else { "absent" },
                if m.impact {
                    "asked for"
                } else {
                    "not asked for"
                }
            ));
        }
        if has_impact {
            out.impact = Some(Impacts::load(&mut d)?);
        }
        if let Some(field) = &mut out.displacement {
            if d.remaining() > 0 {
                let t0 = d.f64("displacement start time")?;
                field.t0 = (!t0.is_nan()).then_some(t0);
            }
        }
        let has_rheology = d.remaining() > 0 && d.bool("rheology")?;
        if has_rheology != m.rheology {
            return Err(format!(
                "measurement rheology: {} in the checkpoint but {} in the scenario",
                if has_rheology { "present" } else { "absent" },
                if m.rheology {
                    "asked for"
                } else {
                    "not asked for"
                }
            ));
        }
        if has_rheology {
            out.rheology = Some(Rheology::load(&mut d)?);
        }
        // A checkpoint from before the fields were saved opens a fresh
        // window.
        if d.remaining() > 0 && d.bool("fields")? {
            let Some(fresh) = out.fields.take() else {
                return Err(
                    "measurement fields: present in the checkpoint but not asked for in the \
                     scenario"
                        .into(),
                );
            };
            out.fields = Some(fresh.load(&mut d)?);
        }
        if d.remaining() != 0 {
            return Err(format!(
                "{} unexpected bytes after the measurements",
                d.remaining()
            ));
        }
        Ok(out)
    }

    /// Whether [`Self::step`] after engine step `step` at time `t` reads the
    /// grains (a decomposed run gathers them then). At any other step it
    /// only notes the drive's phase, so the serial runner skips it: judged
    /// from an older phase the answer is the same, as no target phase (nor
    /// cycle start) was crossed in between — else that step was due.
    pub(crate) fn due(&self, step: u64, t: f64) -> bool {
        self.phases.as_ref().is_some_and(|p| p.due(t))
            || self.trajectories.as_ref().is_some_and(|x| x.due(step))
            || self.impact.is_some()
            || self.fields.as_ref().is_some_and(|f| f.due(step))
    }

    /// After every step (phase- and step-exact measurements).
    pub(crate) fn step<D: Dim>(&mut self, view: &GrainView<D>) {
        if let Some(p) = &mut self.phases {
            p.step(view);
        }
        if let Some(t) = &mut self.trajectories {
            t.step(view);
        }
        if let Some(i) = &mut self.impact {
            i.step(view);
        }
        if let Some(f) = self
            .fields
            .as_mut()
            .filter(|f| f.wants(view.step, view.time))
        {
            f.sample(&crate::measure::fields::snapshot(view));
        }
    }

    pub(crate) fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        if let Some(d) = &mut self.displacement {
            d.sample(view);
        }
        if let Some(c) = &mut self.convection {
            c.sample(view);
        }
        if let Some(t) = &mut self.tracer {
            t.sample(view);
        }
        if let Some(p) = &mut self.profiles {
            p.sample(view);
        }
        if let Some(f) = &mut self.flow_field {
            f.sample(view);
        }
        if let Some(r) = &mut self.rheology {
            r.sample(view);
        }
    }

    pub(crate) fn write<D: Dim>(
        &self,
        dir: &Path,
        view: &GrainView<D>,
        last: &Frame,
    ) -> Result<()> {
        if let Some(c) = &self.convection {
            c.write(dir, view.domain)?;
        }
        if let Some(p) = &self.phases {
            p.write(dir, view.walls)?;
        }
        if let Some(t) = &self.tracer {
            t.write(dir, last)?;
        }
        if let Some(p) = &self.profiles {
            p.write(dir)?;
        }
        if let Some(t) = &self.trajectories {
            t.write(dir, last, view.walls)?;
        }
        if let Some(f) = &self.flow_field {
            f.write(dir, last, view.walls)?;
        }
        if let Some(i) = &self.impact {
            i.write(dir)?;
        }
        if let Some(f) = &self.fields {
            f.write(dir)?;
        }
        if let Some(r) = &self.rheology {
            r.write(dir)?;
        }
        Ok(())
    }

    pub(crate) fn scalars(&self, summary: &mut Map<String, Value>) {
        if let Some(c) = &self.convection {
            summary.insert("convection_center_vz".into(), json!(c.center_vz()));
            summary.insert("convection_edge_vz".into(), json!(c.edge_vz()));
            summary.insert(
                "convection_strength".into(),
                json!(c.center_vz() - c.edge_vz()),
            );
            summary.insert("heap_height".into(), json!(c.heap_height()));
        }
        if let Some(t) = &self.tracer {
            summary.insert("tracer_rms".into(), json!(t.rms_spread()));
        }
        if let Some(p) = &self.profiles {
            summary.insert("transport_velocity".into(), json!(p.transport_velocity()));
        }
        if let Some(i) = &self.impact {
            i.scalars(summary);
        }
        if let Some(f) = &self.fields {
            f.scalars(summary);
        }
        if let Some(r) = &self.rheology {
            r.scalars(summary);
        }
    }
}

/// `[measure.fields]` over the view's box, `d0` the mean grain diameter.
fn fields_begin<D: Dim>(
    f: &crate::scenario::schema::FieldsSpec,
    d0: f64,
    view: &GrainView<D>,
) -> Result<crate::measure::fields::FieldsMeasure> {
    let b = view.domain;
    let bx = (D::to_xyz(b.lo), D::to_xyz(b.hi), b.periodic);
    Ok(crate::measure::fields::FieldsMeasure::begin(f, d0, D::D, bx)?.begun_at(view.step))
}
