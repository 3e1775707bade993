//! Checkpoint and resume of the MD engine: a run of 2N steps and a run of N
//! steps, saved, restored into a fresh engine and run N more, end bit for
//! bit equal, in 2D and 3D, with Gear-5 and velocity Verlet, with tangential
//! springs stretched at the stop. The comparison is on the encoded state
//! (every particle array, Gear history, pair list, image codes, skin
//! reference positions, springs, counters). And the scenario runner, which
//! advances in fused stretches between the steps its hooks act at, against
//! the same engine taken one `Md::step` at a time: frames, a measurement
//! file and checkpoints bit for bit.

use grains::codec::Enc;
use grains::dim::{Dim, D2, D3};
use grains::io::vtp_string;
use grains::md::codec::encode_md;
use grains::md::contract as engine;
use grains::md::Md;
use grains::measure::Convection;
use grains::runner::checkpointing::{self, Every};
use grains::runner::{run, RunOptions, Silent};
use grains::scenario::flow::FlowRun;
use grains::scenario::{build_md, load_str, Loaded};
use std::path::PathBuf;

/// Random grains above a vibrating floor, with frictional springs.
fn scenario(dim: &str, integrator: &str) -> String {
    let (g, lo, hi, per, region, floor, n) = if dim == "2d" {
        (
            "[0.0, -100.0]",
            "[0.0, -0.002]",
            "[0.012, 0.03]",
            "[true, false]",
            "{ lo = [0.0, 0.0005], hi = [0.012, 0.016] }",
            "{ type = \"plane\", point = [0.0, 0.0], normal = [0.0, 1.0] }",
            60,
        )
    } else {
        (
            "[0.0, 0.0, -100.0]",
            "[0.0, 0.0, -0.002]",
            "[0.006, 0.006, 0.03]",
            "[true, true, false]",
            "{ lo = [0.0, 0.0, 0.0005], hi = [0.006, 0.006, 0.008] }",
            "{ type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }",
            80,
        )
    };
    format!(
        r#"name = "ckpt-{dim}-{integrator}"
dimension = "{dim}"
seed = 7
gravity = {g}

[domain]
lo = {lo}
hi = {hi}
periodic = {per}

[particles]
placement = "lattice"
count = {n}
d0 = 1.0e-3
width = 0.3
random_velocity = 0.1
region = {region}

[contact]
preset = "lammps-hooke-history"
kn = 2.0e3

[[walls]]
name = "floor"
shape = {floor}
motion = {{ type = "vibrate", amplitude = 5.0e-4, frequency = 60.0 }}

[run]
integrator = "{integrator}"
dt = 2.0e-6
duration = 0.01
"#
    )
}

fn state_bytes<D: Dim>(md: &Md<D>) -> Vec<u8> {
    let mut e = Enc::default();
    encode_md(&mut e, &md.export_state().unwrap());
    e.buf
}

fn straight_vs_resumed<D: Dim>(dim: &str, integrator: &str, n: u64) {
    let text = scenario(dim, integrator);
    let loaded = load_str(&text, "test", PathBuf::from("."), &[]).unwrap();
    let (mut straight, _) = build_md::<D>(&loaded).unwrap();
    straight.run(2 * n).unwrap();

    let (mut first, _) = build_md::<D>(&loaded).unwrap();
    first.run(n).unwrap();
    let saved = engine::encode(&first).unwrap();
    let st = first.export_state().unwrap();
    eprintln!(
        "{dim} {integrator}: {} pairs, {} stretched springs, {} contacts, {} builds, dt {}",
        st.list.pairs.len(),
        st.springs.iter().filter(|&&s| D::norm2(s) > 0.0).count(),
        st.contacts,
        st.list.builds,
        first.settings.dt
    );
    assert!(
        st.springs.iter().any(|&s| D::norm2(s) > 0.0),
        "{dim} {integrator}: no tangential spring stretched at the stop"
    );
    assert!(st.list.builds > 2, "the list should have been rebuilt");
    drop(first);

    let (mut resumed, _) = build_md::<D>(&loaded).unwrap();
    engine::restore(&mut resumed, &saved).unwrap();
    assert_eq!(resumed.step, n);
    resumed.run(n).unwrap();
    assert_eq!(resumed.step, 2 * n);
    let (a, b) = (state_bytes(&straight), state_bytes(&resumed));
    assert!(
        a == b,
        "{dim} {integrator}: resumed state differs from the straight run"
    );
    assert_eq!(straight.neighbor_builds(), resumed.neighbor_builds());
}

#[test]
fn md_2d_gear5_resumes_bit_for_bit() {
    straight_vs_resumed::<D2>("2d", "gear5", 4000);
}

#[test]
fn md_2d_verlet_resumes_bit_for_bit() {
    straight_vs_resumed::<D2>("2d", "verlet", 4000);
}

#[test]
fn md_3d_gear5_resumes_bit_for_bit() {
    straight_vs_resumed::<D3>("3d", "gear5", 4000);
}

#[test]
fn md_3d_verlet_resumes_bit_for_bit() {
    straight_vs_resumed::<D3>("3d", "verlet", 4000);
}

#[test]
fn state_of_another_scenario_is_refused() {
    let a = load_str(&scenario("2d", "gear5"), "a", PathBuf::from("."), &[]).unwrap();
    let b = load_str(
        &scenario("2d", "gear5"),
        "b",
        PathBuf::from("."),
        &["contact.kn=6.0e7".to_string()],
    )
    .unwrap();
    let (md, _) = build_md::<D2>(&a).unwrap();
    let bytes = engine::encode(&md).unwrap();
    let (mut other, _) = build_md::<D2>(&b).unwrap();
    let e = engine::restore(&mut other, &bytes).unwrap_err().to_string();
    assert!(e.contains("different scenario"), "{e}");
    let c = load_str(
        &scenario("2d", "verlet"),
        "c",
        PathBuf::from("."),
        &["particles.count=59".to_string()],
    )
    .unwrap();
    let (mut other, _) = build_md::<D2>(&c).unwrap();
    let e = engine::restore(&mut other, &bytes).unwrap_err().to_string();
    assert!(e.contains("integrator"), "{e}");
}

/// Measured steps (after `RELAX` relaxation steps), output every 373
/// steps, convection sampled every 37 (a tenth of that), checkpoints every
/// 199: the runner advances in fused stretches between those steps and the
/// progress reports (every 256). The last checkpoint (step 2388) directly
/// follows a sample (measured step 1887), so a stretch that overshoots by
/// one step misses it.
const RELAX: u64 = 500;
const MEASURE: u64 = 2000;
const OUTPUT_EVERY: u64 = 373;
const CHECKPOINT_EVERY: u64 = 199;

/// The scenario run by the runner in [`runner_matches_single_steps`];
/// with `events`, it settles at the first look (step 50) and then tilts
/// gravity every step (never failing).
fn runner_scenario(dim: &str, integrator: &str, events: bool) -> Loaded {
    let dt = 2.0e-6;
    let text = format!(
        "{}\n[output]\nevery = {}\npicture = false\n\n[measure]\nconvection = {{ band = 0.2 }}\n",
        scenario(dim, integrator),
        OUTPUT_EVERY as f64 * dt
    );
    let mut sets = vec![
        format!("run.relax={}", RELAX as f64 * dt),
        format!("run.duration={}", MEASURE as f64 * dt),
    ];
    if events {
        sets.extend(
            ["settle_energy=1e9", "tilt_rate=1e4", "fail_energy=1e9"]
                .map(|s| format!("run.events.{s}")),
        );
    }
    load_str(&text, "test", PathBuf::from("."), &sets).unwrap()
}

/// The scenario run through the runner (which advances with the fused pass
/// between the steps its hooks look at) writes the frames, measurement file
/// and checkpoints of the same engine taken one `Md::step` at a time (run
/// events after every step), bit for bit: every frame holds the
/// full-precision state of its step, the newest checkpoint the whole engine
/// state (run events cannot be checkpointed: none then).
fn runner_matches_single_steps<D: Dim>(dim: &str, integrator: &str, events: bool) {
    let loaded = runner_scenario(dim, integrator, events);
    let dir = std::env::temp_dir().join(format!(
        "grains-runner-steps-{dim}-{integrator}-{events}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = RunOptions {
        out_dir: dir.clone(),
        checkpoint_every: (!events).then_some(Every::Steps(CHECKPOINT_EVERY)),
        ..Default::default()
    };
    let summary = run(&loaded, &opts, &mut Silent).unwrap();
    assert_eq!(summary["steps"], RELAX + MEASURE);
    if events {
        // Settled at step 50, then tilted by 0.02 degrees a step.
        assert_eq!(summary["settled"], 1);
        let tilt = summary["marginal_angle_lower_bound_deg"].as_f64().unwrap();
        assert!(tilt > 40.0, "tilted {tilt} degrees");
    }

    let (mut md, r) = build_md::<D>(&loaded).unwrap();
    let mut flow = FlowRun::begin(&loaded, &md).unwrap();
    assert_eq!(
        (r.relax_steps, r.measure_steps, r.output_every),
        (RELAX, MEASURE, OUTPUT_EVERY)
    );
    let mut convection = Convection::new(0.2);
    let end = RELAX + MEASURE;
    let last_checkpoint = end / CHECKPOINT_EVERY * CHECKPOINT_EVERY;
    let mut checkpoint_state = Vec::new();
    let mut frames = 0;
    let frame_is = |md: &Md<D>, index: usize| {
        let path = dir.join(format!("frames/frame_{index:06}.vtp"));
        let written = std::fs::read_to_string(&path).unwrap();
        assert!(
            written == vtp_string(&md.frame()),
            "{dim} {integrator}: frame {index} (step {}) differs",
            md.step
        );
    };
    grains::parallel::on_pool(|| -> grains::Result<()> {
        while md.step < end {
            md.step()?;
            flow.after_step(&mut md);
            if md.step == last_checkpoint {
                checkpoint_state = state_bytes(&md);
            }
            // Measured step k; the first frame is the state after relaxing.
            let Some(k) = md.step.checked_sub(RELAX) else {
                continue;
            };
            if k > 0 && k % 37 == 0 {
                convection.sample(&md.view());
            }
            if k % OUTPUT_EVERY == 0 || md.step == end {
                frame_is(&md, frames);
                frames += 1;
            }
        }
        Ok(())
    })
    .unwrap();
    assert_eq!(frames, 7, "frames at k = 0, 373, ..., 1865 and the end");
    convection.sample(&md.view());
    if !events {
        let newest = checkpointing::find(&dir).unwrap().0;
        let newest = newest.restore_md::<D>().unwrap();
        assert_eq!(newest.step, last_checkpoint);
        assert!(
            state_bytes(&newest) == checkpoint_state,
            "{dim} {integrator}: checkpoint at step {last_checkpoint} differs"
        );
    }
    let reference = dir.join("reference");
    std::fs::create_dir_all(&reference).unwrap();
    convection.write(&reference, &md.domain).unwrap();
    let csv = |d: &std::path::Path| std::fs::read(d.join("convection_profile.csv")).unwrap();
    assert!(
        csv(&dir) == csv(&reference),
        "{dim} {integrator}: convection profile differs"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn runner_matches_single_steps_2d_gear5() {
    runner_matches_single_steps::<D2>("2d", "gear5", false);
}

#[test]
fn runner_matches_single_steps_2d_verlet_with_run_events() {
    runner_matches_single_steps::<D2>("2d", "verlet", true);
}

#[test]
fn runner_matches_single_steps_3d_verlet() {
    runner_matches_single_steps::<D3>("3d", "verlet", false);
}
