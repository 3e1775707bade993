//! Seed 002 Figs. 2-3 at reduced length: convection from a modulated plate
//! amplitude and from side walls, through the shipped scenarios.

#[path = "seed_util.rs"]
mod seed_util;
use seed_util::{num, run_scenario};

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
    let (c, e) = modulated("base", &[]);
    assert!(c > 0.0 && e < 0.0, "center {c}, edge {e}");
}

// Measured (shipped length, seed 1): strength 0.215 m/s at gamma_s = 400,
// 0.042 m/s at gamma_s = 0 (still up in the centre, but 5x weaker). The
// seed finds the convection "quite insensitive to gamma_s, even if 0".
#[test]
#[ignore = "not reproduced: strength 0.215 m/s at gamma_s = 400 but 0.042 at 0; see comment"]
fn modulated_plate_convection_is_insensitive_to_shear_friction() {
    let (c, e) = modulated("gs400", &[]);
    let (c0, e0) = modulated("gs0", &["contact.gamma_t=0"]);
    let (s, s0) = (c - e, c0 - e0);
    assert!(s0 > 0.0, "gamma_s = 0: center {c0}, edge {e0}");
    assert!(
        s0 / s > 0.5 && s0 / s < 2.0,
        "strength {s} vs {s0} at gamma_s = 0"
    );
}

// Measured (shipped length, seed 1): strength 0.215 m/s at gamma_n = 200,
// 0.072 m/s at 2000: a factor 2.98, and at 10 + 5 cycles 0.127 vs 0.069
// (1.9). The convection weakens but is not "completely suppressed"; the
// other reading (2000 -> 20000 s^-1) is overdamped and unstable at t_c/50.
#[test]
#[ignore = "gamma_n x10 weakens the convection by ~3x (0.215 -> 0.072 m/s), not clearly more; see comment"]
fn ten_times_the_dissipation_suppresses_the_convection() {
    let (c, e) = modulated("g200", &[]);
    let (c10, e10) = modulated("g2000", &["contact.gamma_n=2000"]);
    let (s, s10) = (c - e, c10 - e10);
    assert!(
        s > 3.0 * s10,
        "strength {s} at gamma_n = 200, {s10} at 2000"
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

/// Not reproduced. A first run gave edge +0.0042 > centre +0.0001 m/s, but
/// the signal is below the noise: after a change to the floating-point order
/// of the force sums, seeds 1, 2, 3 gave (centre, edge) = (−0.0010, −0.0022),
/// (+0.0032, −0.0023), (+0.0027, −0.0011) m/s: grains sink at the walls
/// with γ_s = 0 too. See docs/seed-figures.md.
#[test]
#[ignore = "gamma_s = 0: edges sink in 3 of 3 seeds (edge - centre = -0.001 to -0.006 m/s); the seed's rise at the walls is not reproduced"]
fn side_walls_without_shear_friction_lift_the_grains() {
    let (c, e) = walls("gs0", "0");
    assert!(e > c, "gamma_s = 0: center {c}, edge {e}");
}

#[test]
fn side_walls_with_shear_friction_drag_the_grains_down() {
    let (c, e) = walls("gs400", "400");
    assert!(e < 0.0 && c > e, "gamma_s = 400: center {c}, edge {e}");
}
