//! DSMC's three validity warnings (seed 000 §4), each raised by a scenario
//! built to break its condition and only that one: (i) a gas too thin to be
//! collisional (λ ≥ L), (ii) cells larger than the mean free path, (iii) a
//! time step longer than the mean time between collisions.
//!
//! The base gas: 2000 elastic disks of 1 mm in a periodic square of side
//! L = 1.414 m, so that the dilute mean free path λ = 1/(2√2 n d) is
//! 0.354 m = L/4; cells of λ/2; √(T/m) = 1 m/s, mean speed 1.25 m/s, mean
//! collision time τ = λ/⟨|v|⟩ ≈ 0.28 s; dt = τ/10.

use grains::runner::{run, RunOptions, Silent};
use grains::scenario::load_str;
use std::path::PathBuf;

fn scenario(count: usize, cell: f64, dt: f64) -> String {
    format!(
        r#"name = "validity"
dimension = "2d"
method = "dsmc"
seed = 5

[domain]
lo = [0.0, 0.0]
hi = [{SIDE}, {SIDE}]
periodic = [true, true]

[particles]
placement = "random"
count = {count}
d0 = 1.0e-3
density = 2500.0

[dsmc]
restitution = 1.0
thermal_speed = 1.0
cell_size = {cell:e}
dense = "none"
regions = 1

[run]
dt = {dt:e}
duration = {duration:e}

[output]
every = {every:e}
frames = false
picture = false
"#,
        duration = 100.0 * dt,
        every = 20.0 * dt,
    )
}

/// The validity warnings of a run of `text`, by condition: which of
/// (i), (ii), (iii) were raised.
fn warnings(name: &str, text: &str) -> [bool; 3] {
    let loaded = load_str(text, name, PathBuf::from("."), &[]).unwrap();
    let dir = std::env::temp_dir().join(format!("grains-validity-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = RunOptions {
        out_dir: dir.clone(),
        ..RunOptions::default()
    };
    let summary = run(&loaded, &opts, &mut Silent).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let list: Vec<String> = summary["validity"]["warnings"]
        .as_array()
        .unwrap_or_else(|| panic!("{name}: no validity warnings list in {summary}"))
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    let has = |tag: &str| list.iter().any(|w| w.contains(tag));
    [has(": (i) "), has(": (ii) "), has(": (iii) ")]
}

/// The box's side, m.
const SIDE: f64 = std::f64::consts::SQRT_2;
const LAMBDA: f64 = 0.354;
const TAU: f64 = 0.28;

#[test]
fn valid_gas_raises_no_warning() {
    let w = warnings("valid", &scenario(2000, LAMBDA / 2.0, TAU / 10.0));
    assert_eq!(w, [false; 3]);
}

#[test]
fn thin_gas_breaks_the_knudsen_condition() {
    // A tenth of the grains: λ = 3.5 m, above the box's 1.41 m; the cells
    // (L/4) stay below λ and τ ≈ 2.8 s far above dt.
    let w = warnings("thin", &scenario(200, SIDE / 4.0, TAU / 10.0));
    assert_eq!(w, [true, false, false]);
}

#[test]
fn coarse_cells_break_the_cell_condition() {
    // Cells of L/2 = 2 λ: two per side.
    let w = warnings("coarse", &scenario(2000, SIDE / 2.0, TAU / 10.0));
    assert_eq!(w, [false, true, false]);
}

#[test]
fn long_steps_break_the_time_step_condition() {
    // dt = 2 τ: each grain collides about twice per step.
    let w = warnings("long-steps", &scenario(2000, LAMBDA / 2.0, 2.0 * TAU));
    assert_eq!(w, [false, false, true]);
}
