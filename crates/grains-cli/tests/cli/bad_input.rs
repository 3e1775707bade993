//! Bad input through the `grains` binary: every malformed scenario, data
//! file or option exits 2 with a message naming the file, the key and what
//! is allowed, never a panic (the small scenarios of `commands.rs`).

use super::commands::{edited, grains, s, Outcome, Sandbox, BASE};
use serde_json::Value;
use std::path::PathBuf;

/// A scenario file that must be refused as bad input.
struct BadCase {
    name: &'static str,
    edits: &'static [(&'static str, &'static str)],
    /// Texts stderr must contain: the key, the offending value, what is allowed.
    needles: &'static [&'static str],
}

const ADD_TWO: &str = "placement = \"none\"\nadd = [ { position = [0.005, 0.005] }, { position = [0.00501, 0.005] } ]";

const BAD_CASES: &[BadCase] = &[
    BadCase {
        name: "nan_d0",
        edits: &[("d0 = 1.0e-3", "d0 = nan")],
        needles: &["particles.d0", "NaN", "must be a positive diameter"],
    },
    BadCase {
        name: "nan_gravity",
        edits: &[("gravity = [0.0, -9.81]", "gravity = [0.0, nan]")],
        needles: &["gravity", "NaN", "must be finite"],
    },
    BadCase {
        name: "inf_dt",
        edits: &[("duration = 0.01", "duration = 0.01\ndt = inf")],
        needles: &["run.dt", "inf", "must be a positive number"],
    },
    BadCase {
        name: "unknown_top_level_key",
        edits: &[("name = \"small\"", "name = \"small\"\nbogus = 1")],
        needles: &["unknown field `bogus`", "expected one of", "`gravity`"],
    },
    BadCase {
        name: "unknown_nested_key",
        edits: &[("preset = \"seed\"", "preset = \"seed\"\nmu_s = 0.3")],
        needles: &["unknown field `mu_s`", "`contact`", "`mu`", "expected one of"],
    },
    BadCase {
        name: "wrong_type",
        edits: &[("count = 30", "count = \"ten\"")],
        needles: &["particles.count", "\"ten\"", "expected"],
    },
    BadCase {
        name: "d0_zero",
        edits: &[("d0 = 1.0e-3", "d0 = 0.0")],
        needles: &["particles.d0 = 0", "must be a positive"],
    },
    BadCase {
        name: "d0_negative",
        edits: &[("d0 = 1.0e-3", "d0 = -1.0e-3")],
        needles: &["particles.d0 = -0.001", "must be a positive"],
    },
    BadCase {
        name: "dt_zero",
        edits: &[("duration = 0.01", "duration = 0.01\ndt = 0.0")],
        needles: &["run.dt = 0", "positive"],
    },
    BadCase {
        name: "dt_negative",
        edits: &[("duration = 0.01", "duration = 0.01\ndt = -1.0e-6")],
        needles: &["run.dt = -0.000001", "positive"],
    },
    BadCase {
        name: "dt_text",
        edits: &[("duration = 0.01", "duration = 0.01\ndt = \"fast\"")],
        needles: &["run.dt", "\"fast\"", "a number of seconds or \"auto\""],
    },
    BadCase {
        name: "width_two",
        edits: &[("width = 0.2", "width = 2.0")],
        needles: &["particles.width = 2", "[0, 2)"],
    },
    BadCase {
        name: "mu_negative",
        edits: &[("preset = \"seed\"", "preset = \"seed\"\nmu = -0.1")],
        needles: &["contact.mu = -0.1", ">= 0"],
    },
    BadCase {
        name: "beta_zero",
        edits: &[("preset = \"seed\"", "preset = \"seed\"\nbeta = 0.0")],
        needles: &["contact.beta = 0", "positive"],
    },
    BadCase {
        name: "restitution_above_one",
        edits: &[("preset = \"seed\"", "preset = \"seed\"\nrestitution = 1.5")],
        needles: &["contact.restitution = 1.5", "(0, 1]"],
    },
    BadCase {
        name: "restitution_zero",
        edits: &[("preset = \"seed\"", "preset = \"seed\"\nrestitution = 0.0")],
        needles: &["contact.restitution = 0", "(0, 1]"],
    },
    BadCase {
        name: "gravity_wrong_length",
        edits: &[("gravity = [0.0, -9.81]", "gravity = [0.0, -9.81, 0.0]")],
        needles: &["gravity", "3 components", "2d", "needs 2"],
    },
    BadCase {
        name: "domain_wrong_length",
        edits: &[("lo = [0.0, 0.0]", "lo = [0.0, 0.0, 0.0]")],
        needles: &["domain.lo", "3 components", "needs 2"],
    },
    BadCase {
        name: "added_grain_wrong_length",
        edits: &[(
            "placement = \"lattice\"",
            "placement = \"none\"\nadd = [ { position = [0.005, 0.005, 0.0] } ]",
        )],
        needles: &["particles.add[0].position", "3 components", "needs 2"],
    },
    BadCase {
        name: "initial_overlap_beyond_tolerance",
        // Centres 0.95 d apart: 10% of a radius, above the 5% tolerance.
        edits: &[(
            "placement = \"lattice\"",
            "placement = \"none\"\nadd = [ { position = [0.005, 0.005] }, { position = [0.00595, 0.005] } ]",
        )],
        needles: &["grain 1 overlaps grain 2", "10.0%", "at most 5% allowed"],
    },
    BadCase {
        name: "grains_at_nearly_the_same_point",
        edits: &[("placement = \"lattice\"", ADD_TWO)],
        needles: &["grain 1", "grain 2", "overlaps"],
    },
    BadCase {
        name: "grains_at_exactly_the_same_point",
        edits: &[(
            "placement = \"lattice\"",
            "placement = \"none\"\nadd = [ { position = [0.005, 0.005] }, { position = [0.005, 0.005] } ]",
        )],
        needles: &["grain 1", "grain 2", "overlaps"],
    },
    BadCase {
        name: "toml_syntax_error",
        edits: &[("count = 30", "count = = 30")],
        needles: &["line 12", "count = = 30"],
    },
];

fn case(name: &str) -> &'static BadCase {
    BAD_CASES
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no bad case {name}"))
}

/// Writes the case, runs `grains check` and `grains run` on it, and checks
/// exit code 2 and the message. Returns the scenario path and run outcome.
fn expect_bad(sb: &Sandbox, c: &BadCase) -> (PathBuf, Outcome) {
    let file = sb.write(&format!("{}.toml", c.name), &edited(BASE, c.edits));
    let check = grains(&sb.dir, &["check", s(&file)]);
    check.assert_code(2);
    check.assert_stderr_has(c.needles);
    let out = sb.path(&format!("out-{}", c.name));
    let run = grains(
        &sb.dir,
        &[
            "run",
            s(&file),
            "--steps",
            "50",
            "--quiet",
            "--out",
            s(&out),
        ],
    );
    run.assert_code(2);
    run.assert_stderr_has(c.needles);
    (file, run)
}

/// The cases whose message names the scenario file today (errors of the
/// TOML parser and the schema, and of the initial overlap check).
fn bad_case_test(name: &str) {
    let sb = Sandbox::new(name);
    let c = case(name);
    let (file, run) = expect_bad(&sb, c);
    let names_file = [
        "unknown_top_level_key",
        "unknown_nested_key",
        "wrong_type",
        "dt_text",
        "initial_overlap_beyond_tolerance",
        "grains_at_nearly_the_same_point",
        "grains_at_exactly_the_same_point",
        "toml_syntax_error",
    ];
    if names_file.contains(&name) {
        run.assert_stderr_has(&[s(&file)]);
    }
}

#[test]
fn unknown_top_level_key() {
    bad_case_test("unknown_top_level_key");
}

#[test]
fn unknown_nested_key() {
    bad_case_test("unknown_nested_key");
}

#[test]
fn wrong_type() {
    bad_case_test("wrong_type");
}

#[test]
fn d0_zero() {
    bad_case_test("d0_zero");
}

#[test]
fn d0_negative() {
    bad_case_test("d0_negative");
}

#[test]
fn dt_zero() {
    bad_case_test("dt_zero");
}

#[test]
fn dt_negative() {
    bad_case_test("dt_negative");
}

#[test]
fn dt_text() {
    bad_case_test("dt_text");
}

#[test]
fn width_two() {
    bad_case_test("width_two");
}

#[test]
fn mu_negative() {
    bad_case_test("mu_negative");
}

#[test]
fn beta_zero() {
    bad_case_test("beta_zero");
}

#[test]
fn restitution_above_one() {
    bad_case_test("restitution_above_one");
}

#[test]
fn restitution_zero() {
    bad_case_test("restitution_zero");
}

#[test]
fn gravity_wrong_length() {
    bad_case_test("gravity_wrong_length");
}

#[test]
fn domain_wrong_length() {
    bad_case_test("domain_wrong_length");
}

#[test]
fn added_grain_wrong_length() {
    bad_case_test("added_grain_wrong_length");
}

#[test]
fn initial_overlap_beyond_tolerance() {
    bad_case_test("initial_overlap_beyond_tolerance");
}

#[test]
fn grains_at_nearly_the_same_point() {
    bad_case_test("grains_at_nearly_the_same_point");
}

#[test]
fn grains_at_exactly_the_same_point() {
    bad_case_test("grains_at_exactly_the_same_point");
}

#[test]
fn toml_syntax_error_gives_the_line() {
    bad_case_test("toml_syntax_error");
}

#[test]

fn every_bad_input_message_names_the_scenario_file() {
    let sb = Sandbox::new("names-file");
    let mut missing = Vec::new();
    for c in BAD_CASES {
        let (file, run) = expect_bad(&sb, c);
        if !run.stderr.contains(s(&file)) {
            missing.push(format!("{}: {}", c.name, run.stderr.trim()));
        }
    }
    assert!(
        missing.is_empty(),
        "messages without the file name:\n{}",
        missing.join("\n")
    );
}

#[test]

fn schema_errors_give_the_line() {
    let sb = Sandbox::new("schema-line");
    // `bogus` is on line 2, `mu_s` on line 18 and `count` on line 12.
    for (name, line) in [
        ("unknown_top_level_key", 2),
        ("unknown_nested_key", 18),
        ("wrong_type", 12),
    ] {
        let (_, run) = expect_bad(&sb, case(name));
        run.assert_stderr_has(&[&format!("line {line}")]);
    }
}

#[test]

fn coincident_grains_are_reported_as_an_initial_overlap() {
    let sb = Sandbox::new("coincident");
    for name in [
        "grains_at_nearly_the_same_point",
        "grains_at_exactly_the_same_point",
    ] {
        let (_, run) = expect_bad(&sb, case(name));
        run.assert_stderr_has(&["at most 5% allowed", "move the grains apart"]);
        assert!(!run.stderr.contains("dt ="), "{}", run.describe());
    }
}

#[test]

fn huge_particle_count_is_bad_input() {
    let sb = Sandbox::new("huge-count");
    let file = sb.write(
        "huge.toml",
        &edited(BASE, &[("count = 30", "count = 1000000000000")]),
    );
    let run = grains(&sb.dir, &["check", s(&file)]);
    run.assert_code(2);
    run.assert_stderr_has(&["particles.count"]);
}

#[test]
fn no_bad_input_makes_run_panic() {
    let sb = Sandbox::new("no-panic");
    let mut texts: Vec<(String, String)> = BAD_CASES
        .iter()
        .map(|c| (c.name.to_string(), edited(BASE, c.edits)))
        .collect();
    // More odd values on top of the cases above.
    for (name, from, to) in [
        ("nan_duration", "duration = 0.01", "duration = nan"),
        ("zero_normal", "normal = [0.0, 1.0]", "normal = [0.0, 0.0]"),
        ("empty_domain", "hi = [0.01, 0.02]", "hi = [0.0, 0.02]"),
        ("negative_count", "count = 30", "count = -3"),
        ("zero_count", "count = 30", "count = 0"),
        ("dimension_4d", "dimension = \"2d\"", "dimension = \"4d\""),
        ("zero_kn", "preset = \"seed\"", "kn = 0.0"),
        ("no_length", "duration = 0.01", "skin = 0.2"),
        ("cycles_no_wall", "duration = 0.01", "cycles = 3"),
        (
            "zero_skin",
            "duration = 0.01",
            "duration = 0.01\nskin = 0.0",
        ),
        (
            "dense_random",
            "placement = \"lattice\"",
            "placement = \"random\"",
        ),
    ] {
        let mut text = edited(BASE, &[(from, to)]);
        if name == "dense_random" {
            text = edited(&text, &[("count = 30", "count = 3000")]);
        }
        texts.push((name.to_string(), text));
    }
    texts.push(("empty".into(), String::new()));
    texts.push(("not_toml".into(), "\u{1}\u{2}[[[".into()));
    for (name, text) in &texts {
        let file = sb.write(&format!("{name}.toml"), text);
        let out = sb.path(&format!("out-{name}"));
        let run = grains(
            &sb.dir,
            &[
                "run",
                s(&file),
                "--steps",
                "50",
                "--quiet",
                "--out",
                s(&out),
            ],
        );
        run.assert_no_panic();
        assert!(
            matches!(run.code, Some(0 | 2 | 3)),
            "{name}: {}",
            run.describe()
        );
        assert!(
            run.code == Some(0) || run.stderr.starts_with("grains: error: "),
            "{name}: {}",
            run.describe()
        );
    }
}

#[test]
fn missing_scenario_file() {
    let sb = Sandbox::new("missing-scenario");
    let file = sb.path("nothere.toml");
    for args in [
        vec!["check", s(&file)],
        vec!["run", s(&file), "--steps", "50", "--quiet"],
    ] {
        let run = grains(&sb.dir, &args);
        run.assert_code(2);
        run.assert_stderr_has(&[s(&file), "No such file"]);
    }
}

#[test]
fn missing_data_file() {
    let sb = Sandbox::new("missing-data");
    let file = sb.write(
        "s.toml",
        &edited(
            BASE,
            &[(
                "placement = \"lattice\"",
                "placement = \"file\"\nfile = \"nothere.data\"",
            )],
        ),
    );
    let run = grains(&sb.dir, &["check", s(&file)]);
    run.assert_code(2);
    run.assert_stderr_has(&[s(&sb.path("nothere.data")), "No such file"]);
}

const GOOD_DATA: &str = "grains test data\n\n2 atoms\n1 atom types\n\n0 0.01 xlo xhi\n0 0.02 ylo yhi\n-0.5 0.5 zlo zhi\n\nAtoms # sphere\n\n1 1 0.001 2500 0.002 0.002 0\n2 1 0.001 2500 0.004 0.004 0\n";

fn file_scenario() -> String {
    edited(
        BASE,
        &[(
            "placement = \"lattice\"",
            "placement = \"file\"\nfile = \"grains.data\"",
        )],
    )
}

#[test]
fn malformed_lammps_data_names_file_and_line() {
    let sb = Sandbox::new("bad-data");
    let data = sb.write(
        "grains.data",
        &GOOD_DATA.replace("0.004 0.004 0\n", "0.00x 0.004 0\n"),
    );
    let file = sb.write("s.toml", &file_scenario());
    let run = grains(&sb.dir, &["check", s(&file)]);
    run.assert_code(2);
    // The bad number is on line 13 of the data file, in column 5 (x).
    run.assert_stderr_has(&[&format!("{}:13", data.display()), "(x)", "'0.00x'"]);
}

#[test]
fn lammps_data_file_is_read_relative_to_the_scenario() {
    let sb = Sandbox::new("good-data");
    sb.write("grains.data", GOOD_DATA);
    let file = sb.write("s.toml", &file_scenario());
    // Run from elsewhere: the data path is relative to the scenario file.
    let run = grains(&std::env::temp_dir(), &["check", s(&file)]);
    run.assert_code(0);
    let v: Value = serde_json::from_str(&run.stdout).expect("check prints JSON");
    assert_eq!(v["particles"], 2, "{}", run.describe());
}

#[test]
fn set_without_equals() {
    let sb = Sandbox::new("set-no-eq");
    let file = sb.write("s.toml", BASE);
    for cmd in ["check", "run"] {
        let run = grains(&sb.dir, &[cmd, s(&file), "--set", "contact.mu"]);
        run.assert_code(2);
        run.assert_stderr_has(&["--set contact.mu", "KEY=VALUE"]);
    }
}

#[test]
fn set_unknown_key() {
    let sb = Sandbox::new("set-unknown");
    let file = sb.write("s.toml", BASE);
    let run = grains(&sb.dir, &["check", s(&file), "--set", "contact.mu_s=0.3"]);
    run.assert_code(2);
    run.assert_stderr_has(&[s(&file), "--set", "unknown field `mu_s`", "`mu`"]);
    let run = grains(&sb.dir, &["check", s(&file), "--set", "walls.4.name=x"]);
    run.assert_code(2);
    run.assert_stderr_has(&["walls.4", "out of range"]);
}

#[test]
fn steps_zero() {
    let sb = Sandbox::new("steps-zero");
    let file = sb.write("s.toml", BASE);
    let out = sb.path("out");
    let run = grains(
        &sb.dir,
        &["run", s(&file), "--steps", "0", "--quiet", "--out", s(&out)],
    );
    run.assert_code(2);
    run.assert_stderr_has(&["--steps", "at least 1"]);
    assert!(!out.exists(), "--steps 0 must not create the output dir");
}
