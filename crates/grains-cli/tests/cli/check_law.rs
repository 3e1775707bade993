//! What `grains check` prints of a material contact law (checked against
//! closed forms from the scenario's own numbers), the time step and the
//! memory; and options a mode would ignore refused by name.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Two glass spheres above a steel floor, DMT cohesion and constant
/// rolling resistance.
const GLASS_ON_STEEL: &str = r#"name = "glass-on-steel"
dimension = "3d"
gravity = [0.0, 0.0, -9.81]

[domain]
lo = [-0.01, -0.01, 0.0]
hi = [0.01, 0.01, 0.02]

[particles]
placement = "none"
d0 = 2.0e-3
material = "glass"
add = [{ position = [0.0, 0.0, 0.003] }, { position = [0.005, 0.0, 0.003] }]

[contact]
model = "hertz-mindlin"
rotation = true
rolling = "constant"
cohesion = "dmt"

[[materials]]
name = "glass"
density = 2500.0
youngs_modulus = 6.3e10
poisson_ratio = 0.23
restitution = 0.9
friction = 0.3
rolling_friction = 0.01
surface_energy = 0.05

[[materials]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
poisson_ratio = 0.3
restitution = 0.8
friction = 0.5
rolling_friction = 0.02
surface_energy = 0.05

[[walls]]
name = "floor"
material = "steel"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }

[run]
duration = 1.0e-3
"#;

fn grains(cwd: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("start the grains binary");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scratch(name: &str, text: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("grains-check-law-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.toml");
    std::fs::write(&file, text).unwrap();
    (dir, file)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn check_prints_the_resolved_material_law() {
    let (dir, file) = scratch("law", GLASS_ON_STEEL);
    let (code, out, err) = grains(&dir, &["check", file.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{out}{err}");
    let v: Value = serde_json::from_str(&out).expect("JSON");
    let c = &v["contact"];
    // No spring-dashpot coefficients that mean nothing here.
    for k in ["kn", "gamma_n", "gamma_t", "kt"] {
        assert!(c[k].is_null(), "{k} printed: {c}");
    }
    assert_eq!(c["model"], "hertz-mindlin", "{c}");
    assert_eq!(c["rolling"]["model"], "constant", "{c}");
    assert_eq!(c["cohesion"]["model"], "dmt", "{c}");
    assert!(c["tangential"].as_str().unwrap().contains("8 G* a"), "{c}");
    let pairs = c["pairs"].as_array().expect("pairs");
    let grains = pairs
        .iter()
        .find(|p| p["between"] == "grains")
        .expect("grain pair");
    let floor = pairs
        .iter()
        .find(|p| p["between"] == "grains and walls floor")
        .expect("floor pair");
    assert_eq!(floor["materials"], serde_json::json!(["glass", "steel"]));
    // Johnson's rules from the scenario's numbers.
    let (e1, n1, e2, n2) = (6.3e10, 0.23f64, 2.0e11, 0.3f64);
    let e_star = 1.0 / ((1.0 - n1 * n1) / e1 + (1.0 - n2 * n2) / e2);
    assert!(close(f(&floor["e_star"]), e_star), "{floor} vs {e_star}");
    let g = |e: f64, n: f64| e / (2.0 * (1.0 + n));
    let g_star = 1.0 / ((2.0 - n1) / g(e1, n1) + (2.0 - n2) / g(e2, n2));
    assert!(close(f(&floor["g_star"]), g_star), "{floor} vs {g_star}");
    let glass_e = 1.0 / (2.0 * (1.0 - n1 * n1) / e1);
    assert!(close(f(&grains["e_star"]), glass_e), "{grains}");
    // Monodisperse: R* and m* are single numbers.
    let r = 1.0e-3;
    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    assert!(close(f(&floor["r_star"]), r), "{floor}");
    assert!(close(f(&floor["m_star"]), m), "{floor}");
    assert!(close(f(&grains["r_star"]), r / 2.0), "{grains}");
    assert!(close(f(&grains["m_star"]), m / 2.0), "{grains}");
    // The weaker surface's restitution and friction; Tsuji's α for e < 1.
    assert_eq!(f(&floor["restitution"]), 0.8);
    assert_eq!(f(&floor["friction"]), 0.3);
    assert_eq!(f(&floor["rolling_friction"]), 0.01);
    assert!(
        f(&floor["damping_alpha"]) > f(&grains["damping_alpha"]),
        "{c}"
    );
    // DMT: Γ = √(Γ₁Γ₂), pull-off 2π Γ R*.
    let pull = 2.0 * std::f64::consts::PI * 0.05 * r;
    assert!(close(f(&floor["pull_off_force"]), pull), "{floor}");
    // The time step's reasoning and the memory.
    let ts = &v["time_step"];
    let (tc, dt) = (f(&ts["contact_time"]), f(&ts["dt"]));
    assert!(close(f(&ts["steps_per_contact"]), tc / dt), "{ts}");
    assert!(
        ts["dt_origin"].as_str().unwrap().starts_with("auto"),
        "{ts}"
    );
    assert!(
        ts["contact_time_of"].as_str().unwrap().contains("Hertz"),
        "{ts}"
    );
    let mem = &v["memory"];
    assert_eq!(mem["grains"], 2);
    assert_eq!(
        f(&mem["estimate_bytes"]),
        2.0 * f(&mem["bytes_per_grain"]),
        "{mem}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A DSMC scenario writes no dump: `output.dump` there is an input error
/// naming the key, not a silent no-op.
#[test]
fn dsmc_refuses_output_dump_by_name() {
    let gas = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/gas-cooling-2d.toml");
    let text = std::fs::read_to_string(&gas).unwrap();
    let (dir, file) = scratch("dsmc-dump", &text);
    let f = file.to_str().unwrap();
    let (code, out, err) = grains(&dir, &["check", f, "--set", "output.dump=true"]);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(err.contains("output.dump") && err.contains("dsmc"), "{err}");
    let out_dir = dir.join("out");
    let (code, _, err) = grains(
        &dir,
        &[
            "run",
            f,
            "--set",
            "output.dump=true",
            "--steps",
            "2",
            "--quiet",
            "--out",
            out_dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("output.dump"), "{err}");
    let (code, out, err) = grains(&dir, &["check", f]);
    assert_eq!(code, Some(0), "{out}{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
