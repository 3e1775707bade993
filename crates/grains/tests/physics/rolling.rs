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
    let mut a = ParticleRecord::new(1, DVec3::new(0.0, 0.0, R - xi), R, m, 0.4 * m * R * R);
    a.vel = DVec3::new(v0, 0.0, 0.0);
    a.omega = DVec3::new(0.0, v0 / R, 0.0);
    a.kind = 0;
    p.push_record(a);
    let plane = Shape::Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    let walls = vec![Wall::new("plane", plane, Motion::Fixed).unwrap()];
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

/// epsd on slopes at half and twice the critical tan θ = μ_r: the first
/// ball creeps to a stop within the springs' give, the second rolls with
/// (5/7) g (sin θ − μ_r cos θ).
#[test]
fn epsd_holds_a_ball_below_the_critical_slope_and_not_above() {
    let mu_r: f64 = 0.1;
    for (tan, rolls) in [(0.5 * mu_r, false), (2.0 * mu_r, true)] {
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
            close(a, want, 0.01, "acceleration above the critical slope");
        } else {
            // The springs' give is a few hundredths of a millimetre; it
            // neither moves on nor creeps.
            assert!(x2.abs() < 0.01 * R, "moved {x2:e} m");
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
    let bytes = grains::checkpoint::engine::encode(&md).unwrap();
    let mut resumed = fresh();
    grains::checkpoint::engine::restore(&mut resumed, &bytes).unwrap();
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
    grains::checkpoint::engine::restore(&mut forgetful, &bytes).unwrap();
    forget_rolling_springs(&mut forgetful);
    forgetful.run(2_000).unwrap();
    assert_ne!(bits(&md), bits(&forgetful));
}
