//! Seed 002 Figs. 2-3 as ensembles: convection from a modulated plate
//! amplitude and from side walls, through the shipped scenarios, over
//! ensembles of seeds of the random placement. Each claim is tested on the
//! ensemble mean with a stated significance (Welch's t on the seeds'
//! spread), not on one run; the spreads quoted are those of the 20-seed
//! sweeps in docs/seed-figures.md (`tools/seed002_ensembles.sh`).

use crate::common;

use common::runs::{num, read_csv, run_scenario_kept};
use grains::runner::{RunOptions, Silent};

/// One run of a shipped scenario with `sets`; `None` when it stops as
/// unstable (a grain squeezed beyond `run.max_overlap`), which the hot
/// gas of some settings does now and then.
fn try_run(name: &str, tag: &str, sets: &[String]) -> Option<serde_json::Value> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("scenarios").join(format!("{name}.toml"));
    let mut all: Vec<String> = ["frames", "picture", "movie"]
        .iter()
        .map(|k| format!("output.{k}=false"))
        .collect();
    all.extend(sets.iter().cloned());
    let loaded = grains::scenario::load_file(&path, &all).expect("scenario loads");
    // Tests run on threads of one process and two may run the same
    // setting: each run its own directory.
    static RUNS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let k = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let out = std::env::temp_dir().join(format!(
        "grains-test-{name}-{tag}-{}-{k}",
        std::process::id()
    ));
    let opts = RunOptions {
        out_dir: out.clone(),
        ..Default::default()
    };
    let s = match grains::runner::run(&loaded, &opts, &mut Silent) {
        Ok(s) => Some(s),
        Err(grains::error::Error::Unstable(_)) => None,
        Err(e) => panic!("{name} {sets:?}: {e}"),
    };
    let _ = std::fs::remove_dir_all(&out);
    s
}

/// (centre, edge) mean vertical velocities (m/s) of seeds 1..=n, every
/// one of which must run to the end: a run that stops as unstable fails
/// the ensemble, naming its seed, rather than shrinking it quietly.
fn ensemble(name: &str, tag: &str, extra: &[&str], n: u64) -> Vec<(f64, f64)> {
    ensemble_of(name, tag, extra, 1..=n)
}

/// [`ensemble`] over the given seeds.
fn ensemble_of(
    name: &str,
    tag: &str,
    extra: &[&str],
    seeds: std::ops::RangeInclusive<u64>,
) -> Vec<(f64, f64)> {
    let (runs, unstable) = ensemble_counted(name, tag, extra, seeds.clone());
    assert!(
        unstable.is_empty(),
        "{name} {extra:?}: seeds {unstable:?} of {seeds:?} stopped as unstable"
    );
    runs
}

/// [`ensemble_of`] that counts the runs stopped as unstable instead of
/// failing on them: (the runs that ended, the seeds that stopped); the two
/// add up to the number of seeds.
fn ensemble_counted(
    name: &str,
    tag: &str,
    extra: &[&str],
    seeds: std::ops::RangeInclusive<u64>,
) -> (Vec<(f64, f64)>, Vec<u64>) {
    let (mut runs, mut unstable) = (Vec::new(), Vec::new());
    let n = seeds.clone().count();
    for seed in seeds {
        let mut sets: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        sets.push(format!("seed={seed}"));
        match try_run(name, &format!("{tag}-{seed}"), &sets) {
            Some(s) => runs.push((
                num(&s, "convection_center_vz"),
                num(&s, "convection_edge_vz"),
            )),
            None => unstable.push(seed),
        }
    }
    assert_eq!(runs.len() + unstable.len(), n);
    (runs, unstable)
}

/// Mean and standard error of the mean.
fn mean_se(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// Welch's t of mean(a) − mean(b).
fn welch(a: &[f64], b: &[f64]) -> f64 {
    let ((ma, sa), (mb, sb)) = (mean_se(a), mean_se(b));
    (ma - mb) / (sa * sa + sb * sb).sqrt()
}

fn strengths(runs: &[(f64, f64)]) -> Vec<f64> {
    runs.iter().map(|(c, e)| c - e).collect()
}

/// Fig. 2: up in the centre, down at the edges. 20 of 20 seeds showed
/// it (docs/seed-figures.md); here seeds 1-12 must, all but one at most:
/// were neither sign preferred, 11 or 12 of 12 would come with
/// probability 13/4096 = 0.3 %.
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn modulated_plate_flows_up_in_the_centre() {
    let runs = ensemble("seed-convection-modulated", "base", &[], 12);
    let rolls = runs.iter().filter(|(c, e)| *c > 0.0 && *e < 0.0).count();
    assert!(rolls >= 11, "{rolls}/12 with rolls: {runs:?}");
    // Two rolls in the column profile of seed 1: every column of the
    // middle fifth rises, the two columns at each side (where the plate's
    // amplitude is smallest) sink.
    let (_, out) = run_scenario_kept("seed-convection-modulated", "profile", &[]);
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

/// Fig. 2, "γ ten times larger": the convection is weakened at least
/// twofold. Written before the runs it judges, from the 20-seed sweeps of
/// docs/seed-figures.md (seeds 1-20: 155 and 48 mm/s at γ = 200 and 2000
/// s⁻¹, spreads 31 and 22 mm/s; weakened about threefold, not "completely
/// suppressed"):
///
/// - the runs: seeds 21-44, none of them in that sweep, 24 per ensemble,
///   each of which must run to the end;
/// - the statistic: Welch's T = (m/2 − m₁₀) / √(se²/4 + se₁₀²) on the
///   ensemble means m, m₁₀ and their standard errors (expected 6.3 and
///   4.5 mm/s from those spreads); the claim holds when T > 2.5, which
///   rejects "weakened by less than half" (m₁₀ ≥ m/2) one-sided at 1 %
///   or less (Welch's degrees of freedom are at least 23, and the 99 %
///   point of Student's t with 23 is 2.50);
/// - expected T = 5.4; the chance that a correct engine fails by the
///   noise of the placements, T < 2.5, is 0.3 % (Monte Carlo of normal
///   ensembles with the sweep's means and spreads);
/// - the same test on m − m₁₀ (weakened at all) expects T = 14.
///
/// Measured afterwards: 154.9 ± 6.7 and 48.4 ± 4.8 mm/s, T = 5.0
/// (halved) and 12.9 (weaker).
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn ten_times_the_dissipation_weakens_the_convection() {
    const T_99: f64 = 2.5;
    let seeds = 21..=44;
    let s = strengths(&ensemble_of(
        "seed-convection-modulated",
        "g200",
        &[],
        seeds.clone(),
    ));
    let s10 = strengths(&ensemble_of(
        "seed-convection-modulated",
        "g2000",
        &["contact.gamma_n=2000"],
        seeds,
    ));
    let ((m, se), (m10, se10)) = (mean_se(&s), mean_se(&s10));
    let weaker = welch(&s, &s10);
    let halved = (0.5 * m - m10) / (0.25 * se * se + se10 * se10).sqrt();
    eprintln!("strength {m} +- {se} m/s at gamma_n = 200, {m10} +- {se10} at 2000: T = {weaker} (weaker), {halved} (halved)");
    assert!(
        weaker > T_99 && halved > T_99,
        "strength {m} +- {se} at gamma_n = 200, {m10} +- {se10} at 2000: \
         T = {weaker} (weaker), {halved} (at least halved), {T_99} asked"
    );
}

// Measured over seeds 1-20 (docs/seed-figures.md): strength 155 ± 7 mm/s at
// gamma_s = 400 but 24 ± 12 at gamma_s = 0, where 9 of 20 runs stop with a
// grain squeezed past max_overlap (a hot gas 60 d0 high); under the
// sqrt(g/d0) reading see the table in docs/seed-figures.md. The seed finds
// the convection "quite insensitive to gamma_s, even if 0".
#[test]
#[ignore = "not reproduced: 155 +- 7 mm/s at gamma_s = 400 against 24 +- 12 at gamma_s = 0 (20 seeds); see comment"]
fn modulated_plate_convection_is_insensitive_to_shear_friction() {
    let s = strengths(&ensemble("seed-convection-modulated", "gs400", &[], 8));
    // 9 of 20 runs stop at gamma_s = 0: counted, and the claim asks for
    // all 8 to run.
    let (runs0, unstable) = ensemble_counted(
        "seed-convection-modulated",
        "gs0",
        &["contact.gamma_t=0"],
        1..=8,
    );
    let s0 = strengths(&runs0);
    let ((m, _), (m0, _)) = (mean_se(&s), mean_se(&s0));
    assert!(
        unstable.is_empty() && m0 / m > 0.5 && m0 / m < 2.0,
        "strength {m} vs {m0} at gamma_s = 0 (seeds {unstable:?} of 1..=8 stopped)"
    );
}

/// Edge minus centre vertical velocity (m/s): positive when the grains
/// rise at the walls.
fn rise_at_walls(runs: &[(f64, f64)]) -> Vec<f64> {
    runs.iter().map(|(c, e)| e - c).collect()
}

/// Fig. 3 with and without shear friction, seeds 1-8 each (10 + 20 cycles
/// at 20 Hz, the shipped elastic side walls). 20 seeds gave an edge
/// velocity of −4.5 ± 0.5 mm/s at γ_s = 400 s⁻¹ and +7.6 ± 0.6 at γ_s = 0
/// (spreads 2.2 and 2.7 mm/s): the drag at the walls is told from the
/// frictionless runs at t ≈ 7.8 on seeds 1-8 (measured); the test asks
/// t > 4, and that the wall columns sink on the γ_s = 400 ensemble's mean
/// by more than three standard errors (measured 4.7).
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn side_walls_with_shear_friction_drag_the_grains_down() {
    let w = "seed-convection-walls";
    let drag = ensemble(w, "gs400", &["contact.gamma_t=400"], 8);
    let free = ensemble(w, "gs0", &["contact.gamma_t=0"], 8);
    let (e400, e0): (Vec<f64>, Vec<f64>) = (
        drag.iter().map(|r| r.1).collect(),
        free.iter().map(|r| r.1).collect(),
    );
    let t = welch(&e0, &e400);
    assert!(
        t > 4.0,
        "edge v_z {e400:?} (gamma_s 400) vs {e0:?} (0): t = {t}"
    );
    let (m, se) = mean_se(&e400);
    assert!(m < -3.0 * se, "edge v_z {m} +- {se} at gamma_s = 400");
    // The rolls turn: with friction the centre rises relative to the
    // walls, without it the walls rise relative to the centre.
    let t_rolls = welch(&rise_at_walls(&free), &rise_at_walls(&drag));
    assert!(t_rolls > 4.0, "edge - centre: t = {t_rolls}");
}

/// Fig. 3 without shear friction: the grains rise at the walls. With the
/// shipped elastic side walls 20 of 20 seeds did, edge − centre
/// = +11.5 ± 1.0 mm/s (spread 4.5); seeds 1-8 give +10.3 ± 1.6, 6.6
/// standard errors; the test asks four (one-sided, 3e-5). With damped
/// side walls (`contact.elastic_walls=[]`, the first pass) the rise is
/// +3.1 ± 1.1 mm/s over 20 seeds, 13 of 20 runs: too weak for a test.
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn side_walls_without_shear_friction_lift_the_grains() {
    let free = ensemble("seed-convection-walls", "gs0", &["contact.gamma_t=0"], 8);
    let (m, se) = mean_se(&rise_at_walls(&free));
    assert!(m > 4.0 * se, "edge - centre {m} +- {se} m/s at gamma_s = 0");
}
