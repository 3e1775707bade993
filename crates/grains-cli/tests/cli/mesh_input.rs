//! Mesh walls through the binary: bad STL input exits 2 naming the file
//! and the triangle, a good mesh run writes walls.csv with the load.

use std::path::{Path, PathBuf};
use std::process::Command;

/// 27 spheres above a floor read from `floor.stl` (a 6 mm square at z = 0,
/// path relative to the scenario, in mm).
const SCENARIO: &str = r#"name = "mesh-floor"
dimension = "3d"
gravity = [0.0, 0.0, -9.81]

[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.006, 0.006, 0.02]
periodic = [true, true, false]

[particles]
placement = "lattice"
count = 27
d0 = 1.0e-3
width = 0.2

[contact]
preset = "lammps-hooke-history"
kn = 5.0e7

[[walls]]
name = "floor"
shape = { type = "mesh", file = "meshes/floor.stl", scale = 1.0e-3 }

[run]
duration = 0.01
"#;

/// The floor as ASCII STL: two squares, four triangles, in mm.
fn floor_stl(first_vertex: &str) -> String {
    let facet = |a: &str, b: &str, c: &str| {
        format!(
            "facet normal 0 0 1\n outer loop\n  vertex {a}\n  vertex {b}\n  vertex {c}\n \
             endloop\nendfacet\n"
        )
    };
    let mut s = "solid floor\n".to_string();
    s += &facet(first_vertex, "3 0 0", "3 6 0");
    s += &facet("0 0 0", "3 6 0", "0 6 0");
    s += &facet("3 0 0", "6 0 0", "6 6 0");
    s += &facet("3 0 0", "6 6 0", "3 6 0");
    s + "endsolid floor\n"
}

struct Sandbox(PathBuf);

impl Sandbox {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("grains-mesh-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("meshes")).unwrap();
        std::fs::write(dir.join("s.toml"), SCENARIO).unwrap();
        Sandbox(dir)
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn run(dir: &Path) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_grains"))
        .args(["run", "s.toml", "--out", "out", "--steps", "200"])
        .current_dir(dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    (out.status.code(), err)
}

#[test]
fn bad_stl_files_exit_2_naming_the_file_and_the_triangle() {
    // Binary, one triangle with a NaN coordinate (ASCII readers refuse
    // "nan" before the mesh sees it).
    let mut nan = vec![0u8; 80];
    nan.extend(1u32.to_le_bytes());
    for x in [
        0.0f32,
        0.0,
        1.0,
        0.0,
        f32::NAN,
        0.0,
        3.0,
        0.0,
        0.0,
        3.0,
        6.0,
        0.0,
    ] {
        nan.extend(x.to_le_bytes());
    }
    nan.extend([0, 0]);
    // (name, the file's bytes or none, what stderr must say)
    type Case<'a> = (&'a str, Option<Vec<u8>>, &'a [&'a str]);
    let cases: [Case; 4] = [
        ("missing", None, &["floor.stl", "walls[0] (floor)"]),
        (
            "malformed",
            Some(b"solid x\nfacet normal 0 0 1\n outer lop\n".to_vec()),
            &["floor.stl", "triangle 0", "malformed"],
        ),
        (
            "degenerate",
            Some(floor_stl("3 0 0").into_bytes()),
            &["floor.stl", "triangle 0", "degenerate"],
        ),
        ("nan", Some(nan), &["floor.stl", "triangle 0", "not finite"]),
    ];
    for (name, text, needles) in cases {
        let sb = Sandbox::new(name);
        if let Some(t) = text {
            std::fs::write(sb.0.join("meshes/floor.stl"), t).unwrap();
        }
        let (code, err) = run(&sb.0);
        assert_eq!(code, Some(2), "{name}: {err}");
        for n in needles {
            assert!(err.contains(n), "{name}: stderr lacks {n:?}: {err}");
        }
    }
}

#[test]
fn a_mesh_run_writes_the_load_on_the_mesh_to_walls_csv() {
    let sb = Sandbox::new("good");
    std::fs::write(sb.0.join("meshes/floor.stl"), floor_stl("0 0 0")).unwrap();
    let (code, err) = run(&sb.0);
    assert_eq!(code, Some(0), "{err}");
    let csv = std::fs::read_to_string(sb.0.join("out/walls.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "step,time,floor_fx,floor_fy,floor_fz,floor_tx,floor_ty,floor_tz"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() >= 2, "{csv}");
    assert_eq!(rows[0][0], 0.0);
    // One row per output step, in order.
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0]), "{csv}");
    // Grains start above the floor: nothing on it at step 0.
    assert_eq!(&rows[0][2..], &[0.0; 6]);
}
