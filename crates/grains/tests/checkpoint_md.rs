//! Checkpoint and resume of the MD engine: a run of 2N steps and a run of N
//! steps, saved, restored into a fresh engine and run N more, end bit for
//! bit equal, in 2D and 3D, with Gear-5 and velocity Verlet, with tangential
//! springs stretched at the stop. The comparison is on the encoded state
//! (every particle array, Gear history, pair list, image codes, skin
//! reference positions, springs, counters).

use grains::checkpoint::{codec::Enc, engine, state::encode_md};
use grains::dim::{Dim, D2, D3};
use grains::md::Md;
use grains::scenario::{build_md, load_str};
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
