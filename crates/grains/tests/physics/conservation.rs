//! Conservation laws of the contact model.

use crate::common;

use common::*;
use glam::{DVec2, DVec3};
use grains::contact::MassScaling;
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Dim, Domain, ParticleRecord, D2, D3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// A loose random gas of polydisperse grains in a fully periodic box, with
/// random velocities and spins, placed without overlaps.
fn gas<D: Dim>(n: usize, side: f64, seed: u64) -> (Vec<ParticleRecord<D>>, Domain<D>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut out: Vec<ParticleRecord<D>> = Vec::new();
    let mut hi = D::zero();
    for a in 0..D::D {
        D::set(&mut hi, a, side);
    }
    let domain = Domain::new(D::zero(), hi, [true; 3]);
    while out.len() < n {
        let d = rng.gen_range(0.6..1.4);
        let mut p = D::zero();
        for a in 0..D::D {
            D::set(&mut p, a, rng.gen_range(0.0..side));
        }
        let free = out
            .iter()
            .all(|q| D::norm(domain.minimum_image(q.pos - p)) > q.radius + 0.5 * d);
        if free {
            let mut g = grain::<D>(out.len() as u64, p, d);
            for a in 0..D::D {
                D::set(&mut g.vel, a, rng.gen_range(-1.0..1.0));
            }
            out.push(g);
        }
    }
    (out, domain)
}

#[test]
fn momentum_is_conserved_to_round_off_with_reduced_scaling() {
    let mut law = hooke(1.0e4, 30.0, MassScaling::Reduced);
    law.kt = 2.0e3;
    law.gamma_t = 10.0;
    law.mu = 0.5;
    law.rotation = true;
    for integrator in [Integrator::Verlet, Integrator::Gear5] {
        let (g, dom) = gas::<D3>(150, 8.0, 1);
        let mut s = MdSettings::<D3>::new(2e-4, law.clone(), 0.2);
        s.integrator = integrator;
        let mut md = engine(g, dom, s);
        let p0 = md.particles.momentum();
        let ke0 = md.particles.kinetic_energy();
        md.run(4000).unwrap();
        let p1 = md.particles.momentum();
        // Scale of the momenta involved: Σ m|v|.
        let scale: f64 = (0..md.particles.len())
            .map(|i| md.particles.mass[i] * md.particles.vel[i].length())
            .sum();
        assert!(
            (p1 - p0).length() < 1e-12 * scale.max(1.0),
            "{integrator:?}: {p0} -> {p1}"
        );
        // Collisions happened and dissipated energy: the test is not vacuous.
        assert!(
            md.particles.kinetic_energy() < 0.95 * ke0,
            "{integrator:?}: no collisions?"
        );
    }
}

/// Kinetic energy lost and momentum change over `steps` steps.
fn run_gas(md: &mut Md<D2>, steps: u64) -> (f64, f64) {
    let (p0, ke0) = (md.particles.momentum(), md.particles.kinetic_energy());
    md.run(steps).unwrap();
    let lost = 1.0 - md.particles.kinetic_energy() / ke0;
    ((md.particles.momentum() - p0).length(), lost)
}

#[test]
fn seed_scaling_conserves_momentum_for_equal_masses_only() {
    // With every coefficient times m_i, unequal grains feel unequal forces:
    // documented, and checked here so the convention cannot change silently.
    let law = hooke(1.0e4, 30.0, MassScaling::Seed);
    let (g, dom) = gas::<D2>(100, 12.0, 2);
    let mut md = engine(
        g,
        dom.clone(),
        MdSettings::<D2>::new(1e-4, law.clone(), 0.2),
    );
    let (dp, lost) = run_gas(&mut md, 3000);
    assert!(lost > 0.05, "unequal: no collisions? lost {lost}");
    assert!(dp > 1e-6, "unequal masses kept momentum: {dp}");
    // The same gas with every grain given the mass of diameter 1 (sizes
    // kept): equal masses, equal and opposite forces, momentum kept to
    // round-off (Σ m|v| ≈ 30).
    let (mut g, _) = gas::<D2>(100, 12.0, 2);
    let m = grains::MassModel::Sphere.mass(1.0, 1.0);
    for r in &mut g {
        r.mass = m;
    }
    let mut md = engine(g, dom, MdSettings::<D2>::new(1e-4, law, 0.2));
    let (dp, lost) = run_gas(&mut md, 3000);
    assert!(lost > 0.05, "equal: no collisions? lost {lost}");
    assert!(dp < 1e-12, "equal masses: momentum changed by {dp}");
}

fn total_energy<D: Dim>(md: &Md<D>) -> f64 {
    // Kinetic plus elastic energy k ξ²/2 of every overlapping pair (β = 1).
    let p = &md.particles;
    let kn = md.settings.law.spring_dashpot().unwrap().kn;
    let mut e = p.kinetic_energy();
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            let d = D::norm(md.domain.minimum_image(p.pos[i] - p.pos[j]));
            let ov = p.radius[i] + p.radius[j] - d;
            if ov > 0.0 {
                e += 0.5 * kn * ov * ov;
            }
        }
    }
    e
}

#[test]
fn energy_is_conserved_without_dissipation() {
    let law = hooke(1.0e4, 0.0, MassScaling::Reduced);
    for integrator in [Integrator::Verlet, Integrator::Gear5] {
        let (g, dom) = gas::<D2>(120, 14.0, 3);
        let mut s = MdSettings::<D2>::new(1e-4, law.clone(), 0.2);
        s.integrator = integrator;
        let mut md = engine(g, dom, s);
        let e0 = total_energy(&md);
        // Start velocities by grain id (the engine sorts its grains).
        let mut v0 = vec![DVec2::ZERO; md.particles.len()];
        for (i, &id) in md.particles.id.iter().enumerate() {
            v0[id as usize] = md.particles.vel[i];
        }
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            md.run(100).unwrap();
            worst = worst.max(((total_energy(&md) - e0) / e0).abs());
        }
        // Collisions happened: in a periodic box without walls or gravity
        // only contacts change velocities; most grains have met another.
        let changed = (0..md.particles.len())
            .filter(|&i| {
                let id = md.particles.id[i] as usize;
                (md.particles.vel[i] - v0[id]).length() > 1e-3
            })
            .count();
        assert!(
            changed > md.particles.len() / 2,
            "{integrator:?}: only {changed} grains collided"
        );
        // Contact time ≈ π√(m/2k) ≈ 1.4e-2 s = 140 steps: both schemes keep
        // the energy within 1e-3 (Verlet's error oscillates with each
        // collision and does not drift; Gear's is smaller still).
        assert!(
            worst < 1e-3,
            "{integrator:?}: relative energy error {worst:.2e}"
        );
    }
}

#[test]
fn grain_on_a_plane_settles_where_spring_balances_weight() {
    use grains::boundary::{Motion, Shape, Wall};
    for scaling in [MassScaling::Seed, MassScaling::Reduced] {
        let kn = 1.0e5;
        let law = hooke(kn, 200.0, scaling);
        let g = grain::<D3>(0, DVec3::new(0.0, 0.0, 0.5), 1.0);
        let m = g.mass;
        let mut s = MdSettings::<D3>::new(2e-4, law, 0.1);
        s.gravity = DVec3::new(0.0, 0.0, -9.81);
        let mut p = grains::Particles::new();
        p.push_record(g);
        let floor = Wall::new(
            "floor",
            Shape::Plane {
                point: DVec3::ZERO,
                normal: DVec3::Z,
            },
            Motion::Fixed,
        )
        .unwrap();
        let mut md = Md::new(p, open_box(5.0), vec![floor], s).unwrap();
        md.run(20_000).unwrap();
        let overlap = 0.5 - md.particles.pos[0].z;
        let expected = match scaling {
            MassScaling::Seed => 9.81 / kn,
            MassScaling::Reduced => m * 9.81 / kn,
        };
        assert!(
            ((overlap - expected) / expected).abs() < 1e-6,
            "{scaling:?}: {overlap} vs {expected}"
        );
    }
}

#[test]
fn two_dimensional_gas_keeps_momentum_too() {
    let mut law = hooke(1.0e4, 30.0, MassScaling::Reduced);
    law.kt = 2.0e3;
    law.mu = 0.3;
    law.rotation = true;
    let (g, dom) = gas::<D2>(150, 15.0, 4);
    let mut md = engine(g, dom, MdSettings::<D2>::new(1e-4, law, 0.2));
    let (dp, lost) = run_gas(&mut md, 3000);
    assert!(dp < 1e-11, "momentum changed by {dp}");
    assert!(lost > 0.05, "no collisions? lost {lost}");
    let _ = DVec2::ZERO;
}
