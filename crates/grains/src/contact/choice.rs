//! The contact law of a run, chosen once: the scenario resolves to one
//! [`Law`], and [`Law::with_kernel`] turns it into the compiled kernel that
//! the pair loop, the wall and mesh contacts and the contact list run.
//!
//! Each caller is generic over the kernel's type ([`RunLaw`]): the match
//! below runs once per call (a block of pairs, a range of grains), never
//! per contact, and every contact calls its law statically.
//!
//! A law is one file in `contact/` implementing [`super::ContactModel`]
//! for its kernels and [`Registered`] for the value a run holds, and one
//! line in the list at the end of this file.

use super::hertz_mindlin::{HertzMindlin, MaterialLaw};
use super::hooke_history::HookeHistory;
use super::law::ContactLaw;
use super::registered::{Registered, RunLaw};
use super::{cohesion::CohesionModel, rolling::RollingModel};
use crate::error::Result;

/// Declares [`Law`], one variant per registered law, and its dispatch to
/// each law's [`Registered`] methods.
macro_rules! registry {
    ($($(#[$doc:meta])* $name:ident($ty:ty),)*) => {
        /// The contact law of a run: one of the registered laws.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Law {
            $($(#[$doc])* $name($ty),)*
        }

        impl Law {
            /// Hands `run` the law's compiled kernel.
            #[inline(always)]
            pub fn with_kernel<R>(&self, run: impl RunLaw<R>) -> R {
                match self {
                    $(Law::$name(law) => law.with_kernel(run),)*
                }
            }

            /// Whether grains rotate.
            pub fn rotation(&self) -> bool {
                match self {
                    $(Law::$name(law) => law.rotation(),)*
                }
            }

            /// The spring–dashpot coefficients the time step was
            /// estimated from.
            pub fn estimate(&self) -> &ContactLaw {
                match self {
                    $(Law::$name(law) => law.estimate(),)*
                }
            }

            /// Refuses a run the law cannot serve (grains up to
            /// `max_radius`, Verlet skin `skin`).
            pub fn check(&self, max_radius: f64, skin: f64) -> Result<()> {
                match self {
                    $(Law::$name(law) => law.check(max_radius, skin),)*
                }
            }

            /// The rolling resistance.
            pub fn rolling(&self) -> RollingModel {
                match self {
                    $(Law::$name(law) => law.rolling(),)*
                }
            }

            /// The cohesion.
            pub fn cohesion(&self) -> CohesionModel {
                match self {
                    $(Law::$name(law) => law.cohesion(),)*
                }
            }

            /// Whether contacts keep a second history in the rolling slots.
            pub fn keeps_second_history(&self) -> bool {
                match self {
                    $(Law::$name(law) => law.keeps_second_history(),)*
                }
            }
        }
    };
}

registry! {
    /// The spring–dashpot law of coefficients (the papers' law of Gallas,
    /// Herrmann & Sokolowski 1992, and LAMMPS's hooke shapes), run by its
    /// Hooke-with-history kernel when the coefficients have that shape.
    SpringDashpot(ContactLaw),
    /// A law of materials: Hertz–Mindlin with its rolling and cohesion
    /// (DMT, JKR) parts, or LAMMPS's `pair granular` preset.
    Materials(MaterialLaw),
}

impl Law {
    /// The material law, when the run has one.
    pub fn materials(&self) -> Option<&HertzMindlin> {
        match self {
            Law::Materials(m) => Some(&m.hertz),
            _ => None,
        }
    }

    /// The spring–dashpot coefficients, when the run has that law.
    pub fn spring_dashpot(&self) -> Option<&ContactLaw> {
        match self {
            Law::SpringDashpot(law) => Some(law),
            _ => None,
        }
    }

    /// The Hooke-with-history kernel, when the run's law has that shape
    /// (what the GPU engine runs).
    pub fn hooke_history(&self) -> Option<HookeHistory> {
        self.spring_dashpot().and_then(HookeHistory::of)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hooke_history::lammps_law;
    use crate::contact::material::Material;
    use crate::contact::ContactModel;

    /// Which kernel type runs, as its name.
    struct Name;
    impl RunLaw<&'static str> for Name {
        fn run<L: ContactModel>(self, _: &L) -> &'static str {
            std::any::type_name::<L>()
        }
    }

    /// The Hooke shape gets its own kernel, any other spring–dashpot law
    /// the general one, a material law its compiled Hertz–Mindlin.
    #[test]
    fn each_law_gets_its_kernel() {
        let hooke = Law::SpringDashpot(lammps_law(0.0));
        assert!(hooke.with_kernel(Name).ends_with("HookeHistory"));
        let mut hertz = lammps_law(0.0);
        hertz.beta = 1.5;
        let general = Law::SpringDashpot(hertz.clone());
        assert!(general.with_kernel(Name).ends_with("ContactLaw"));
        let mats = [Material::elastic("glass", 6e10, 0.2, 2500.0, 0.9, 0.3)];
        let law = HertzMindlin::new(&mats, &[], vec![0], vec![0], true);
        let m = Law::Materials(MaterialLaw {
            hertz: law,
            estimate: hertz,
        });
        assert!(m.with_kernel(Name).ends_with("HertzMindlin"));
        assert!(m.materials().is_some() && m.hooke_history().is_none());
    }
}
