//! Collisions of two bodies (`measure.impact`): two grains, or a grain and
//! a wall. Per collision: the largest overlap, the peak normal force, the
//! contact duration, and the normal and tangential restitution and the
//! rebound angle; impacts.csv, and the first collision's figures in the
//! summary.
//!
//! Read after every step. A collision begins at the first step whose force
//! evaluation finds the contact and ends at the first that does not: the
//! duration is counted in steps (to ± dt). The normal n̂ is the line of
//! centres (the wall's normal) at the first step in contact; the incoming
//! velocities are those of the last step before it, the outgoing ones
//! those of the first step after. With v the velocity of the first grain
//! relative to its partner and u that of its contact point (v with the
//! spins' ω × r):
//! - normal restitution e_n = −v'·n̂ / v·n̂;
//! - tangential restitution e_t = u'_t / u_t, u_t the contact point's
//!   tangential speed signed along the incoming tangential direction
//!   (Chung & Ooi 2011: −1 when it reverses, as a ball that sticks);
//! - rebound angle atan(|v'_t| / v'_n) in degrees from the normal (of the
//!   centre's relative velocity).
//!
//! The peak normal force is the largest |F·n̂| of the contact's force on
//! the first grain (the grain's force less gravity).

use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::io::write_atomic;
use crate::view::GrainView;
use serde_json::{json, Map, Value};
use std::fmt::Write;
use std::path::Path;

/// One finished collision.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Collision {
    /// Time of the first step in contact (s).
    pub start: f64,
    pub duration: f64,
    pub max_overlap: f64,
    pub peak_force: f64,
    /// Normal and tangential relative velocity of the centres, in and out.
    pub vn_in: f64,
    pub vt_in: f64,
    pub vn_out: f64,
    pub vt_out: f64,
    /// Tangential speed of the contact point, in and out (signed along the
    /// incoming direction).
    pub ut_in: f64,
    pub ut_out: f64,
}

impl Collision {
    pub fn restitution(&self) -> f64 {
        -self.vn_out / self.vn_in
    }
    pub fn tangential_restitution(&self) -> f64 {
        self.ut_out / self.ut_in
    }
    pub fn rebound_angle_deg(&self) -> f64 {
        self.vt_out.abs().atan2(self.vn_out).to_degrees()
    }

    const FIELDS: usize = 10;

    fn to_array(self) -> [f64; Self::FIELDS] {
        [
            self.start,
            self.duration,
            self.max_overlap,
            self.peak_force,
            self.vn_in,
            self.vt_in,
            self.vn_out,
            self.vt_out,
            self.ut_in,
            self.ut_out,
        ]
    }

    fn from_slice(a: &[f64]) -> Self {
        Self {
            start: a[0],
            duration: a[1],
            max_overlap: a[2],
            peak_force: a[3],
            vn_in: a[4],
            vt_in: a[5],
            vn_out: a[6],
            vt_out: a[7],
            ut_in: a[8],
            ut_out: a[9],
        }
    }
}

/// The two bodies' relative state at one step.
struct Relative<D: Dim> {
    /// Whether the engine found the contact.
    touching: bool,
    overlap: f64,
    /// Unit normal from the partner to the first grain (None when the
    /// bodies are too far apart for a wall to give one).
    normal: Option<D::V>,
    /// Centre velocity of the first grain relative to the partner, and that
    /// of its contact point.
    v: D::V,
    u: D::V,
    /// The contact's force on the first grain.
    force: D::V,
}

type Xyz = [f64; 3];

/// The collisions of a two-body scenario.
#[derive(Clone, Debug, Default)]
pub struct Impacts {
    done: Vec<Collision>,
    /// The collision under way, with its normal.
    open: Option<(Collision, Xyz)>,
    /// The relative velocities (centre, contact point) at the last step out
    /// of contact.
    last_free: Option<(Xyz, Xyz)>,
}

impl Impacts {
    /// Checks that `view` has two bodies: two grains and no wall, or one
    /// grain and one wall.
    pub fn begin<D: Dim>(view: &GrainView<D>) -> Result<Self> {
        let (n, w) = (view.grains.len(), view.walls.len());
        if !matches!((n, w), (2, 0) | (1, 1)) {
            return Err(Error::input(format!(
                "measure.impact measures two bodies (two grains and no wall, or one grain and one \
                 wall); this scenario has {n} grains and {w} walls"
            )));
        }
        if view.grains.frozen.iter().all(|&f| f) {
            return Err(Error::input(
                "measure.impact: every grain is frozen; nothing can collide",
            ));
        }
        Ok(Self::default())
    }

    /// The first grain (a moving one; the lower id of two) and its partner.
    fn order<D: Dim>(view: &GrainView<D>) -> (usize, Option<usize>) {
        let p = &view.grains;
        if p.len() == 1 {
            return (0, None);
        }
        let first = if p.frozen[0] != p.frozen[1] {
            usize::from(p.frozen[0])
        } else {
            usize::from(p.id[1] < p.id[0])
        };
        (first, Some(1 - first))
    }

    fn relative<D: Dim>(view: &GrainView<D>) -> Relative<D> {
        let p = &view.grains;
        let (a, partner) = Self::order(view);
        let ra = p.radius[a];
        let gravity = if p.frozen[a] {
            D::zero()
        } else {
            view.gravity * p.mass[a]
        };
        let force = p.force[a] - gravity;
        let touching = view.contacts > 0;
        let (overlap, normal, v_partner, partner_point) = match partner {
            Some(b) => {
                let del = p.pos[a] - p.pos[b];
                let r = D::norm(del);
                let n = del * (1.0 / r);
                let rb = p.radius[b];
                // The partner's contact point: v_b + ω_b × (r_b n).
                let vb = p.vel[b];
                let point = vb + D::ang_cross(p.omega[b] * rb, n);
                (ra + rb - r, Some(n), vb, point)
            }
            None => {
                // Asked as for a grain twice as large, so that a contact
                // kept beyond touching (JKR) has its normal too.
                match view.walls[0].contact(p.pos[a], 2.0 * ra, view.time) {
                    Some(c) => (c.overlap - ra, Some(c.normal), c.velocity, c.velocity),
                    None => (f64::NEG_INFINITY, None, D::zero(), D::zero()),
                }
            }
        };
        let v = p.vel[a] - v_partner;
        // The first grain's contact point: v_a + ω_a × (−r_a n).
        let u = match normal {
            Some(n) => p.vel[a] - D::ang_cross(p.omega[a] * ra, n) - partner_point,
            None => v,
        };
        Relative {
            touching,
            overlap,
            normal,
            v,
            u,
            force,
        }
    }

    /// After every step.
    pub fn step<D: Dim>(&mut self, view: &GrainView<D>) {
        let now = Self::relative(view);
        let xyz = |v: D::V| D::to_xyz(v);
        let free = self
            .last_free
            .map(|(v, u)| (D::from_xyz(v), D::from_xyz(u)));
        match (&mut self.open, now.touching) {
            (None, true) => {
                let Some(n) = now.normal else { return };
                let (v_in, u_in) = free.unwrap_or((now.v, now.u));
                let vn = D::dot(v_in, n);
                let vt = v_in - n * vn;
                let ut = u_in - n * D::dot(u_in, n);
                let c = Collision {
                    start: view.time,
                    max_overlap: now.overlap,
                    peak_force: D::dot(now.force, n).abs(),
                    vn_in: vn,
                    vt_in: D::norm(vt),
                    ut_in: D::norm(ut),
                    ..Collision::default()
                };
                self.open = Some((c, xyz(n)));
            }
            (Some((c, _)), true) => {
                c.max_overlap = c.max_overlap.max(now.overlap);
                if let Some(n) = now.normal {
                    c.peak_force = c.peak_force.max(D::dot(now.force, n).abs());
                }
            }
            (Some((c, n)), false) => {
                let n = D::from_xyz(*n);
                let mut c = *c;
                c.duration = view.time - c.start;
                let vn = D::dot(now.v, n);
                let vt = now.v - n * vn;
                c.vn_out = vn;
                c.vt_out = D::norm(vt);
                // Signed along the incoming tangential direction of the
                // contact point.
                let (_, u_in) = free.unwrap_or((now.v, now.u));
                let t_in = u_in - n * D::dot(u_in, n);
                let ut = now.u - n * D::dot(now.u, n);
                let t_len = D::norm(t_in);
                c.ut_out = if t_len > 0.0 {
                    D::dot(ut, t_in) / t_len
                } else {
                    D::norm(ut)
                };
                self.done.push(c);
                self.open = None;
                self.last_free = Some((xyz(now.v), xyz(now.u)));
            }
            (None, false) => self.last_free = Some((xyz(now.v), xyz(now.u))),
        }
    }

    pub fn collisions(&self) -> &[Collision] {
        &self.done
    }

    /// impacts.csv: one line per finished collision.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut csv = String::from(
            "collision,t_start,duration,max_overlap,peak_force,vn_in,vt_in,vn_out,vt_out,\
             ut_in,ut_out,restitution,tangential_restitution,rebound_angle_deg\n",
        );
        for (k, c) in self.done.iter().enumerate() {
            let _ = write!(csv, "{}", k + 1);
            let derived = [
                c.restitution(),
                c.tangential_restitution(),
                c.rebound_angle_deg(),
            ];
            for v in c.to_array().into_iter().chain(derived) {
                let _ = write!(csv, ",{v:e}");
            }
            csv.push('\n');
        }
        write_atomic(&dir.join("impacts.csv"), csv.as_bytes())
    }

    /// The first collision's figures (none when no collision finished).
    pub fn scalars(&self, summary: &mut Map<String, Value>) {
        summary.insert("impacts".into(), json!(self.done.len()));
        let Some(c) = self.done.first() else {
            return;
        };
        summary.insert("impact_max_overlap".into(), json!(c.max_overlap));
        summary.insert("impact_peak_force".into(), json!(c.peak_force));
        summary.insert("impact_contact_time".into(), json!(c.duration));
        summary.insert("impact_restitution".into(), json!(c.restitution()));
        summary.insert(
            "impact_tangential_restitution".into(),
            json!(c.tangential_restitution()),
        );
        summary.insert(
            "impact_rebound_angle_deg".into(),
            json!(c.rebound_angle_deg()),
        );
    }

    pub fn save(&self, e: &mut Enc) {
        e.len(self.done.len());
        for c in &self.done {
            e.f64s(&c.to_array());
        }
        e.bool(self.open.is_some());
        if let Some((c, n)) = &self.open {
            e.f64s(&c.to_array());
            e.f64s(n);
        }
        e.bool(self.last_free.is_some());
        if let Some((v, u)) = &self.last_free {
            e.f64s(v);
            e.f64s(u);
        }
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let n = d.len(8 * Collision::FIELDS, "impacts")?;
        let mut done = Vec::with_capacity(n);
        let fields = |d: &mut Dec| -> DecResult<Collision> {
            let a = d.f64s("impact")?;
            if a.len() != Collision::FIELDS {
                return Err(format!(
                    "impact: {} fields, expected {}",
                    a.len(),
                    Collision::FIELDS
                ));
            }
            Ok(Collision::from_slice(&a))
        };
        for _ in 0..n {
            done.push(fields(d)?);
        }
        let xyz = |d: &mut Dec, what: &str| -> DecResult<Xyz> {
            let a = d.f64s(what)?;
            a.try_into()
                .map_err(|a: Vec<f64>| format!("{what}: {} components, expected 3", a.len()))
        };
        let open = if d.bool("impact open")? {
            Some((fields(d)?, xyz(d, "impact normal")?))
        } else {
            None
        };
        let last_free = if d.bool("impact last free")? {
            Some((xyz(d, "impact v")?, xyz(d, "impact u")?))
        } else {
            None
        };
        Ok(Self {
            done,
            open,
            last_free,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hooke_history::lammps_law;
    use crate::dim::D3;
    use crate::domain::Domain;
    use crate::md::{Md, MdSettings};
    use crate::particles::{ParticleRecord, Particles};
    use glam::DVec3;

    fn grains(n: u64) -> Md<D3> {
        let mut p = Particles::<D3>::new();
        for k in 0..n {
            let at = DVec3::new(2.0 * k as f64 + 1.0, 5.0, 5.0);
            p.push_record(ParticleRecord::new(k + 1, at, 0.5, 1.0, 0.1));
        }
        let domain = Domain::new(DVec3::ZERO, DVec3::splat(10.0), [false; 3]);
        Md::new(
            p,
            domain,
            Vec::new(),
            MdSettings::new(1e-4, lammps_law(0.0), 0.1),
        )
        .unwrap()
    }

    /// Two grains are two bodies; three, or one without a wall, are not.
    #[test]
    fn impact_needs_two_bodies() {
        assert!(Impacts::begin(&grains(2).view()).is_ok());
        for n in [1, 3] {
            let e = Impacts::begin(&grains(n).view()).unwrap_err().to_string();
            assert!(
                e.contains("measure.impact") && e.contains(&format!("{n} grains")),
                "{e}"
            );
        }
    }
}
