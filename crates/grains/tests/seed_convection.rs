//! Seed 002 Figs. 2-3 at reduced length: convection from a modulated plate
//! amplitude and from side walls, through the shipped scenarios.

mod common;

use common::runs::{num, read_csv, run_scenario, run_scenario_kept};

// The shipped length (10 + 15 cycles, about 2.5 s in release): shorter runs
// are dominated by the bed's breathing and do not give a stable sign.
const SHORT: [&str; 0] = [];

fn modulated(tag: &str, extra: &[&str]) -> (f64, f64) {
    let mut sets = SHORT.to_vec();
    sets.extend_from_slice(extra);
    let s = run_scenario("seed-convection-modulated", tag, &sets);
    (
        num(&s, "convection_center_vz"),
        num(&s, "convection_edge_vz"),
    )
}

#[test]
fn modulated_plate_flows_up_in_the_centre() {
    let (s, out) = run_scenario_kept("seed-convection-modulated", "base", &[]);
    let (c, e) = (
        num(&s, "convection_center_vz"),
        num(&s, "convection_edge_vz"),
    );
    assert!(c > 0.0 && e < 0.0, "center {c}, edge {e}");
    // Two rolls: every column of the middle fifth rises, the two columns
    // at each side (where the plate's amplitude is smallest) sink.
    let rows = read_csv(&out.join("convection_profile.csv"));
    let _ = std::fs::remove_dir_all(&out);
    let vz: Vec<f64> = rows.iter().map(|r| r[1]).collect();
    let n = vz.len();
    assert!(vz[n / 2 - 2..n / 2 + 2].iter().all(|&v| v > 0.0), "{vz:?}");
    assert!(
        [vz[0], vz[1], vz[n - 2], vz[n - 1]]
            .iter()
            .all(|&v| v < 0.0),
        "{vz:?}"
    );
}

/// Convection strength (centre minus edge vertical velocity, m/s) averaged
/// over the seeds 1..=n of the random placement: single runs at the damped
/// setting scatter by ±0.04 m/s (seed 002 averages over up to 200 cycles).
fn mean_strength(tag: &str, extra: &[&str], n: u64) -> f64 {
    let total: f64 = (1..=n)
        .map(|seed| {
            let set = format!("seed={seed}");
            let mut sets = extra.to_vec();
            sets.push(&set);
            let (c, e) = modulated(&format!("{tag}-{seed}"), &sets);
            c - e
        })
        .sum();
    total / n as f64
}

// Measured (shipped length, curved plate): strength 0.19, 0.17, 0.19, 0.17
// m/s at gamma_s = 400 (seeds 1-4) but 0.005, -0.024, -0.040 at gamma_s = 0
// (seeds 1, 3, 5; seed 2 overlaps 90.6% and stops). Without shear friction
// the rolls vanish; the seed finds the convection "quite insensitive to
// gamma_s, even if 0".
#[test]
#[ignore = "not reproduced: strength 0.18 m/s at gamma_s = 400 but about 0 at gamma_s = 0; see comment"]
fn modulated_plate_convection_is_insensitive_to_shear_friction() {
    let s = mean_strength("gs400", &[], 3);
    let s0 = mean_strength("gs0", &["contact.gamma_t=0"], 3);
    assert!(
        s0 / s > 0.5 && s0 / s < 2.0,
        "strength {s} vs {s0} at gamma_s = 0"
    );
}

// Measured (shipped length, curved plate, seeds 1-4): strength 0.190,
// 0.172, 0.186, 0.170 m/s at gamma_n = 200 and 0.023, 0.021, 0.104, 0.029
// at 2000: 4.1x weaker on average, with one seed (3) keeping half a roll.
// "Completely suppressed" is read as: at least 3x weaker on the average.
// The other reading (2000 -> 20000 s^-1) is overdamped and unstable at t_c/50.
#[test]
fn ten_times_the_dissipation_suppresses_the_convection() {
    let s = mean_strength("g200", &[], 4);
    let s10 = mean_strength("g2000", &["contact.gamma_n=2000"], 4);
    assert!(
        s > 3.0 * s10,
        "mean strength {s} at gamma_n = 200, {s10} at 2000"
    );
}

// Shipped length (10 + 20 cycles at 20 Hz, about 12 s in release).
fn walls(tag: &str, gamma_t: &str) -> (f64, f64) {
    let set = format!("contact.gamma_t={gamma_t}");
    let s = run_scenario("seed-convection-walls", tag, &[&set]);
    (
        num(&s, "convection_center_vz"),
        num(&s, "convection_edge_vz"),
    )
}

/// Not reproduced: with γ_s = 0 there is no convection at all. Seeds 1, 2, 3
/// at 20 cycles gave (centre, edge) = (−0.0010, −0.0022), (+0.0032, −0.0023),
/// (+0.0027, −0.0011) m/s; seeds 1, 2 at 200 cycles (-0.0006, -0.0010),
/// (-0.0007, +0.0007): within ±1 mm/s of zero, no consistent sign. See
/// docs/seed-figures.md.
#[test]
#[ignore = "gamma_s = 0: no convection within +-1 mm/s over 200 cycles, no consistent sign between seeds; the seed's rise at the walls is not reproduced"]
fn side_walls_without_shear_friction_lift_the_grains() {
    let (c, e) = walls("gs0", "0");
    assert!(e > c, "gamma_s = 0: center {c}, edge {e}");
}

#[test]
fn side_walls_with_shear_friction_drag_the_grains_down() {
    let (s, out) = run_scenario_kept("seed-convection-walls", "gs400", &["contact.gamma_t=400"]);
    let (c, e) = (
        num(&s, "convection_center_vz"),
        num(&s, "convection_edge_vz"),
    );
    assert!(e < 0.0 && c > e, "gamma_s = 400: center {c}, edge {e}");
    // The column profile shows the same: the columns at the walls sink
    // fastest of all, and the flow turns upward away from them.
    let rows = read_csv(&out.join("convection_profile.csv"));
    let _ = std::fs::remove_dir_all(&out);
    assert_eq!(rows.len(), grains::measure::convection::COLUMNS);
    let vz: Vec<f64> = rows.iter().map(|r| r[1]).collect();
    let (left, right) = (vz[0], vz[vz.len() - 1]);
    let inner_max = vz[2..vz.len() - 2].iter().cloned().fold(f64::MIN, f64::max);
    assert!(
        left < 0.0 && right < 0.0,
        "wall columns {left}, {right}: {vz:?}"
    );
    assert!(inner_max > 0.0, "no rising column inside: {vz:?}");
    // Mass balance: over the whole bed the mean vertical velocity is
    // nearly zero against the wall columns' sinking.
    let mean = vz.iter().sum::<f64>() / vz.len() as f64;
    assert!(
        mean.abs() < 0.5 * left.abs().min(right.abs()),
        "mean {mean}: {vz:?}"
    );
}
