//! A rigid clump's weight: in free fall a body and a free sphere beside it
//! follow the closed form of constant acceleration g, and gravity, acting
//! at the centre of mass, leaves the body's angular momentum alone.
//!
//! Velocity Verlet integrates a constant force exactly: after n steps
//! v = v0 + g t and x = x0 + v0 t + ½ g t² (t = n dt) up to the rounding
//! of the sums, about n ε relative (2e-13 over the 1000 steps here), held
//! to 1e-10. The clump is two touching spheres of radii r and 2r, its
//! mass properties from `rigid::shape::clump`, so that its centre of mass
//! lies far from the sub-spheres' mean.

use glam::DVec3;
use grains::contact::law::ContactLaw;
use grains::contact::mass_scaling::MassScaling;
use grains::domain::Domain;
use grains::md::{Md, MdSettings};
use grains::rigid::BodySpec;
use grains::{MassModel, ParticleRecord, Particles, D3};
use std::f64::consts::PI;

const R: f64 = 1e-3;
const RHO: f64 = 2500.0;

/// Planted: sub-spheres weighed in the field pass with their own mass
/// share as well as the body at its centre (the body falls at 2 g, fails).
#[test]
fn a_falling_clump_and_sphere_follow_g_and_keep_their_spin() {
    let law = ContactLaw {
        kn: 1e3,
        beta: 1.0,
        gamma_n: 0.0,
        gamma_t: 0.0,
        kt: 0.0,
        mu: 0.0,
        scaling: MassScaling::Reduced,
        rotation: true,
    };
    let dt = 1e-5;
    let mut s = MdSettings::<D3>::new(dt, law, 0.2 * R);
    s.integrator = grains::integrate::Integrator::Verlet;
    let g = DVec3::new(1.5, -0.5, -9.81);
    s.gravity = g;
    let ms = RHO * 4.0 / 3.0 * PI * R.powi(3);
    let mut p = Particles::<D3>::new();
    let (x_sphere, v_sphere) = (DVec3::new(0.05, 0.05, 0.05), DVec3::new(0.1, 0.0, 0.2));
    let mut sphere = ParticleRecord::new(1, x_sphere, R, ms, 0.4 * ms * R * R);
    sphere.vel = v_sphere;
    p.push_record(sphere);
    let domain = Domain::new(DVec3::splat(-0.1), DVec3::splat(0.1), [false; 3]);
    let mut md = Md::new(p, domain, Vec::new(), s).unwrap();
    let balls = [(DVec3::ZERO, R), (DVec3::new(3.0 * R, 0.0, 0.0), 2.0 * R)];
    let (shape, _) = grains::rigid::shape::clump::<D3>("pair", &balls, RHO, MassModel::Sphere);
    let (x_body, v_body) = (DVec3::new(-0.02, 0.01, 0.0), DVec3::new(0.0, 0.3, 0.1));
    let spec = BodySpec {
        shape: 0,
        kind: 0,
        pos: x_body,
        orientation: [0.8, 0.0, 0.6, 0.0],
        vel: v_body,
        omega: DVec3::new(40.0, -25.0, 10.0),
    };
    md.add_bodies(vec![shape], vec![spec]).unwrap();
    let l0 = md.bodies().unwrap().bodies[0].ang_mom;
    let n = 1000;
    md.run(n).unwrap();
    let t = n as f64 * dt;
    let close = |a: DVec3, b: DVec3, what: &str| {
        let rel = (a - b).length() / b.length();
        assert!(rel < 1e-10, "{what}: {a} against {b} ({rel:e})");
    };
    let body = md.bodies().unwrap().bodies[0];
    close(body.vel, v_body + g * t, "body velocity");
    close(
        body.pos,
        x_body + v_body * t + 0.5 * g * t * t,
        "body position",
    );
    close(body.ang_mom, l0, "body angular momentum");
    let i = md.particles.id.iter().position(|&id| id == 1).unwrap();
    close(md.particles.vel[i], v_sphere + g * t, "sphere velocity");
    close(
        md.particles.pos[i],
        x_sphere + v_sphere * t + 0.5 * g * t * t,
        "sphere position",
    );
}
