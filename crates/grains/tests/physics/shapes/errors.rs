//! Bad input about clumps is refused with a message naming the key (and
//! the allowed values), never a panic.

use super::placement::{parts, BASE};
use grains::{D2, D3};

fn error(text: &str, sets: &[&str]) -> String {
    match parts::<D3>(text, sets) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

fn has(e: &str, words: &[&str]) {
    for w in words {
        assert!(e.contains(w), "{w:?} missing from: {e}");
    }
}

fn first_shape(spheres: &str) -> String {
    let start = BASE.find("[[shapes]]").unwrap();
    format!("{}[[shapes]]\nname = \"rod\"\n{spheres}\n", &BASE[..start])
}

#[test]
fn shape_keys_are_checked_by_name() {
    has(
        &error(&first_shape(""), &[]),
        &["clumps.toml", "shapes[0] (rod)", "spheres", "file"],
    );
    let e = error(
        &first_shape("spheres = [{ center = [0.0, 0.0, 0.0], radius = 1e-3 }, { center = [1e-3, 0.0, 0.0], radius = 0.0 }]"),
        &[],
    );
    has(&e, &["shapes[0] (rod).spheres[1].radius = 0", "positive"]);
    let e = error(
        &first_shape("spheres = [{ center = [0.0, 0.0, 0.0], radius = 1e-3 }, { center = [2.5e-3, 0.0, 0.0], radius = 1e-3 }]"),
        &[],
    );
    has(
        &e,
        &["shapes[0] (rod).spheres[1]", "connected", "rigid body"],
    );
    let e = error(
        &first_shape("spheres = [{ center = [0.0, 0.0], radius = 1e-3 }]"),
        &[],
    );
    has(
        &e,
        &[
            "shapes[0] (rod).spheres[0].center has 2 components",
            "needs 3",
        ],
    );
    let e = error(
        &first_shape("units = \"cm\"\nspheres = [{ center = [0.0, 0.0, 0.0], radius = 1.0 }]"),
        &[],
    );
    has(&e, &["units", "`m`", "`d0`"]);
    let e = error(
        &first_shape("scale = -1.0\nspheres = [{ center = [0.0, 0.0, 0.0], radius = 1.0 }]"),
        &[],
    );
    has(&e, &["shapes[0] (rod).scale = -1"]);
    let e = error(&first_shape("file = \"no-such-shape.csv\""), &[]);
    has(
        &e,
        &[
            "shapes[0] (rod).file = \"no-such-shape.csv\"",
            "cannot read",
        ],
    );
    let twice = format!("{BASE}[[shapes]]\nname = \"rod\"\nspheres = [{{ center = [0.0, 0.0, 0.0], radius = 1e-3 }}]\n");
    has(
        &error(&twice, &[]),
        &["shapes[3].name = \"rod\" is used twice"],
    );
}

#[test]
fn a_shape_file_is_read_and_its_lines_named() {
    let dir = std::env::temp_dir().join(format!("grains-shapes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("rod.csv"),
        "# x y z r (d0)\n-0.8 0 0 0.5\n0, 0, 0, 0.5 # middle\n\n0.8 0 0 0.5\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.csv"), "0 0 0 0.5\n1 0 0\n").unwrap();
    let text = |file: &str| {
        first_shape(&format!(
            "units = \"d0\"\nfile = \"{}\"",
            dir.join(file).display()
        ))
    };
    let (_, from_file) = parts::<D3>(&text("rod.csv"), &[]).unwrap();
    let (_, inline) = parts::<D3>(BASE, &[]).unwrap();
    assert_eq!(from_file.shapes[0], inline.shapes[0]);
    has(
        &error(&text("bad.csv"), &[]),
        &[
            "shapes[0] (rod).file",
            "bad.csv) line 2",
            "3 numbers",
            "x y z r",
        ],
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn body_keys_are_checked_by_name() {
    has(
        &error(BASE, &["particles.shape=\"cube\""]),
        &[
            "particles.shape = \"cube\"",
            "\"rod\", \"dimer\", \"tetra\"",
        ],
    );
    let mix = BASE.replace(
        "shape = \"rod\"\n",
        "shapes = [{ name = \"rod\", fraction = 0.5 }, { name = \"dimer\", fraction = 0.3 }]\n",
    );
    has(&error(&mix, &[]), &["particles.shapes", "sum to 0.8"]);
    has(
        &error(BASE, &["particles.orientation=\"sideways\""]),
        &["particles.orientation = \"sideways\"", "\"random\""],
    );
    has(
        &error(BASE, &["particles.orientation=[1.0, 0.1, 0.0, 0.0]"]),
        &["particles.orientation", "norm", "unit quaternion"],
    );
    assert_eq!(
        error(BASE, &["particles.orientation=[1.0, 0.0, 0.0, 0.0005]"]),
        "",
        "rounding is normalised"
    );
    let add = format!("{BASE}[[particles.add]]\nshape = \"dimer\"\nposition = [0.006, 0.006, 0.02]\ndiameter = 0.001\n");
    has(&error(&add, &[]), &["particles.add[0].diameter", "shape"]);
    let add = format!("{BASE}[[particles.add]]\nposition = [0.006, 0.006, 0.02]\norientation = [1.0, 0.0, 0.0, 0.0]\n");
    has(&error(&add, &[]), &["particles.add[0].orientation", "body"]);
    has(
        &error(BASE, &["particles.width=0.2"]),
        &["particles.width", "[[shapes]]"],
    );
    has(
        &error(BASE, &["particles.count=100000"]),
        &["body", "shape \"rod\"", "particles.region"],
    );
}

#[test]
fn what_bodies_do_not_do_is_refused_by_name() {
    has(
        &error(
            BASE,
            &["particles.placement=\"file\"", "particles.file=\"x.data\""],
        ),
        &["particles.placement = \"file\"", "bodies"],
    );
    has(
        &error(BASE, &["method=\"dsmc\""]),
        &["method = \"dsmc\"", "MD"],
    );
    let sink = format!("{BASE}[run.events]\nsink = -0.01\n");
    has(&error(&sink, &[]), &["run.events.sink"]);
    let z = r#"name = "c2"
dimension = "2d"
[domain]
lo = [0.0, 0.0]
hi = [0.02, 0.04]
[particles]
placement = "none"
[[particles.add]]
shape = "d"
position = [0.01, 0.01]
orientation = [0.0, 1.0, 0.0, 0.0]
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-6
duration = 1.0e-4
[[shapes]]
name = "d"
spheres = [{ center = [0.0, 0.0, 0.0], radius = 5e-4 }, { center = [1e-3, 0.0, 1e-4], radius = 5e-4 }]
"#;
    let e = match parts::<D2>(z, &[]) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    has(&e, &["particles.add[0].orientation", "about z"]);
    let z = z.replace("orientation = [0.0, 1.0, 0.0, 0.0]\n", "");
    let e = match parts::<D2>(&z, &[]) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    has(
        &e,
        &[
            "shapes[0] (d).spheres[1].center has z = 0.0001",
            "plane z = 0",
        ],
    );
}
