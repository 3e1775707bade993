//! Clumps stand steeper than spheres: the angle of repose of tetrahedral
//! four-sphere clumps, of dimers and of single spheres of glass at the same
//! friction and no rolling friction, an ensemble over seeds.
//!
//! Spheres free to roll run out nearly flat without rolling friction
//! (`sand_repose_angle_3d_rises_with_rolling_friction`: 7–9°); a clump
//! cannot roll on its sub-spheres as a sphere does, since a turn about one
//! sub-sphere's centre lifts or presses the others, so its pile holds by
//! friction and interlocking.

use crate::common;

use common::runs::num;
use grains::runner::{RunOptions, Silent};

const SEEDS: [u64; 4] = [3, 4, 5, 6];

/// The pile of `repose-3d-clumps` cut down to a slab 4 d0 deep (periodic)
/// and filled with one kind of grain of about the same solid volume: 320
/// spheres, 160 dimers (2 spheres' volume each) or 88 tetrahedral clumps
/// (3.67 spheres' each); settled (at least 0.25 s), the right wall removed,
/// 0.75 s in all, the slope fitted over the first 12 d0 in columns of
/// 2 d0.
fn repose(shape: &str, seed: u64) -> f64 {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    let text = std::fs::read_to_string(root.join("repose-3d-clumps.toml")).unwrap();
    let mut tree: toml::Value = toml::from_str(&text).unwrap();
    let t = tree.as_table_mut().unwrap();
    t.insert("seed".into(), toml::Value::Integer(seed as i64));
    let depth = 0.004;
    t["domain"]["hi"].as_array_mut().unwrap()[1] = depth.into();
    let p = t["particles"].as_table_mut().unwrap();
    p["region"]["hi"].as_array_mut().unwrap()[1] = depth.into();
    p.remove("shapes");
    let count = match shape {
        "sphere" => {
            p.remove("orientation");
            320
        }
        "dimer" => 160,
        "tetra" => 88,
        _ => unreachable!(),
    };
    if shape != "sphere" {
        p.insert("shape".into(), shape.into());
    }
    p.insert("count".into(), toml::Value::Integer(count));
    t["run"]
        .as_table_mut()
        .unwrap()
        .insert("duration".into(), 0.75.into());
    let sets: Vec<String> = ["output.frames=false", "output.picture=false"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let loaded = grains::scenario::load_str(
        &toml::to_string(&tree).unwrap(),
        "repose-3d-clumps (slab)",
        root.clone(),
        &sets,
    )
    .expect("scenario loads");
    let out = std::env::temp_dir().join(format!(
        "grains-test-repose-{shape}-{seed}-{}",
        std::process::id()
    ));
    let opts = RunOptions {
        out_dir: out.clone(),
        steps: None,
        ..Default::default()
    };
    let s = grains::runner::run(&loaded, &opts, &mut Silent).expect("run");
    let _ = std::fs::remove_dir_all(&out);
    assert_eq!(
        s["settled"], 1,
        "{shape}, seed {seed}: settled before the wall went"
    );
    num(&s, "repose_angle_deg")
}

fn mean_sd(a: &[f64]) -> (f64, f64) {
    let n = a.len() as f64;
    let m = a.iter().sum::<f64>() / n;
    let var = a.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// Welch's t of the difference of two means (unequal variances).
fn welch_t(a: &[f64], b: &[f64]) -> f64 {
    let ((ma, sa), (mb, sb)) = (mean_sd(a), mean_sd(b));
    (ma - mb) / (sa * sa / a.len() as f64 + sb * sb / b.len() as f64).sqrt()
}

/// θ_r(dimer) and θ_r(tetra) > θ_r(sphere) at μ = 0.3, no rolling
/// friction, over four seeds each. Significance: every seed of each clump
/// above every seed of the spheres (the chance of that ordering when both
/// come from one distribution is 1/C(8, 4) = 1/70, p = 0.014 one-sided),
/// and Welch's t above 4.54 (one-sided 1 % at 3 degrees of freedom, the
/// fewest Welch's formula can give with 4 + 4 runs).
///
/// The issue expects tetrahedral clumps above dimers too: not borne out
/// here. Measured (docs/clumps.md): spheres 5.3 ± 1.2°, dimers 30.7 ±
/// 2.6°, tetrahedra 30.0 ± 4.0° (Welch t of tetrahedra over dimers −0.3):
/// the two clumps stand alike, so that order is printed, not asserted.
#[test]
#[cfg_attr(not(feature = "long-tests"), ignore = "long tier: .ci/long.sh")]
fn clumps_stand_steeper_than_spheres() {
    // The seeds of a shape run side by side (each run gives the same bits
    // on any number of threads).
    let angles: Vec<(&str, Vec<f64>)> = ["sphere", "dimer", "tetra"]
        .iter()
        .map(|&shape| {
            let a = std::thread::scope(|s| {
                let runs: Vec<_> = SEEDS
                    .iter()
                    .map(|&seed| s.spawn(move || repose(shape, seed)))
                    .collect();
                runs.into_iter().map(|r| r.join().unwrap()).collect()
            });
            (shape, a)
        })
        .collect();
    for (shape, a) in &angles {
        let (m, sd) = mean_sd(a);
        eprintln!("repose {shape}: {a:.1?} deg, mean {m:.1} ± {sd:.1}");
    }
    let spheres = &angles[0].1;
    let top = spheres.iter().copied().fold(f64::MIN, f64::max);
    for (shape, a) in &angles[1..] {
        let t = welch_t(a, spheres);
        eprintln!("{shape} over spheres: Welch t = {t:.1}");
        let low = a.iter().copied().fold(f64::MAX, f64::min);
        assert!(
            low > top,
            "every {shape} seed above every sphere seed: {a:?} against {spheres:?}"
        );
        assert!(t > 4.54, "{shape} over spheres: Welch t = {t}");
    }
    let t = welch_t(&angles[2].1, &angles[1].1);
    eprintln!("tetra over dimer: Welch t = {t:.1} (not asserted)");
}
