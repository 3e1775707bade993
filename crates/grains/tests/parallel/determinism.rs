//! Same inputs → bitwise the same state.

use crate::common;

use common::*;
use glam::DVec2;
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::MassScaling;
use grains::md::{Md, MdSettings};
use grains::{Particles, D2};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn run(seed: u64) -> Vec<u64> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut p = Particles::<D2>::new();
    for k in 0..200u64 {
        let x = (k % 20) as f64 * 1.3 + 0.65;
        let y = (k / 20) as f64 * 1.3 + 0.7;
        let mut g = grain::<D2>(k, DVec2::new(x, y), rng.gen_range(0.75..1.25));
        g.vel = DVec2::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
        p.push_record(g);
    }
    let mut law = hooke(2.0e5, 50.0, MassScaling::Reduced);
    law.kt = 2.0 / 7.0 * 2.0e5;
    law.mu = 0.5;
    law.rotation = true;
    let mut s = MdSettings::<D2>::new(1e-4, law, 0.3);
    s.gravity = DVec2::new(0.0, -1.0);
    let domain = grains::Domain::new(DVec2::ZERO, DVec2::new(26.0, 40.0), [true, false, false]);
    let plate = Wall::new(
        "plate",
        Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
        Motion::Vibrate {
            direction: DVec2::Y,
            amplitude: 1.0,
            modulation: 0.0,
            wavelength: 26.0,
            frequency: 0.5,
            phase: 0.0,
        },
    )
    .unwrap();
    let mut md = Md::new(p, domain, vec![plate], s).unwrap();
    md.run(3000).unwrap();
    let mut bits = Vec::new();
    for i in 0..md.particles.len() {
        bits.extend([
            md.particles.pos[i].x.to_bits(),
            md.particles.vel[i].y.to_bits(),
            md.particles.omega[i].to_bits(),
        ]);
    }
    bits
}

#[test]
fn same_seed_gives_identical_bits() {
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}

#[test]
fn huge_time_step_is_reported_as_unstable() {
    let law = hooke(1.0e6, 0.0, MassScaling::Reduced);
    let a = grain::<D2>(0, DVec2::ZERO, 1.0);
    let mut b = grain::<D2>(1, DVec2::new(1.0, 0.0), 1.0);
    b.vel = DVec2::new(-50.0, 0.0);
    let mut p = Particles::new();
    p.push_record(a);
    p.push_record(b);
    let mut md = Md::new(p, open_box(100.0), vec![], MdSettings::new(6e-3, law, 0.1)).unwrap();
    let err = md.run(100).unwrap_err().to_string();
    assert!(err.contains("unstable") && err.contains("dt"), "{err}");
    let _ = Md::<D2>::contact_time;
}

/// The first grain whose state is not finite is named, on any thread count.
#[test]
fn non_finite_grain_is_named_on_any_thread_count() {
    let law = hooke(1.0e6, 0.0, MassScaling::Reduced);
    let grains: Vec<_> = (0..20_000u64)
        .map(|k| {
            grain::<D2>(
                k + 1,
                DVec2::new((k % 100) as f64 * 2.0, (k / 100) as f64 * 2.0),
                1.0,
            )
        })
        .collect();
    for threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut md = pool.install(|| {
            engine(
                grains.clone(),
                open_box(1e3),
                MdSettings::new(1e-4, law.clone(), 0.1),
            )
        });
        md.particles.vel[19_000].y = f64::NAN;
        md.particles.pos[12_345].x = f64::INFINITY;
        let err = pool
            .install(|| md.check_stability())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("grain 12346 has a non-finite"),
            "{threads}: {err}"
        );
    }
}

/// The vib2d benchmark (3700 grains, several force blocks, a vibrating wall,
/// friction and rotation) ends in the same bits on 1, 2 and 4 threads, with
/// either integrator.
#[test]
fn final_state_does_not_depend_on_thread_count() {
    final_state_on_1_2_4_threads("verlet");
}

#[test]
fn gear5_final_state_does_not_depend_on_thread_count() {
    final_state_on_1_2_4_threads("gear5");
}

fn final_state_on_1_2_4_threads(integrator: &str) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-vib2d.toml");
    let sets = [format!("run.integrator={integrator}")];
    let loaded = grains::scenario::load_file(&path, &sets).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (mut md, _) = grains::scenario::build_md::<D2>(&loaded).unwrap();
            md.run(300).unwrap();
            let p = &md.particles;
            let mut bits: Vec<(u64, [u64; 5])> = (0..p.len())
                .map(|i| {
                    let (x, v) = (p.pos[i], p.vel[i]);
                    (
                        p.id[i],
                        [
                            x.x.to_bits(),
                            x.y.to_bits(),
                            v.x.to_bits(),
                            v.y.to_bits(),
                            p.omega[i].to_bits(),
                        ],
                    )
                })
                .collect();
            bits.sort_unstable();
            bits
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(4));
}

/// Two identical engines on the vib2d benchmark with `integrator`.
fn two_vib2d_engines(integrator: &str) -> [Md<D2>; 2] {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-vib2d.toml");
    let sets = [format!("run.integrator={integrator}")];
    let loaded = grains::scenario::load_file(&path, &sets).unwrap();
    [(); 2].map(|_| grains::scenario::build_md::<D2>(&loaded).unwrap().0)
}

/// `Md::run` fuses each step's corrector with the next step's predictor;
/// the same steps taken one at a time (`Md::step`, two passes) must give the
/// same bits, across neighbour rebuilds, with either integrator.
#[test]
fn fused_steps_match_single_steps() {
    for integrator in ["verlet", "gear5"] {
        let [mut fused, mut single] = two_vib2d_engines(integrator);
        // A frozen grain must not move in the fused pass either.
        for md in [&mut fused, &mut single] {
            md.particles.frozen[7] = true;
        }
        fused.run(500).unwrap();
        grains::parallel::on_pool(|| (0..500).try_for_each(|_| single.step())).unwrap();
        assert!(fused.neighbor_builds() >= 3, "the stretch spans rebuilds");
        assert_eq!(fused.neighbor_builds(), single.neighbor_builds());
        assert_eq!((fused.step, fused.time), (single.step, single.time));
        let state = |md: &Md<D2>| {
            let p = &md.particles;
            let mut bits = Vec::new();
            for i in 0..p.len() {
                let (x, v, f) = (p.pos[i], p.vel[i], p.force[i]);
                bits.extend(
                    [x.x, x.y, v.x, v.y, f.x, f.y, p.omega[i], p.torque[i]].map(f64::to_bits),
                );
                for g in &p.gear {
                    bits.extend([g[i].x.to_bits(), g[i].y.to_bits()]);
                }
                for w in &p.gear_ang {
                    bits.push(w[i].to_bits());
                }
            }
            bits
        };
        assert_eq!(state(&fused), state(&single), "{integrator}");
    }
}

/// A grain whose state turns non-finite inside a fused stretch is named at
/// the same step as when the steps are taken one at a time.
#[test]
fn fused_steps_report_non_finite_grains_as_single_steps() {
    for integrator in ["verlet", "gear5"] {
        let [mut fused, mut single] = two_vib2d_engines(integrator);
        for md in [&mut fused, &mut single] {
            md.run(3).unwrap();
            md.particles.vel[2000].x = f64::NAN;
            md.particles.vel[3000].y = f64::NAN;
        }
        let fused_err = fused.run(50).unwrap_err().to_string();
        let single_err = (0..50)
            .find_map(|_| single.step().err())
            .unwrap()
            .to_string();
        let head = |e: &str| e.split(';').next().unwrap().to_string();
        assert_eq!(head(&fused_err), head(&single_err), "{integrator}");
        assert!(fused_err.contains("at step 10 "), "{fused_err}");
    }
}
