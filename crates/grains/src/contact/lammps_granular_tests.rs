//! The `lammps-granular` preset through the whole engine: two spheres
//! colliding head-on (Verlet, dt = t_c/2000, no gravity), against Hertz's
//! closed forms and the restitution its damping must give.

use super::chung_ooi::{close, collide_under, hertz, rigid};
use super::hertz_mindlin::HertzMindlin;
use super::lammps_granular::{tsuji_alpha, GranularTable};
use super::material::Material;
use super::tsuji_damping::restitution_of;
use glam::DVec3;

/// The preset's law for `mats`: grains of material 0, the plane of 1.
fn preset(mats: &[Material]) -> HertzMindlin {
    HertzMindlin::new(mats, &[], vec![0, 0], vec![1], true)
        .with_lammps_granular(GranularTable::new(mats, &[], None))
}

/// e = 1 leaves α(1) = 3e-4 of LAMMPS's fit: the collision of two glass
/// spheres (R = 10 mm, each at 10 m/s) is Hertz's, overlap, peak force
/// and duration within 1% (the Hertz force is the same as Hertz–Mindlin's;
/// LAMMPS's E* for one material is E / (2 (1 − ν²))).
#[test]
fn near_elastic_collision_is_hertz() {
    let (e, nu, rho) = (4.8e10, 0.20, 2800.0);
    let mats = [Material::elastic("glass", e, nu, rho, 1.0, 0.0), rigid()];
    let r: f64 = 0.01;
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let (delta, force, t_c) = hertz(0.5 * m, 0.5 * r, e / (2.0 * (1.0 - nu * nu)), 20.0);
    let out = collide_under(
        preset(&mats),
        &mats,
        r,
        DVec3::new(0.0, 0.0, -10.0),
        true,
        t_c,
    );
    close(out.max_overlap, delta, 0.01, "overlap");
    close(out.peak_force, force, 0.01, "peak force");
    close(out.duration, t_c, 0.01, "duration");
    close(out.vel.z, 10.0, 2e-3, "rebound speed");
}

/// LAMMPS's damping is α √(m* (4/3) E* a) v_n: in the reduced collision of
/// `tsuji_damping` (whose damping is α' √(m* 2 E* a)) that is α' =
/// α √(2/3). Two cast-iron spheres (R = 2.5 mm, 3.9 m/s each) rebound
/// with `restitution_of(α(e) √(2/3))` within 0.5%, for e = 0.3 … 0.9.
/// That is not e itself: 0.440, 0.616, 0.778, 0.928 for e = 0.3, 0.5,
/// 0.7, 0.9 (LAMMPS's fit under this damping restores more than e asks;
/// Hertz–Mindlin's closed-form α gives e within 1e-5). The test pins the
/// rebound to within 1% of those numbers too.
#[test]
fn restitution_follows_lammps_damping() {
    let (e, nu, rho) = (1.0e11, 0.25, 7000.0);
    let r: f64 = 0.0025;
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let (_, _, t_c) = hertz(0.5 * m, 0.5 * r, e / (2.0 * (1.0 - nu * nu)), 7.8);
    for rest in [0.3, 0.5, 0.7, 0.9] {
        let mats = [Material::elastic("iron", e, nu, rho, rest, 0.0), rigid()];
        let out = collide_under(
            preset(&mats),
            &mats,
            r,
            DVec3::new(0.0, 0.0, -3.9),
            true,
            t_c,
        );
        let got = out.vel.z / 3.9;
        let want = restitution_of(tsuji_alpha(rest) * (2.0f64 / 3.0).sqrt());
        close(got, want, 0.005, &format!("e = {rest}"));
        let stated = [(0.3, 0.4396), (0.5, 0.6161), (0.7, 0.7777), (0.9, 0.9284)];
        let (_, e_out) = stated.iter().find(|(e, _)| *e == rest).unwrap();
        close(got, *e_out, 0.01, &format!("e = {rest}, stated"));
    }
}
