//! Servo walls through the whole engine: a lid pressing a settled bed of
//! 216 spheres in a box periodic in x and y holds its target pressure, gets
//! there without a large overshoot, and at rest the floor carries the lid's
//! load plus the grains' weight (Newton's third law on the whole bed: no
//! side walls, so nothing else carries it); the same bits on 1 and 2
//! threads and across a checkpoint taken mid-compression.
//!
//! Units are the grains' own: d ≈ 1, density 1, g = 1. Hooke contacts with
//! k_n = 4000: the target P = 4 puts about P d² / k_n = 1e-3 d of overlap on
//! the lid's contacts; the lid's load P A = 144 and the bed's weight
//! W ≈ 113 are of a size, so the static balance tests both.

use crate::common;

use common::*;
use glam::DVec3;
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::{ContactLaw, MassScaling};
use grains::engine::Engine;
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Domain, Particles, D3};
use rand::{Rng, SeedableRng};
use std::sync::OnceLock;

const SIDE: f64 = 6.0;
const TARGET: f64 = 4.0;
const KN: f64 = 4000.0;
const DT: f64 = 5e-4;
/// The gain (docs/servo-walls.md): under both bounds, the lid's contact
/// stiffness (g 36 k_n dt / A = 0.04 ≪ 1) and its dashpots (the lid
/// touches 7 grains: g 7 γ_n m / A = 0.4 < 1; at 0.05 the lid rings at ±
/// max_speed from step to step); its time constant on the bed's elastic
/// stiffness K ≈ 6 k_n (36 columns of 6 contacts), A / (K g) = 0.075, is
/// far shorter than the bed's creep as it compacts under the lid.
const GAIN: f64 = 0.02;

fn domain() -> Domain<D3> {
    Domain::new(
        DVec3::ZERO,
        DVec3::new(SIDE, SIDE, 20.0),
        [true, true, false],
    )
}

fn settings() -> MdSettings<D3> {
    // γ_n = 200: a damping ratio of about 0.3 at a contact; friction
    // μ = 0.5 on a tangential spring k_t = 2/7 k_n, so that the bed comes
    // to rest.
    let law = ContactLaw {
        kt: 2.0 / 7.0 * KN,
        gamma_t: 100.0,
        mu: 0.5,
        rotation: true,
        ..hooke(KN, 200.0, MassScaling::Reduced)
    };
    let mut s = MdSettings::new(DT, law, 0.2);
    s.integrator = Integrator::Verlet;
    s.gravity = DVec3::new(0.0, 0.0, -1.0);
    s
}

fn floor() -> Wall<D3> {
    let shape = Shape::Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    Wall::new("floor", shape, Motion::Fixed).unwrap()
}

/// 6 × 6 × 6 spheres of diameters in [0.9, 1.1] on a jittered grid,
/// settled on the floor; and the height of the bed's top.
fn settled() -> &'static (Particles<D3>, f64) {
    static BED: OnceLock<(Particles<D3>, f64)> = OnceLock::new();
    BED.get_or_init(|| {
        let mut rng = rand::rngs::StdRng::seed_from_u64(45);
        let mut p = Particles::new();
        for i in 0..216u64 {
            let (x, y, z) = ((i % 6) as f64, ((i / 6) % 6) as f64, (i / 36) as f64);
            let jitter = DVec3::new(rng.gen_range(-0.02..0.02), rng.gen_range(-0.02..0.02), 0.0);
            let pos = DVec3::new(x + 0.5, y + 0.5, 1.15 * z + 0.6) + jitter;
            p.push_record(grain::<D3>(i + 1, pos, rng.gen_range(0.9..1.1)));
        }
        let mut md = Md::new(p, domain(), vec![floor()], settings()).unwrap();
        md.run(20000).unwrap();
        let p = &md.particles;
        let fastest = p.vel.iter().map(|v| v.length()).fold(0.0, f64::max);
        // A few rattlers still roll; the bed itself is at rest.
        assert!(fastest < 0.05, "the bed has not settled: {fastest}");
        let top = (0..p.len())
            .map(|i| p.pos[i].z + p.radius[i])
            .fold(0.0, f64::max);
        (md.particles.clone(), top)
    })
}

/// The settled bed with the floor and a servo lid 0.02 above its top.
fn press(gain: f64) -> Md<D3> {
    let (p, top) = settled();
    let lid = Wall::new(
        "lid",
        Shape::Plane {
            point: DVec3::new(0.0, 0.0, top + 0.02),
            normal: -DVec3::Z,
        },
        Motion::servo(TARGET, gain, 0.05, SIDE * SIDE, 0.0),
    )
    .unwrap();
    Md::new(p.clone(), domain(), vec![floor(), lid], settings()).unwrap()
}

/// The loads on the floor and on the lid (upward force on the grains, each
/// as a pressure on the box's cross-section), from the contacts now.
fn loads(md: &Md<D3>) -> (f64, f64) {
    let c = md.wall_contact_list();
    let mut sums = [0.0; 2];
    for (&w, f) in c.wall.iter().zip(&c.force) {
        sums[w] += f.z;
    }
    (sums[0] / (SIDE * SIDE), -sums[1] / (SIDE * SIDE))
}

fn weight_pressure(p: &Particles<D3>) -> f64 {
    p.mass.iter().sum::<f64>() / (SIDE * SIDE)
}

/// Runs `md` for `steps`, sampling the lid's pressure (from the contacts,
/// on the true cross-section) every 10 steps.
fn sample(md: &mut Md<D3>, steps: u64) -> Vec<(f64, f64)> {
    (0..steps / 10)
        .map(|_| {
            md.run(10).unwrap();
            loads(md)
        })
        .collect()
}

/// The lid reaches P within 1 % in 16000 steps (the bed compacts under it
/// for about 6 time units), never goes above 1.02 P on the way (the
/// pressure approaches from below, a first-order response), and holds it:
/// the time average over the next 4000 steps (2.0) is within 1 %, and the
/// floor carries the lid's load plus the weight of the grains (Σ m g / A),
/// within 1 % of that sum: what is left of the bed's momentum change over
/// the window and of the servo's 1 %.
#[test]
fn a_servo_lid_holds_its_pressure_on_a_settled_bed() {
    let mut md = press(GAIN);
    let way = sample(&mut md, 16000);
    let peak = way.iter().map(|l| l.1).fold(0.0, f64::max);
    let reached = way
        .iter()
        .position(|l| (l.1 - TARGET).abs() < 0.01 * TARGET)
        .map(|k| (k + 1) as f64 * 10.0 * DT);
    let held = sample(&mut md, 4000);
    let n = held.len() as f64;
    let lid = held.iter().map(|l| l.1).sum::<f64>() / n;
    let floor = held.iter().map(|l| l.0).sum::<f64>() / n;
    let spread = held.iter().map(|l| (l.1 - lid).powi(2)).sum::<f64>().sqrt() / n.sqrt();
    let weight = weight_pressure(&md.particles);
    let servo = md.walls[1].motion.servo_state().unwrap();
    eprintln!(
        "servo: reached 1% at t = {reached:?}, peak {peak:.4} ({:.2}%), held {lid:.5} \
         (rms {spread:.2e}), floor {floor:.5} = lid + weight {:.5}, offset {:.4e}, \
         measured by the servo {:.5}",
        100.0 * (peak / TARGET - 1.0),
        lid + weight,
        servo.offset,
        servo.pressure
    );
    assert!(reached.is_some(), "never within 1 % of P in 16000 steps");
    assert!(
        peak < 1.02 * TARGET,
        "overshoot: peak {peak} for P = {TARGET}"
    );
    assert!(
        (lid - TARGET).abs() < 0.01 * TARGET,
        "held {lid} for P = {TARGET}"
    );
    let expected = TARGET + weight;
    assert!(
        (floor - expected).abs() < 0.01 * expected,
        "floor {floor}, lid + weight {expected}"
    );
}

/// The bits of the positions and velocities by id, and the lid's state.
fn bits(md: &Md<D3>) -> Vec<u64> {
    let p = &md.particles;
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by_key(|&i| p.id[i]);
    let s = md.walls[1].motion.servo_state().unwrap();
    order
        .iter()
        .flat_map(|&i| {
            let (x, v) = (p.pos[i], p.vel[i]);
            [x.x, x.y, x.z, v.x, v.y, v.z].map(f64::to_bits)
        })
        .chain(s.to_array().map(f64::to_bits))
        .collect()
}

/// The load is a fixed-order sum, and the lid's offset, speed and pressure
/// travel in the checkpoint: the same bits on 1 and 2 threads and across a
/// checkpoint taken while the lid is still pressing.
#[test]
fn a_servo_run_gives_the_same_bits_on_threads_and_across_a_checkpoint() {
    let on = |threads: usize, f: &mut (dyn FnMut() + Send)| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    };
    let mut one = press(GAIN);
    on(1, &mut || one.advance(1600).unwrap());
    let mut two = press(GAIN);
    on(2, &mut || two.advance(1600).unwrap());
    assert_eq!(bits(&one), bits(&two), "1 vs 2 threads");

    let mut first = press(GAIN);
    on(2, &mut || first.advance(800).unwrap());
    let s = first.walls[1].motion.servo_state().unwrap();
    assert!(
        s.offset > 0.0 && s.speed != 0.0,
        "not pressing: {:?}",
        s.to_array()
    );
    let saved = first.export().unwrap();
    let mut resumed = press(GAIN);
    resumed.import(&saved, "test").unwrap();
    assert_eq!(resumed.export().unwrap(), saved);
    on(2, &mut || resumed.advance(800).unwrap());
    assert_eq!(bits(&resumed), bits(&one), "resumed vs uninterrupted");
}
