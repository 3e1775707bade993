//! Where a run's wall time goes, phase by phase of the step (what LAMMPS
//! prints as its timing breakdown after a run): read it before optimizing,
//! and to see what a change bought. Each phase is timed on the thread that
//! drives the step, around the whole parallel pass, so with several threads
//! a phase's time includes waiting for the slowest worker. About five clock
//! reads per step, a fraction of a microsecond: a per cent or two of the
//! default scenario's 200-grain step, far less of a large system's.

use serde_json::{json, Value};
use std::time::{Duration, Instant};

/// Wall time spent in each phase since the engine was built (or since
/// [`PhaseTimes::reset`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PhaseTimes {
    /// The contact test and the contact law over the neighbour list
    /// (grain–grain contacts).
    pub contacts: Duration,
    /// Contact shares across blocks, wall contacts and gravity, added to
    /// the sums after the pair loop.
    pub fields: Duration,
    /// The integrator's passes, with the displacement test of the
    /// neighbour list.
    pub integrate: Duration,
    /// Neighbour-list rebuilds: wrapping, spatial sorting, the build and
    /// the springs carried over.
    pub neighbors: Duration,
}

impl PhaseTimes {
    /// Zero in every phase.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// The time of all phases together.
    pub fn total(&self) -> Duration {
        self.contacts + self.fields + self.integrate + self.neighbors
    }

    /// The phases as JSON, each `scale` times its seconds, with `other`:
    /// what `wall_seconds` holds beyond the phases (stability checks,
    /// measurements, output; never negative).
    pub fn to_json(&self, wall_seconds: f64, scale: f64) -> Value {
        let s = |d: Duration| d.as_secs_f64() * scale;
        let other = (wall_seconds - self.total().as_secs_f64()).max(0.0) * scale;
        json!({
            "contacts": s(self.contacts),
            "fields": s(self.fields),
            "integrate": s(self.integrate),
            "neighbors": s(self.neighbors),
            "other": other,
        })
    }
}

/// Adds the time since `start` to `slot`; returns the present instant, the
/// start of whatever comes next.
#[inline]
pub(crate) fn add_since(slot: &mut Duration, start: Instant) -> Instant {
    let now = Instant::now();
    *slot += now - start;
    now
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{Motion, Shape, Wall};
    use crate::contact::hooke_history::lammps_law;
    use crate::dim::D2;
    use crate::domain::Domain;
    use crate::md::{Md, MdSettings};
    use crate::particles::{ParticleRecord, Particles};
    use glam::DVec2;

    /// A row of touching disks falling onto a floor: every phase has work.
    #[test]
    fn every_phase_of_a_run_is_timed() {
        let mut p = Particles::<D2>::new();
        for k in 0..40 {
            let x = 1.0 + 0.99 * k as f64;
            p.push_record(ParticleRecord::new(k, DVec2::new(x, 1.0), 0.5, 1.0, 0.1));
        }
        let domain = Domain::new(DVec2::ZERO, DVec2::new(50.0, 50.0), [false; 3]);
        let floor = Wall::new(
            "floor",
            Shape::Plane {
                point: DVec2::ZERO,
                normal: DVec2::Y,
            },
            Motion::Fixed,
        )
        .unwrap();
        let mut settings = MdSettings::new(1e-3, lammps_law(0.0), 0.02);
        settings.gravity = DVec2::new(0.0, -9.81);
        let started = Instant::now();
        let mut md = Md::new(p, domain, vec![floor], settings).unwrap();
        // Building the engine builds the list and evaluates the forces once.
        assert!(md.timing.neighbors > Duration::ZERO && md.timing.contacts > Duration::ZERO);
        md.timing.reset();
        md.advance(500).unwrap();
        let t = md.timing;
        for (name, d) in [
            ("contacts", t.contacts),
            ("fields", t.fields),
            ("integrate", t.integrate),
            ("neighbors", t.neighbors),
        ] {
            assert!(d > Duration::ZERO, "{name}: {t:?}");
        }
        assert!(md.neighbor_builds() > 1, "the disks fell less than a skin");
        assert!(t.total() <= started.elapsed(), "{t:?}");
    }

    #[test]
    fn json_gives_each_phase_and_the_rest_of_the_wall_time() {
        let t = PhaseTimes {
            contacts: Duration::from_millis(500),
            fields: Duration::from_millis(100),
            integrate: Duration::from_millis(200),
            neighbors: Duration::from_millis(50),
        };
        assert_eq!(t.total(), Duration::from_millis(850));
        let j = t.to_json(1.0, 1e3);
        let ms = |k: &str| j[k].as_f64().unwrap();
        assert!((ms("contacts") - 500.0).abs() < 1e-9);
        assert!((ms("fields") - 100.0).abs() < 1e-9);
        assert!((ms("integrate") - 200.0).abs() < 1e-9);
        assert!((ms("neighbors") - 50.0).abs() < 1e-9);
        assert!((ms("other") - 150.0).abs() < 1e-9);
        // A wall time shorter than the phases (another clock, rounding)
        // leaves nothing for the rest, not a negative time.
        assert_eq!(t.to_json(0.5, 1.0)["other"].as_f64(), Some(0.0));
        let mut r = t;
        r.reset();
        assert_eq!(r, PhaseTimes::default());
    }
}
