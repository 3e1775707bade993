//! The grain–grain contacts of the current state as a list (ids, overlap,
//! normal, force), for analysis from outside the engine.

use super::Md;
use crate::contact::{Contact, ContactModel, RunLaw, Step};
use crate::dim::Dim;

pub use crate::view::ContactList;

impl<D: Dim> Md<D> {
    /// Every grain–grain contact now. The force is the contact law
    /// evaluated on the present positions, velocities and stretched spring
    /// (the spring is not advanced); it is the force the engine adds at a
    /// force evaluation made in this state. Grain–wall contacts are not
    /// listed.
    pub fn contact_list(&self) -> ContactList<D> {
        // The law as compiled for the run (LAMMPS's forces under the
        // `lammps-granular` preset).
        self.settings.law.with_kernel(ListRun(self))
    }

    fn contacts_under<L: ContactModel>(&self, law: &L) -> ContactList<D> {
        let p = &self.particles;
        let mut out = ContactList::default();
        let masses = self.contact_mass();
        let mass = |i: usize| {
            if p.frozen[i] {
                f64::INFINITY
            } else {
                masses[i]
            }
        };
        for (k, &[i, j]) in self.neighbors.pairs.iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let del = p.pos[i] - (p.pos[j] + self.neighbors.shift(self.neighbors.image[k]));
            let (ri, rj) = (p.radius[i], p.radius[j]);
            let r = D::norm(del);
            let pair = law.pair_index(p.kind[i], p.kind[j]);
            // A formed JKR contact is kept beyond touching, as the pair
            // loop keeps it.
            let marked = L::BONDED && self.rolling.get(k).is_some_and(|m| *m != D::zero());
            let reach = if marked { law.reach(pair, ri, rj) } else { 0.0 };
            if r >= ri + rj + reach {
                continue;
            }
            let n = del * (1.0 / r);
            let mut v_rel = p.vel[i] - p.vel[j];
            if self.neighbors.sheared() {
                v_rel -= self.neighbors.velocity_shift(self.neighbors.image[k]);
            }
            if law.rotation() {
                v_rel -= D::ang_cross(p.omega[i] * ri + p.omega[j] * rj, n);
            }
            let mut spring = self.springs.get(k).copied().unwrap_or(D::zero());
            let contact = Contact::<D> {
                overlap: ri + rj - r,
                normal: n,
                v_rel,
                mi: mass(i),
                mj: mass(j),
                ri,
                rj,
                omega_rel: p.omega[i] - p.omega[j],
                pair,
            };
            let still = Step {
                dt: 0.0,
                update: false,
            };
            let f = law.evaluate(&contact, &mut spring, still);
            out.ids.push([p.id[i], p.id[j]]);
            out.overlap.push(ri + rj - r);
            out.normal.push(n);
            out.branch.push(del);
            out.force.push(f.force * law.force_factor(masses[i]));
        }
        out
    }
}

/// [`Md::contacts_under`] for the run's law as compiled.
struct ListRun<'a, D: Dim>(&'a Md<D>);

impl<D: Dim> RunLaw<ContactList<D>> for ListRun<'_, D> {
    fn run<L: ContactModel>(self, law: &L) -> ContactList<D> {
        self.0.contacts_under(law)
    }
}

#[cfg(test)]
mod tests {
    use crate::contact::{ContactLaw, MassScaling};
    use crate::dim::D3;
    use crate::domain::Domain;
    use crate::md::{Md, MdSettings};
    use crate::particles::{ParticleRecord, Particles};
    use glam::DVec3;

    /// Two resting spheres pressed together by ξ: the force is k_n ξ^β
    /// along the line of centres, the closed form of the elastic law.
    #[test]
    fn resting_pair_has_the_elastic_force() {
        let law = ContactLaw {
            kn: 1.0e4,
            beta: 1.5,
            gamma_n: 30.0,
            gamma_t: 0.0,
            kt: 0.0,
            mu: 0.5,
            scaling: MassScaling::Reduced,
            rotation: true,
        };
        let mut p = Particles::<D3>::new();
        p.push_record(ParticleRecord::new(
            7,
            DVec3::new(5.0, 5.0, 5.0),
            0.5,
            1.0,
            0.1,
        ));
        p.push_record(ParticleRecord::new(
            9,
            DVec3::new(5.0, 5.0, 5.99),
            0.5,
            1.0,
            0.1,
        ));
        let domain = Domain::new(DVec3::ZERO, DVec3::splat(10.0), [false; 3]);
        let md = Md::new(p, domain, Vec::new(), MdSettings::new(1e-5, law, 0.2)).unwrap();
        let c = md.contact_list();
        assert_eq!(c.ids.len(), 1);
        let [a, b] = c.ids[0];
        assert_eq!((a.min(b), a.max(b)), (7, 9));
        let xi = 1.0 - 0.99;
        assert!((c.overlap[0] - xi).abs() < 1e-12);
        let expect = 1.0e4 * xi.powf(1.5);
        // The force pushes the first grain away from the second.
        let f = c.force[0];
        assert!((f.length() - expect).abs() < 1e-9 * expect, "{f:?}");
        assert!(f.dot(c.normal[0]) > 0.0);
        assert!(c.normal[0].z.abs() > 1.0 - 1e-12);
    }
}
