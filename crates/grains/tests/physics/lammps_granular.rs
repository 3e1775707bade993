//! The `lammps-granular` preset through the whole engine: two spheres
//! colliding head-on (Verlet, dt = t_c/2000, no gravity), against Hertz's
//! closed forms and against LAMMPS itself.
//!
//! LAMMPS's `pair granular` with `hertz/material` and `damping tsuji`
//! (its documentation): F_n = k_n a δ + η_n v_n with k_n = (4/3) E*,
//! a = √(R* δ), η_n = α √(m* k_n a) and
//! α = 1.2728 − 4.2783 e + 11.087 e² − 22.348 e³ + 27.467 e⁴ − 18.022 e⁵ +
//! 4.8218 e⁶, where e is the restitution the user gives; for one
//! material E* = E / (2 (1 − ν²)).

use super::chung_ooi::{close, collide, e_star, head_on_rk4, hertz, material, near, rigid, Body};
use glam::DVec3;
use grains::contact::hertz_mindlin::HertzMindlin;
use grains::contact::lammps_granular::GranularTable;
use grains::contact::material::Material;

/// The preset's law for `mats`: grains of material 0, the plane of 1.
fn preset(mats: &[Material]) -> HertzMindlin {
    HertzMindlin::new(mats, &[], vec![0, 0], vec![1], true)
        .with_lammps_granular(GranularTable::new(mats, &[], None))
}

/// e = 1 leaves α(1) = 3e-4 of LAMMPS's fit: the collision of two glass
/// spheres (R = 10 mm, each at 10 m/s) is Hertz's, overlap, peak force
/// and duration within 1e-3 (α(1) = 3e-4 damps the collision by about
/// that much: the rebound is 0.99958 of the approach in LAMMPS, see
/// below; the Hertz force itself is the same as Hertz–Mindlin's).
#[test]
fn near_elastic_collision_is_hertz() {
    let (e, nu, rho) = (4.8e10, 0.20, 2800.0);
    let mats = [material("glass", e, nu, rho, 1.0, 0.0), rigid()];
    let r: f64 = 0.01;
    let m = super::chung_ooi::sphere_mass(rho, r);
    let (delta, force, t_c) = hertz(0.5 * m, 0.5 * r, e_star((e, nu), (e, nu)), 20.0);
    let a = Body::new(r, rho, 0, -10.0 * DVec3::Z);
    let b = Body::new(r, rho, 0, 10.0 * DVec3::Z);
    let out = collide(preset(&mats), a, Some(b), t_c);
    close(out.max_overlap, delta, 1e-3, "overlap");
    close(out.peak_force, force, 1e-3, "peak force");
    close(out.duration, t_c, 1e-3, "duration");
    close(out.vel[0].z, 10.0, 1e-3, "rebound speed");
}

/// The restitution two cast-iron spheres (R = 2.5 mm, 3.9 m/s each)
/// rebound with under the preset, for the restitutions 0.3, 0.5, 0.7, 0.9
/// and 1.0 asked of it, is LAMMPS's: the numbers below are LAMMPS's own
/// (29 Sep 2021 Update 2, Debian's `lammps`), from
/// `tests/data/lammps/tsuji-pair.in` run as that file says, the same
/// collision at the same dt = 6.5e-9 s (t_c/2000), its output in
/// `tsuji-pair.out`. They are not the e asked for (LAMMPS's fit restores
/// more than e under this damping). The engine agrees to 2e-5 (both are
/// velocity Verlet at t_c/2000, from slightly different starting gaps;
/// measured 6e-6). As a check on the reference, an independent
/// Runge–Kutta integration of LAMMPS's documented law gives the same
/// numbers within 2e-4 (LAMMPS's Verlet takes the damping at the
/// predicted velocity, first order in dt/t_c = 5e-4: measured 7.6e-5).
#[test]
fn restitution_is_lammps_own() {
    let (e, nu, rho) = (1.0e11, 0.25, 7000.0);
    let r: f64 = 0.0025;
    let m = super::chung_ooi::sphere_mass(rho, r);
    let (m_s, r_s, e_s) = (0.5 * m, 0.5 * r, e_star((e, nu), (e, nu)));
    let (_, _, t_c) = hertz(m_s, r_s, e_s, 7.8);
    let from_lammps = [
        (0.3f64, 0.4395207026),
        (0.5, 0.6160534909),
        (0.7, 0.7776520844),
        (0.9, 0.9283531959),
        (1.0, 0.9995785795),
    ];
    for (rest, lammps) in from_lammps {
        // LAMMPS's documented damping, integrated here.
        let alpha = 1.2728 - 4.2783 * rest + 11.087 * rest.powi(2) - 22.348 * rest.powi(3)
            + 27.467 * rest.powi(4)
            - 18.022 * rest.powi(5)
            + 4.8218 * rest.powi(6);
        let [_, _, rk4] = head_on_rk4(m_s, 7.8, t_c, |x, u| {
            let kn_a = 4.0 / 3.0 * e_s * (r_s * x).sqrt();
            kn_a * x + alpha * (m_s * kn_a).sqrt() * u
        });
        near(
            rk4,
            lammps,
            2e-4,
            &format!("RK4 of LAMMPS's law, e = {rest}"),
        );
        let mats = [material("iron", e, nu, rho, rest, 0.0), rigid()];
        let a = Body::new(r, rho, 0, -3.9 * DVec3::Z);
        let b = Body::new(r, rho, 0, 3.9 * DVec3::Z);
        let out = collide(preset(&mats), a, Some(b), t_c);
        near(out.vel[0].z / 3.9, lammps, 2e-5, &format!("e = {rest}"));
    }
}
