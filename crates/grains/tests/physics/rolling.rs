//! Rolling resistance through the whole engine, against closed forms: a
//! sphere of radius r rolling on a plane, Hertz–Mindlin with sliding
//! friction high enough that it never slips.
//!
//! - Constant torque M = μ_r r m g against a ball rolling at v₀: the
//!   kinetic energy (7/10) m v² falls at the rate M ω = μ_r m g v, so the
//!   ball stops after s = 7 v₀² / (10 μ_r g).
//! - epsd on a slope θ: at rest the friction carries m g sin θ, whose
//!   torque about the centre the rolling spring must hold; it can up to
//!   μ_r r m g cos θ, so the ball stays put when tan θ < μ_r and otherwise
//!   rolls with a = (5/7) g (sin θ − μ_r cos θ), the torque at its limit.

use super::chung_ooi::{close, material as elastic};
use super::jkr::forget_rolling_springs;
use glam::DVec3;
use grains::boundary::{Motion, Shape, Wall};
use grains::contact::hertz_mindlin::HertzMindlin;
use grains::contact::material::Material;
use grains::contact::rolling::RollingModel;
use grains::domain::Domain;
use grains::md::{Md, MdSettings};
use grains::{ParticleRecord, Particles, D3};
use std::f64::consts::PI;

const R: f64 = 0.01;
const G: f64 = 9.81;

fn material(name: &str, e: f64, rest: f64, mu: f64, mu_r: f64) -> Material {
    Material {
        rolling_friction: mu_r,
        ..elastic(name, e, 0.25, 2500.0, rest, mu)
    }
}

/// A ball (E = 10 MPa, R = 1 cm, restitution 0.5, μ = 0.8) resting on the
/// plane z = 0 at its equilibrium overlap under gravity `g_vec`, moving at
/// `v0` along x and rolling without slipping.
fn ball_on_plane(model: RollingModel, mu_r: f64, g_vec: DVec3, v0: f64) -> Md<D3> {
    let plane = Shape::Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    let floor = Wall::new("plane", plane, Motion::Fixed).unwrap();
    ball_on(
        floor,
        model,
        mu_r,
        g_vec,
        [DVec3::ZERO, DVec3::new(v0, 0.0, 0.0)],
    )
}

/// The ball of [`ball_on_plane`] on `floor` (a wall in the plane z = 0),
/// its centre above `at` (z ignored), moving at `vel` (horizontal) and
/// rolling without slipping.
pub fn ball_on(
    floor: Wall<D3>,
    model: RollingModel,
    mu_r: f64,
    g_vec: DVec3,
    [at, vel]: [DVec3; 2],
) -> Md<D3> {
    let mats = [
        material("ball", 1e7, 0.5, 0.8, mu_r),
        // The rigid plane: its restitution and friction exceed the ball's,
        // so the ball's decide (the mixing rules take the smaller).
        material("rigid", 1e30, 1.0, 1.0, 1.0),
    ];
    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
    let e_star = 1e7 / (1.0 - 0.25 * 0.25);
    // Hertz: m g cos θ = (4/3) E* √R ξ^{3/2}.
    let xi = (m * g_vec.z.abs() / (4.0 / 3.0 * e_star * R.sqrt())).powf(2.0 / 3.0);
    let mut p = Particles::<D3>::new();
    let at = DVec3::new(at.x, at.y, R - xi);
    let mut a = ParticleRecord::new(1, at, R, m, 0.4 * m * R * R);
    a.vel = vel;
    // v = ω × (R ẑ): the contact point at rest.
    a.omega = DVec3::Z.cross(vel) / R;
    a.kind = 0;
    p.push_record(a);
    let walls = vec![floor];
    let mut law = HertzMindlin::new(&mats, &[], vec![0], vec![1], true);
    law.rolling = model;
    // The contact's period is about 7 ms.
    let mut s = MdSettings::<D3>::with_materials(2e-5, law, 0.1 * R);
    s.gravity = g_vec;
    let domain = Domain::new(
        DVec3::new(-100.0 * R, -10.0 * R, -10.0 * R),
        DVec3::new(100.0 * R, 10.0 * R, 10.0 * R),
        [false; 3],
    );
    Md::new(p, domain, walls, s).unwrap()
}

/// The constant torque stops a ball rolling at 0.1 m/s after
/// 7 v₀² / (10 μ_r g), in the time v₀ / ((5/7) μ_r g), for two μ_r.
#[test]
fn constant_torque_stops_a_rolling_ball_over_the_closed_form_distance() {
    for mu_r in [0.05, 0.1] {
        let v0 = 0.1;
        let mut md = ball_on_plane(RollingModel::Constant, mu_r, DVec3::new(0.0, 0.0, -G), v0);
        let want = 0.7 * v0 * v0 / (mu_r * G);
        let stop_time = v0 / (5.0 / 7.0 * mu_r * G);
        let mut stopped = None;
        while md.time < 2.0 * stop_time {
            md.step().unwrap();
            if md.particles.vel[0].x <= 0.0 {
                stopped = Some((md.particles.pos[0].x, md.time));
                break;
            }
        }
        let (x, t) = stopped.expect("the ball stops");
        close(x, want, 0.01, &format!("distance at mu_r {mu_r}"));
        close(t, stop_time, 0.01, &format!("time at mu_r {mu_r}"));
        // Rolling, not sliding: the contact point stayed at rest.
        let slip = md.particles.vel[0].x - md.particles.omega[0].y * R;
        assert!(slip.abs() < 1e-3 * v0, "slip {slip}");
    }
}

/// Without rolling resistance the same ball rolls on at its speed: the
/// stop above is the model's doing.
#[test]
fn without_rolling_resistance_the_ball_rolls_on() {
    let mut md = ball_on_plane(RollingModel::None, 0.1, DVec3::new(0.0, 0.0, -G), 0.1);
    md.run(10_000).unwrap();
    close(md.particles.vel[0].x, 0.1, 1e-3, "speed after 0.2 s");
}

/// epsd on slopes at 0.95 and 1.05 of the critical tan θ = μ_r (Ai et
/// al. 2011: the torque that holds a ball on a slope is R m g sin θ, the
/// most the contact gives μ_r R m g cos θ): the first ball creeps to a
/// stop within the springs' give, the second rolls with (5/7) g (sin θ −
/// μ_r cos θ), 0.035 m/s² here, to 1e-6 (measured over 0.3 s after 0.2 s
/// of settling, once the spring slides at the cap: 2e-12). A cap off by
/// 5% either way fails one of the two.
#[test]
fn epsd_holds_a_ball_below_the_critical_slope_and_not_above() {
    let mu_r: f64 = 0.1;
    for (tan, rolls) in [(0.95 * mu_r, false), (1.05 * mu_r, true)] {
        let theta = tan.atan();
        let g_vec = DVec3::new(G * theta.sin(), 0.0, -G * theta.cos());
        let mut md = ball_on_plane(RollingModel::Epsd, mu_r, g_vec, 0.0);
        // 0.2 s to settle (or reach the limit), then 0.3 s measured.
        md.run(10_000).unwrap();
        let (x1, v1, t1) = (md.particles.pos[0].x, md.particles.vel[0].x, md.time);
        md.run(15_000).unwrap();
        let (x2, v2, t2) = (md.particles.pos[0].x, md.particles.vel[0].x, md.time);
        if rolls {
            let a = (v2 - v1) / (t2 - t1);
            let want = 5.0 / 7.0 * G * (theta.sin() - mu_r * theta.cos());
            close(a, want, 1e-6, "acceleration above the critical slope");
        } else {
            // The springs' give near the cap, with the overshoot of their
            // settling, is a few tenths of a millimetre (measured 0.025 R);
            // it neither moves on nor creeps.
            assert!(x2.abs() < 0.05 * R, "moved {x2:e} m");
            assert!((x2 - x1).abs() < 1e-4 * R, "crept {:e} m", x2 - x1);
            assert!(v2.abs() < 1e-5, "speed {v2:e}");
        }
    }
}

/// The rolling springs travel in a checkpoint: a ball held on a slope by
/// epsd, saved and restored into a fresh engine, continues bit for bit.
#[test]
fn rolling_springs_resume_bit_for_bit() {
    let theta = 0.05f64.atan();
    let g_vec = DVec3::new(G * theta.sin(), 0.0, -G * theta.cos());
    let fresh = || ball_on_plane(RollingModel::Epsd, 0.1, g_vec, 0.0);
    let mut md = fresh();
    md.run(2_000).unwrap();
    let bytes = grains::md::contract::encode(&md).unwrap();
    let mut resumed = fresh();
    grains::md::contract::restore(&mut resumed, &bytes).unwrap();
    md.run(2_000).unwrap();
    resumed.run(2_000).unwrap();
    let bits = |m: &Md<D3>| {
        let p = &m.particles;
        [p.pos[0], p.vel[0], p.omega[0]].map(|v| v.to_array().map(f64::to_bits))
    };
    assert_eq!(bits(&md), bits(&resumed));
    // Without the rolling spring the resumed ball would take a different
    // path: the test can tell.
    let mut forgetful = fresh();
    grains::md::contract::restore(&mut forgetful, &bytes).unwrap();
    forget_rolling_springs(&mut forgetful);
    forgetful.run(2_000).unwrap();
    assert_ne!(bits(&md), bits(&forgetful));
}

/// Two free grains of unlike materials and unequal radii (R = 1 cm,
/// E = 10 MPa, 2500 kg/m³, μ_r = 0.1; R = 6 mm, E = 50 MPa, 7800 kg/m³,
/// μ_r = 0.2: the pair's μ_r is the smaller, 0.1), held together by DMT
/// cohesion (Γ = 0.05 J/m²) at the overlap where Hertz's force equals the
/// pull, no sliding friction (μ = 0: only the normal force and the
/// rolling torques act), no gravity. The upper grain spins at 2 rad/s
/// about y, rolling on the lower.
fn rolling_pair(model: RollingModel) -> Md<D3> {
    let mats = [
        Material {
            rolling_friction: 0.1,
            surface_energy: 0.05,
            ..elastic("a", 1e7, 0.25, 2500.0, 0.5, 0.0)
        },
        Material {
            rolling_friction: 0.2,
            surface_energy: 0.05,
            ..elastic("b", 5e7, 0.3, 7800.0, 0.5, 0.0)
        },
    ];
    let (ra, rb) = (0.01, 0.006);
    let (ma, mb) = (
        2500.0 * 4.0 / 3.0 * PI * ra * ra * ra,
        7800.0 * 4.0 / 3.0 * PI * rb * rb * rb,
    );
    let xi = dmt_overlap();
    let mut p = Particles::<D3>::new();
    let mut a = ParticleRecord::new(1, DVec3::new(0.0, 0.0, ra - xi), ra, ma, 0.4 * ma * ra * ra);
    a.omega = DVec3::new(0.0, 2.0, 0.0);
    a.kind = 0;
    p.push_record(a);
    let mut b = ParticleRecord::new(2, DVec3::new(0.0, 0.0, -rb), rb, mb, 0.4 * mb * rb * rb);
    b.kind = 1;
    p.push_record(b);
    let mut law = HertzMindlin::new(&mats, &[], vec![0, 1], vec![], true)
        .with_cohesion(grains::contact::cohesion::CohesionModel::Dmt);
    law.rolling = model;
    let s = MdSettings::<D3>::with_materials(1e-5, law, 0.1 * rb);
    let domain = Domain::new(
        DVec3::splat(-10.0 * ra),
        DVec3::splat(10.0 * ra),
        [false; 3],
    );
    Md::new(p, domain, Vec::new(), s).unwrap()
}

/// R* = R₁R₂/(R₁+R₂) of the rolling pair.
const PAIR_R_STAR: f64 = 0.01 * 0.006 / 0.016;

/// The pair's DMT rest overlap, written from Derjaguin et al. (1975) and
/// Hertz: (4/3) E* √R* ξ^{3/2} = 2π Γ R*, Johnson's E*.
fn dmt_overlap() -> f64 {
    let e_star = 1.0 / ((1.0 - 0.25 * 0.25) / 1e7 + (1.0 - 0.3 * 0.3) / 5e7);
    let pull = 2.0 * PI * 0.05 * PAIR_R_STAR;
    (pull / (4.0 / 3.0 * e_star * PAIR_R_STAR.sqrt())).powf(2.0 / 3.0)
}

/// (ω_y of grain 1, ω_y of grain 2, their total spin Σ I ω_y).
fn spins(md: &Md<D3>) -> (f64, f64, f64) {
    let p = &md.particles;
    let k = |id: u64| p.id.iter().position(|&i| i == id).unwrap();
    let (a, b) = (k(1), k(2));
    let (wa, wb) = (p.omega[a].y, p.omega[b].y);
    let i = |k: usize| 0.4 * p.mass[k] * p.radius[k] * p.radius[k];
    (wa, wb, i(a) * wa + i(b) * wb)
}

/// Rolling resistance between two free grains, Ai et al.'s types A
/// (constant torque) and C (epsd, once its spring has reached the cap,
/// within 1.2 ms here): the torque on each grain is μ_r R* times the load
/// F_n + 2 F_po (the DMT contact's load, docs/contact-models.md: F_n = 0
/// at rest, so 4π Γ R*), the partner's its negative. The relative spin
/// then falls at μ_r R* · 4π Γ R* · (1/I₁ + 1/I₂), 10.7 rad/s² here,
/// measured between 20 and 120 ms: to 1e-6 (type A: a constant torque on
/// a contact at rest, exact but for the load's rounding; type C: the
/// spring slides at the cap, so the same; measured 6e-13 for both). The total spin Σ I ω is kept (1e-12 relative: only equal and
/// opposite torques and central forces act). An R* of equal grains
/// (R/2 of either), or a torque that leaves the partner out, fails.
#[test]
fn rolling_between_two_free_grains_decays_at_the_cap() {
    for model in [RollingModel::Constant, RollingModel::Epsd] {
        let mut md = rolling_pair(model);
        let (.., l0) = spins(&md);
        let p = &md.particles;
        let i_sum: f64 = (0..2)
            .map(|k| 1.0 / (0.4 * p.mass[k] * p.radius[k] * p.radius[k]))
            .sum();
        let load = 4.0 * PI * 0.05 * PAIR_R_STAR;
        let want = 0.1 * PAIR_R_STAR * load * i_sum;
        md.run(2_000).unwrap();
        let (wa1, wb1, l1) = spins(&md);
        let t1 = md.time;
        md.run(10_000).unwrap();
        let (wa2, wb2, l2) = spins(&md);
        let rate = ((wa1 - wb1) - (wa2 - wb2)) / (md.time - t1);
        close(
            rate,
            want,
            1e-6,
            &format!("{model:?}: relative spin's decay"),
        );
        for l in [l1, l2] {
            assert!(
                (l / l0 - 1.0).abs() < 1e-12,
                "{model:?}: spin {l} against {l0}"
            );
        }
        // Still rolling at the end (the decay measured is the cap's).
        assert!(wa2 - wb2 > 0.2, "{model:?}: stopped early");
    }
}
