//! DSMC against kinetic theory: collision rate, equilibrium, conservation,
//! Haff's law, the impact-parameter distribution, thread independence.

use grains::dsmc::collide::{collide_pair, GasDim};
use grains::dsmc::rng::Stream;
use grains::dsmc::store::cross_section;
use grains::dsmc::workload::PeriodicGas;
use grains::dsmc::{collision_frequency, haff_time, DenseGas, Dsmc};
use grains::{D2, D3};

/// Mean free path λ = 1/(√2 n σ_cross χ).
fn mean_free_path(dim: usize, n: f64, d: f64, chi: f64) -> f64 {
    1.0 / (std::f64::consts::SQRT_2 * n * cross_section(dim, d) * chi)
}

/// A gas of `count` particles of diameter 1 at packing fraction `nu`,
/// T/m = 1, cells of λ/2 but holding 20 particles at least (the local ν of
/// the Enskog factor needs a few particles per cell; the rate of a
/// homogeneous gas does not depend on the cell size), ω τ = `omega_dt`.
fn gas(dim: usize, count: usize, nu: f64, e: f64, dense: DenseGas, omega_dt: f64) -> PeriodicGas {
    let vp = if dim == 2 {
        std::f64::consts::PI / 4.0
    } else {
        std::f64::consts::PI / 6.0
    };
    let n = nu / vp;
    let length = (count as f64 / n).powf(1.0 / dim as f64);
    let chi = match dense {
        DenseGas::Enskog => grains::dsmc::dense::enskog_chi(dim, nu),
        _ => 1.0,
    };
    let omega = collision_frequency(dim, n, 1.0, chi, 1.0);
    PeriodicGas {
        count,
        length,
        diameter: 1.0,
        thermal_speed: 1.0,
        cell: (0.5 * mean_free_path(dim, n, 1.0, chi)).max((20.0 / n).powf(1.0 / dim as f64)),
        dt: omega_dt / omega,
        restitution: e,
        dense,
        seed: 2024,
    }
}

fn measured_rate<D: GasDim>(g: &PeriodicGas, steps: u64) -> (f64, f64) {
    let mut sim: Dsmc<D> = g.build();
    sim.run(20);
    let c0 = sim.totals.collisions;
    let t0 = sim.time;
    let mut temp = 0.0;
    for _ in 0..steps {
        sim.step();
        temp += sim.store.granular_temperature();
    }
    let temp = temp / steps as f64;
    let rate = 2.0 * (sim.totals.collisions - c0) as f64 / (g.count as f64 * (sim.time - t0));
    let n = g.count as f64 / g.length.powi(D::D as i32);
    let nu = n * sim.store.particle_volume();
    let theory = sim.kinetic_collision_frequency(n, nu, temp);
    (rate, theory)
}

#[test]
fn dsmc_collision_rate_matches_kinetic_theory() {
    for (dim, dense, nu) in [
        (2, DenseGas::None, 0.01),
        (3, DenseGas::None, 0.01),
        (2, DenseGas::Enskog, 0.05),
        (3, DenseGas::Enskog, 0.05),
    ] {
        let g = gas(dim, 20_000, nu, 1.0, dense, 0.2);
        let (rate, theory) = if dim == 2 {
            measured_rate::<D2>(&g, 150)
        } else {
            measured_rate::<D3>(&g, 150)
        };
        let err = rate / theory - 1.0;
        eprintln!("{dim}D {dense:?} nu={nu}: rate {rate:.6e}, theory {theory:.6e}, {err:+.4}");
        assert!(err.abs() < 0.02, "{dim}D {dense:?}: {err}");
    }
}

fn kurtosis_and_core<D: GasDim>(sim: &Dsmc<D>) -> (f64, f64) {
    let n = sim.store.len() as f64;
    let mut m2 = 0.0;
    let mut m4 = 0.0;
    for q in &sim.store.p {
        for a in 0..D::D {
            let x = D::get(q.v, a);
            m2 += x * x;
            m4 += x * x * x * x;
        }
    }
    let m2 = m2 / (n * D::D as f64);
    let m4 = m4 / (n * D::D as f64);
    let s = m2.sqrt();
    let core = sim
        .store
        .p
        .iter()
        .map(|q| (0..D::D).filter(|&a| D::get(q.v, a).abs() < s).count())
        .sum::<usize>() as f64
        / (n * D::D as f64);
    (m4 / (m2 * m2), core)
}

#[test]
fn dsmc_maxwellian_stays_maxwellian_and_uniform_relaxes_to_it() {
    let g = gas(3, 30_000, 0.01, 1.0, DenseGas::None, 0.2);
    let mut sim: Dsmc<D3> = g.build();
    sim.run(100);
    let (k, core) = kurtosis_and_core(&sim);
    eprintln!("maxwellian after 10 collisions/particle: kurtosis {k}, core {core}");
    assert!((k - 3.0).abs() < 0.06, "{k}");
    assert!((core - 0.6827).abs() < 0.006, "{core}");
    // A uniform start (kurtosis 1.8) relaxes to Maxwell's.
    for q in &mut sim.store.p {
        let mut r = Stream::new(q.x.x.to_bits(), 0, 0);
        q.v = glam::DVec3::new(r.symmetric(), r.symmetric(), r.symmetric()) * 3f64.sqrt();
    }
    sim.run(100);
    let (k, core) = kurtosis_and_core(&sim);
    eprintln!("uniform start after 10 collisions/particle: kurtosis {k}, core {core}");
    assert!((k - 3.0).abs() < 0.06, "{k}");
}

#[test]
fn dsmc_conserves_momentum_and_energy_to_round_off() {
    fn check<D: GasDim>() {
        let g = gas(D::D, 5_000, 0.02, 1.0, DenseGas::FreeVolume, 0.3);
        let mut sim: Dsmc<D> = g.build();
        let p0 = sim.store.momentum();
        let e0 = sim.store.kinetic_energy();
        sim.run(200);
        let p1 = sim.store.momentum();
        let e1 = sim.store.kinetic_energy();
        let scale = (2.0 * e0 * sim.store.mass * g.count as f64).sqrt();
        assert!(sim.totals.collisions > 100_000);
        assert!(D::norm(p1 - p0) / scale < 1e-13, "{:?} {:?}", p0, p1);
        assert!(((e1 - e0) / e0).abs() < 1e-12, "{e0} {e1}");
        // Inelastic: momentum still conserved, energy lost.
        let g = PeriodicGas {
            restitution: 0.5,
            ..g
        };
        let mut sim: Dsmc<D> = g.build();
        let p0 = sim.store.momentum();
        sim.run(50);
        assert!(D::norm(sim.store.momentum() - p0) / scale < 1e-13);
        assert!(sim.store.kinetic_energy() < 0.9 * e0);
    }
    check::<D2>();
    check::<D3>();
}

/// Homogeneous cooling in a box of about four mean free paths (small enough
/// that the shear and clustering instabilities of the cooling state do not
/// develop), e = 0.9, until T has fallen by more than two decades.
fn haff<D: GasDim>() {
    let dim = D::D;
    let count = 20_000usize;
    let ratio = 4.0; // L / λ
                     // L/λ = √2 σ_cross n L with n = N / L^d and diameter 1.
    let n = if dim == 2 {
        (ratio / (2.0 * std::f64::consts::SQRT_2)).powi(2) / count as f64
    } else {
        (ratio / (std::f64::consts::SQRT_2 * std::f64::consts::PI * (count as f64).cbrt()))
            .powf(1.5)
    };
    let vp = if dim == 2 {
        std::f64::consts::PI / 4.0
    } else {
        std::f64::consts::PI / 6.0
    };
    let mut g = gas(dim, count, n * vp, 0.9, DenseGas::None, 0.15);
    g.seed = 7;
    let mut sim: Dsmc<D> = g.build();
    let t0 = sim.store.granular_temperature();
    let omega0 = collision_frequency(dim, n, 1.0, 1.0, t0);
    let tau0 = haff_time(dim, 0.9, omega0);
    let mut worst: f64 = 0.0;
    let mut k = 0;
    loop {
        sim.step();
        k += 1;
        let t = sim.store.granular_temperature();
        let want = t0 / (1.0 + sim.time / tau0).powi(2);
        if k % 50 == 0 {
            let err = t / want - 1.0;
            worst = worst.max(err.abs());
            assert!(
                err.abs() < 0.03,
                "{dim}D: T/T0 = {} at t/tau0 = {}: Haff {} ({err:+.4})",
                t / t0,
                sim.time / tau0,
                want / t0
            );
        }
        if t < 0.008 * t0 {
            break;
        }
        assert!(sim.time < 20.0 * tau0, "{dim}D: cooling too slow");
    }
    eprintln!(
        "{dim}D Haff: T fell to {:.4} T0 at t = {:.3} tau0 in {k} steps, worst deviation {worst:.4}",
        sim.store.granular_temperature() / t0,
        sim.time / tau0
    );
}

#[test]
fn dsmc_homogeneous_cooling_follows_haff_2d() {
    haff::<D2>();
}

#[test]
fn dsmc_homogeneous_cooling_follows_haff_3d() {
    haff::<D3>();
}

/// The impact parameter recovered from the collisions themselves: the
/// normal is along the momentum transfer, and b/2R is the component of n
/// perpendicular to the relative velocity.
#[test]
fn dsmc_impact_parameters_have_the_geometric_distribution() {
    let bins = 10;
    let samples = 200_000;
    let mut rng = Stream::new(1, 2, 3);
    // 2D: b uniform in [−2R, 2R].
    let mut h = vec![0usize; bins];
    for _ in 0..samples {
        let mut vi = glam::DVec2::new(rng.symmetric(), rng.symmetric());
        let mut vj = glam::DVec2::new(rng.symmetric(), rng.symmetric());
        let g = vi - vj;
        let dv = collide_pair::<D2>(&mut vi, &mut vj, g.length_squared(), 1.0, &mut rng);
        let n = dv.normalize();
        let u = g.normalize();
        let s = u.x * n.y - u.y * n.x; // signed sin: b / 2R
        let s = if u.dot(n) < 0.0 { -s } else { s };
        h[(((s + 1.0) / 2.0 * bins as f64) as usize).min(bins - 1)] += 1;
    }
    let want = samples as f64 / bins as f64;
    for (k, &c) in h.iter().enumerate() {
        assert!(
            (c as f64 / want - 1.0).abs() < 0.03,
            "2D bin {k}: {c} vs {want}"
        );
    }
    // 3D: b uniform in the disk of radius 2R, so (b/2R)² is uniform in [0, 1].
    let mut h = vec![0usize; bins];
    for _ in 0..samples {
        let mut vi = glam::DVec3::new(rng.symmetric(), rng.symmetric(), rng.symmetric());
        let mut vj = glam::DVec3::new(rng.symmetric(), rng.symmetric(), rng.symmetric());
        let g = vi - vj;
        let dv = collide_pair::<D3>(&mut vi, &mut vj, g.length_squared(), 1.0, &mut rng);
        let c = dv.normalize().dot(g.normalize());
        let s2 = (1.0 - c * c).max(0.0);
        h[((s2 * bins as f64) as usize).min(bins - 1)] += 1;
    }
    for (k, &c) in h.iter().enumerate() {
        assert!(
            (c as f64 / want - 1.0).abs() < 0.03,
            "3D bin {k}: {c} vs {want}"
        );
    }
}

#[test]
fn dsmc_result_does_not_depend_on_thread_count() {
    fn state<D: GasDim>(threads: usize) -> Vec<u64> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let g = gas(D::D, 40_000, 0.05, 0.8, DenseGas::FreeVolume, 0.3);
            let mut sim: Dsmc<D> = g.build();
            sim.run(40);
            let mut bits = vec![sim.totals.collisions];
            for q in &sim.store.p {
                for a in 0..D::D {
                    bits.push(D::get(q.x, a).to_bits());
                    bits.push(D::get(q.v, a).to_bits());
                }
            }
            bits
        })
    }
    for threads in [2, 3] {
        assert!(
            state::<D2>(1) == state::<D2>(threads),
            "2D, {threads} threads"
        );
        assert!(
            state::<D3>(1) == state::<D3>(threads),
            "3D, {threads} threads"
        );
    }
}
