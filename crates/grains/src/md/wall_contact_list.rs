//! The grain–wall contacts of the current state as a list (grain id, wall,
//! contact point, normal, force), the walls' counterpart of
//! [`super::contact_list`], for contact output and coarse-graining.

use super::Md;
use crate::boundary::MeshScratch;
use crate::contact::{Contact, ContactModel, RunLaw, Step};
use crate::dim::Dim;

pub use crate::view::WallContactList;

impl<D: Dim> Md<D> {
    /// Every grain–wall contact now, with the force the contact law gives on
    /// the present state (springs read, not advanced), as
    /// [`Md::contact_list`] does for pairs. A JKR contact held beyond
    /// touching is not listed.
    pub fn wall_contact_list(&self) -> WallContactList<D> {
        // The law as compiled for the run, as the wall loop runs it.
        self.settings.law.with_kernel(WallListRun(self))
    }

    fn wall_contacts_under<L: ContactModel>(&self, (law, elastic): (&L, &L)) -> WallContactList<D> {
        let p = &self.particles;
        let walls: Vec<_> = self.walls.iter().map(|w| w.at(self.time)).collect();
        let mut out = WallContactList::default();
        let mut scratch = MeshScratch::default();
        let mut found = Vec::new();
        let still = Step {
            dt: 0.0,
            update: false,
        };
        for i in 0..p.n_owned() {
            if p.frozen[i] {
                continue;
            }
            let (x, r, m) = (p.pos[i], p.radius[i], self.contact_mass()[i]);
            for (w, wall) in walls.iter().enumerate() {
                let wall_law = if wall.is_elastic() { elastic } else { law };
                found.clear();
                if wall.mesh().is_some() {
                    wall.mesh_contacts(x, r, None, &mut scratch, &mut found);
                } else if let Some(c) = wall.contact(x, r) {
                    found.push((u32::MAX, c));
                }
                for &(patch, c) in &found {
                    let mut spring = if patch == u32::MAX {
                        self.wall_springs.cursor(i..i + 1).get(i, w)
                    } else {
                        let key = (i as u32, w as u32, patch);
                        self.mesh_springs.cursor(i..i + 1).get_key(key)
                    };
                    let mut v_rel = p.vel[i] - c.velocity;
                    if law.rotation() {
                        v_rel -= D::ang_cross(p.omega[i] * r, c.normal);
                    }
                    let contact = Contact::<D> {
                        overlap: c.overlap,
                        normal: c.normal,
                        v_rel,
                        mi: m,
                        mj: f64::INFINITY,
                        ri: r,
                        rj: f64::INFINITY,
                        omega_rel: p.omega[i] - wall.spin(),
                        pair: wall_law.wall_pair_index(p.kind[i], w),
                    };
                    let f = wall_law.evaluate(&contact, &mut spring, still);
                    out.ids.push(p.id[i]);
                    out.wall.push(w);
                    out.point.push(c.point);
                    out.normal.push(c.normal);
                    out.overlap.push(c.overlap);
                    out.force.push(f.force * wall_law.force_factor(m));
                }
            }
        }
        out
    }
}

/// [`Md::wall_contacts_under`] for the run's law as compiled.
struct WallListRun<'a, D: Dim>(&'a Md<D>);

impl<D: Dim> RunLaw<WallContactList<D>> for WallListRun<'_, D> {
    fn run<L: ContactModel>(self, law: &L) -> WallContactList<D> {
        // An elastic wall meets grains with the law's elastic form, as in
        // the wall loop (`md/field_forces.rs`).
        let elastic = law.elastic_wall();
        self.0
            .wall_contacts_under((law, elastic.as_ref().unwrap_or(law)))
    }
}
