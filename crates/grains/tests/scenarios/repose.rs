//! Angle of repose in 2D (seed 000 §3, Lee & Herrmann 1993), reduced to fit
//! CI: 470 disks settle in a box 30 d0 wide, the right wall goes, the slope of
//! what stays is fitted. One avalanche is chaotic (the last bits of the force sums change
//! θ_r by several degrees), so every figure is a mean over three seeds and the
//! assertions keep margins far wider than that spread.

use crate::common;

use common::runs::run_scenario;
use glam::DVec2;
use grains::contact::{ContactLaw, MassScaling};
use grains::integrate::Integrator;
use grains::md::MdSettings;
use grains::D2;
use serde_json::Value;

const SEEDS: [u64; 3] = [3, 4, 5];

fn run_repose(mu: f64, seed: u64, extra: &[&str]) -> Value {
    let (mu_set, seed_set) = (format!("contact.mu={mu}"), format!("seed={seed}"));
    let mut sets = vec![mu_set.as_str(), seed_set.as_str(), "output.picture=false"];
    sets.extend_from_slice(extra);
    let tag = format!("{mu}-{seed}-{}", extra.join("_").replace(['=', '.'], ""));
    let s = run_scenario("repose-2d", &tag, &sets);
    assert_eq!(s["settled"], 1, "the pile must settle before the wall goes");
    s
}

/// θ_r of one run. Without a fit (fewer than three columns below the fill
/// height) the pile either flowed away entirely, which is flat, or stood as a
/// block, which the caller must not average as an angle.
fn angle(s: &Value) -> f64 {
    match s["repose_angle_deg"].as_f64() {
        Some(a) => a,
        None => {
            // Flat means all but a few flowed away (under a tenth stays).
            let left = s["remaining_grains"].as_u64().unwrap();
            let n = s["particles"].as_u64().unwrap();
            assert!(
                10 * left < n,
                "no slope fitted but {left} grains stayed: {s}"
            );
            0.0
        }
    }
}

fn mean_angle(mu: f64, extra: &[&str]) -> (f64, Vec<f64>) {
    let a: Vec<f64> = SEEDS
        .iter()
        .map(|&seed| angle(&run_repose(mu, seed, extra)))
        .collect();
    (a.iter().sum::<f64>() / a.len() as f64, a)
}

/// Rotation off, the seed's set-up. Measured (seeds 3–7, docs/validation.md):
/// μ = 0 flat (0.0–0.5°), μ = 0.1 9.0–13.3°, μ = 0.2 21.1–23.9°: the linear
/// rise the seed reports for μ < 0.2 (about 110° per unit μ).
#[test]
fn repose_angle_rises_with_mu_and_flattens_without_friction() {
    let (a0, r0) = mean_angle(0.0, &[]);
    let (a1, r1) = mean_angle(0.1, &[]);
    let (a2, r2) = mean_angle(0.2, &[]);
    eprintln!("theta_r rotation off: mu=0 {r0:.1?}, mu=0.1 {r1:.1?}, mu=0.2 {r2:.1?} deg");
    assert!(
        r0.iter().all(|&a| a < 5.0),
        "mu = 0 must flatten the pile: {r0:?}"
    );
    assert!(a1 > a0 + 5.0, "theta_r must rise with mu: {a0} -> {a1}");
    assert!(a2 > a1 + 5.0, "theta_r must rise with mu: {a1} -> {a2}");
    assert!(a2 < 45.0, "theta_r(mu = 0.2) = {a2} deg");
}

/// The target for the seed set-up: θ_r < 45° up to μ = 1 with
/// rotation off. Not met, and not reachable with this model: non-rotating
/// disks can only slide, a disk holds on one neighbour up to a contact
/// angle arctan μ (`non_rotating_disk_holds_on_one_neighbour_up_to_arctan_mu`),
/// and the settled packing is a solid that keeps a vertical face. Measured
/// (seeds 3–7, share of the grains that left the box in brackets):
/// μ = 0.3 26.6–37.4° (24–31 %); μ = 0.5 52.5°, 60.1°, 22.5° and two blocks
/// (9–16 %); μ = 0.7 and 1.0 no avalanche in any seed (0–6 % left). Other
/// boxes (16 × 18 d0 and 40 × 8 d0), w = 0.3 or 0.5, k_t/k_n = 0.1, 2/7 or
/// 1 changed the numbers, never the verdict (docs/validation.md). Kept as
/// the record of the target; run with `--ignored` to see it fail.
#[test]
#[ignore = "not met with rotation off: the pile stands above 45 deg or as a block for mu >= 0.5 (see comment)"]
fn seed_setup_stays_below_45_deg_up_to_mu_1() {
    for mu in [0.5, 1.0] {
        for seed in SEEDS {
            let s = run_repose(mu, seed, &[]);
            let a = s["repose_angle_deg"].as_f64();
            assert!(
                a.is_some_and(|a| a < 45.0),
                "mu = {mu}, seed {seed}: theta_r = {a:?} deg, flowed {}",
                s["repose_flowed_fraction"]
            );
        }
    }
}

/// Rotation on (beyond the seed): disks roll off the pile. Measured (seeds
/// 3–7): 0.2° at μ = 0, 8.4° at 0.2, 14.2° at 0.5, 17.7° at 1: linear below
/// μ ≈ 0.2 (about 40° per unit μ), then bending (about 7° per unit μ from
/// 0.5 to 1), below tan θ = μ everywhere but the first few hundredths.
#[test]
fn rolling_disks_rise_linearly_then_bend_and_stay_below_45_deg() {
    let rot = ["contact.rotation=true"];
    let (a0, _) = mean_angle(0.0, &rot);
    let (a2, r2) = mean_angle(0.2, &rot);
    let (a5, r5) = mean_angle(0.5, &rot);
    let (a10, r10) = mean_angle(1.0, &rot);
    eprintln!(
        "theta_r rotation on: mu=0 {a0:.1}, mu=0.2 {r2:.1?}, mu=0.5 {r5:.1?}, mu=1 {r10:.1?} deg"
    );
    assert!(a0 < 5.0, "mu = 0 must flatten the pile: {a0}");
    assert!(r10.iter().all(|&a| a < 45.0), "mu = 1: {r10:?}");
    assert!(a2 > a0 + 4.0, "theta_r must rise with mu: {a0} -> {a2}");
    assert!(a10 > a2 + 4.0, "theta_r must rise with mu: {a2} -> {a10}");
    // The bend: the slope at small μ is several times the one above 0.5.
    let (low, high) = ((a2 - a0) / 0.2, (a10 - a5) / 0.5);
    assert!(
        low > 2.0 * high,
        "no bend: {low:.1} deg per unit mu below 0.2, {high:.1} above 0.5"
    );
}

/// The angle of marginal stability: the pile the avalanche left is tilted
/// until it fails. θ_m must exceed θ_r by a few degrees (Lee & Herrmann
/// 1993), never by more than the tilt reached. One pile's gap depends on
/// rounding: at μ = 0.2, seeds 3–10 gave 0.5–3.9° (mean 1.9°), and 0.1–3.8°
/// (mean 1.4°) when only the order of the neighbour-list rebuilds changed.
/// So eight piles, each gap positive and their mean above 1°.
#[test]
fn marginal_angle_exceeds_repose_angle_by_a_few_degrees() {
    let mut gaps = Vec::new();
    for seed in 3..=10 {
        let s = run_repose(
            0.2,
            seed,
            &[
                "run.events.tilt_rate=10",
                "run.duration=4",
                "run.events.fail_energy=1e-3",
            ],
        );
        let m = s["marginal_angle_deg"]
            .as_f64()
            .unwrap_or_else(|| panic!("the tilted pile must fail: {s}"));
        let base = s["repose_before_tilt_deg"].as_f64().unwrap();
        gaps.push(m - base);
    }
    eprintln!("theta_m - theta_r at mu = 0.2: {gaps:.1?} deg");
    let mean = gaps.iter().sum::<f64>() / gaps.len() as f64;
    assert!(gaps.iter().all(|&g| g > 0.0), "theta_m > theta_r: {gaps:?}");
    assert!(
        (1.0..15.0).contains(&mean),
        "theta_m - theta_r = {mean} deg"
    );
}

/// The grain-scale reason non-rotating piles stand steep: a disk resting on a
/// single frozen disk, the contact normal tilted by α from the vertical.
/// Returns how far its centre moved in 0.4 s, in diameters.
fn disk_on_disk(alpha_deg: f64, mu: f64, rotation: bool) -> f64 {
    let (d, g, kn) = (1.0e-3, 9.81, 1.0e7);
    let law = ContactLaw {
        kt: 2.0 / 7.0 * kn,
        gamma_t: 200.0,
        mu,
        rotation,
        ..common::hooke(kn, 960.0, MassScaling::Seed)
    };
    let mut s = MdSettings::<D2>::new(2e-5, law, 0.3 * d);
    s.integrator = Integrator::Verlet;
    s.gravity = DVec2::new(0.0, -g);
    let a = alpha_deg.to_radians();
    // Start at the static overlap of the normal load (seed scaling: m kn ξ).
    let gap = d - g * a.cos() / kn;
    let start = DVec2::new(a.sin(), a.cos()) * gap;
    let mut base = common::grain::<D2>(0, DVec2::ZERO, d);
    base.frozen = true;
    let top = common::grain::<D2>(1, start, d);
    let mut md = common::engine(vec![base, top], common::open_box(0.05), s);
    md.run((0.4 / 2e-5) as u64).unwrap();
    let i = (0..2).find(|&i| md.particles.id[i] == 1).unwrap();
    (md.particles.pos[i] - start).length() / d
}

/// Without rotation a disk can leave its support only by sliding, which
/// Coulomb forbids while tan α < μ: at μ = 1 it holds on one neighbour up to
/// α = 45°, so a random packing with its supporting contacts mostly within
/// ~30° of the vertical cannot flow, whatever the box. A disk free to rotate
/// rolls off the same contact at any α > 0 (rolling needs no sliding). This
/// is why the seed set-up (rotation off) gives θ_r > 45° and standing blocks
/// for μ ≳ 0.5 (docs/validation.md), and rotation on stays far below.
#[test]
fn non_rotating_disk_holds_on_one_neighbour_up_to_arctan_mu() {
    let stuck = disk_on_disk(40.0, 1.0, false);
    let slid = disk_on_disk(50.0, 1.0, false);
    let rolled = disk_on_disk(10.0, 1.0, true);
    eprintln!("moved (d): rotation off 40 deg {stuck:.2e}, 50 deg {slid:.2e}; rotation on 10 deg {rolled:.2e}");
    assert!(stuck < 0.01, "tan 40° < μ = 1 must hold: moved {stuck} d");
    assert!(slid > 0.5, "tan 50° > μ = 1 must slide off: moved {slid} d");
    assert!(
        rolled > 0.5,
        "a rotating disk must roll off: moved {rolled} d"
    );
}

/// 3D, sand from a material (`repose-3d-sand`, Hertz–Mindlin, epsd rolling
/// friction), seed 3: spheres free to roll run out flat at μ_r = 0 and
/// stand at a slope with rolling friction. Measured (docs/validation.md,
/// seeds 3–5): μ_r = 0 gives 7.0–8.8°, μ_r = 0.2 gives about 33°; the
/// margins (below 12°, a rise of more than 15°, below 45°) are several
/// times the seed spread. Two runs of 440 000 steps of 700 spheres.
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn sand_repose_angle_3d_rises_with_rolling_friction() {
    let run = |mu_r: &str| {
        let set = format!("materials.0.rolling_friction={mu_r}");
        let s = run_scenario("repose-3d-sand", &format!("mur{mu_r}"), &[set.as_str()]);
        assert_eq!(s["settled"], 1, "the pile must settle before the wall goes");
        s["repose_angle_deg"]
            .as_f64()
            .unwrap_or_else(|| panic!("no slope fitted at mu_r = {mu_r}: {s}"))
    };
    let (flat, held) = (run("0"), run("0.2"));
    eprintln!("theta_r sand 3D: mu_r=0 {flat:.1}, mu_r=0.2 {held:.1} deg");
    assert!(flat < 12.0, "rolling spheres must run out: {flat} deg");
    assert!(
        held > flat + 15.0,
        "rolling friction must hold a slope: {flat} -> {held} deg"
    );
    assert!(held < 45.0, "theta_r(mu_r = 0.2) = {held} deg");
}
