//! The GPU pipeline's CPU mirror against the CPU engine, bit for bit, and
//! its neighbour-list build against brute force.

use grains::gpu::grain_kernels::{dot, row_key, sub, V3};
use grains::gpu::mirror::{CellOrder, Mirror};
use grains::md::Md;
use grains::scenario::{build_md, load_file, load_str};
use grains::D3;
use std::collections::HashMap;
use std::path::PathBuf;

fn chute() -> Md<D3> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-chute.toml");
    build_md::<D3>(&load_file(&path, &[]).unwrap()).unwrap().0
}

/// A bed of 3000 spheres (three of the CPU engine's pair blocks), diameters
/// 1 ± 10 % on a lattice of pitch 1 (so some start overlapping), periodic
/// along y only, between two side planes and on a floor, one side wall
/// elastic, under gravity tilted toward a side wall.
fn bed() -> Md<D3> {
    let text = r#"name = "bed-walls"
dimension = "3d"
gravity = [3.0, 0.0, -10.0]
[domain]
lo = [0.0, 0.0, 0.0]
hi = [16.0, 18.0, 40.0]
periodic = [false, true, false]
[particles]
placement = "lattice"
count = 3000
d0 = 1.0
width = 0.2
density = 1.9098593
spacing = 1.0
region = { lo = [0.0, 0.0, 0.0], hi = [16.0, 18.0, 40.0] }
[contact]
preset = "lammps-hooke-history"
elastic_walls = ["right"]
[[walls]]
name = "floor"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
[[walls]]
name = "left"
shape = { type = "plane", point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }
[[walls]]
name = "right"
shape = { type = "plane", point = [16.0, 0.0, 0.0], normal = [-1.0, 0.0, 0.0] }
[run]
integrator = "verlet"
dt = 1.0e-4
duration = 1.0
skin = 0.1
[output]
frames = false
picture = false
"#;
    let loaded = load_str(text, "bed-walls", PathBuf::from("."), &[]).unwrap();
    build_md::<D3>(&loaded).unwrap().0
}

/// Every grain's position, velocity and spin bits, and the list and
/// springs of the two states, compared (grains by index: the mirror keeps
/// the CPU engine's order, which is part of what is tested).
fn assert_same_bits(cpu: &Md<D3>, mirror: &Mirror, what: &str) {
    let a = cpu.export_state().unwrap();
    let b = mirror.to_state();
    assert_eq!(a.step, b.step, "{what}: step");
    assert_eq!(a.particles.id, b.particles.id, "{what}: grain order");
    let bits = |v: &[glam::DVec3]| -> Vec<[u64; 3]> {
        v.iter().map(|x| x.to_array().map(f64::to_bits)).collect()
    };
    for (name, x, y) in [
        ("positions", &a.particles.pos, &b.particles.pos),
        ("velocities", &a.particles.vel, &b.particles.vel),
        ("spins", &a.particles.omega, &b.particles.omega),
    ] {
        let (x, y) = (bits(x), bits(y));
        let differ = x.iter().zip(&y).filter(|(p, q)| p != q).count();
        assert_eq!(differ, 0, "{what}: {differ} grains' {name} differ");
    }
    assert_eq!(a.list.pairs, b.list.pairs, "{what}: pairs");
    assert_eq!(a.list.image, b.list.image, "{what}: image codes");
    assert_eq!(bits(&a.springs), bits(&b.springs), "{what}: springs");
    assert_eq!(
        bits(&a.wall_springs),
        bits(&b.wall_springs),
        "{what}: wall springs"
    );
    assert_eq!(a.list.builds, b.list.builds, "{what}: list builds");
    assert_eq!(a.contacts, b.contacts, "{what}: contacts");
}

/// The LAMMPS chute (34 656 grains on a frozen rough base, periodic x and
/// y, gravity along the incline) over 1000 steps: several rebuilds, a
/// re-sort every third (into Morton order on the mirror), sliding and
/// sticking contacts.
#[test]
fn chute_1000_steps_same_bits_as_the_cpu_engine() {
    let mut cpu = chute();
    cpu.settings.sort_every = 3;
    let mut mirror = Mirror::from_md(&cpu).unwrap();
    assert_same_bits(&cpu, &mirror, "chute at the start");
    cpu.run(1000).unwrap();
    mirror.advance(1000).unwrap();
    assert!(
        mirror.builds >= 3,
        "{} list builds: the run must cross rebuilds",
        mirror.builds
    );
    assert_stored_in_morton_order(&mirror);
    assert_same_bits(&cpu, &mirror, "chute after 1000 steps");
}

/// The mirror stores its grains in Morton order (not the CPU engine's):
/// most grains sit elsewhere than their rank, and the sort grid's cells
/// of consecutive grains never go back in Morton order.
fn assert_stored_in_morton_order(m: &Mirror) {
    let moved = m
        .rank
        .iter()
        .enumerate()
        .filter(|&(k, &r)| r as usize != k)
        .count();
    assert!(moved > m.len() / 2, "{moved} of {} grains moved", m.len());
    let grid = &m.params.sort_grid;
    let place = |k: usize| m.params.places[grid.cell_of(m.reference.get(k))];
    // The reference positions are those of the last build; the last
    // re-sort may be older, so count the breaks rather than forbid them.
    let breaks = (1..m.len()).filter(|&k| place(k) < place(k - 1)).count();
    assert!(breaks < m.len() / 10, "{breaks} breaks of Morton order");
}

/// The bed with walls in uneven stretches (as hooks would cut a run) and
/// with a re-sort at every rebuild: the same bits as the CPU engine run in
/// one stretch.
#[test]
fn bed_with_walls_same_bits_in_any_stretches() {
    let mut cpu = bed();
    cpu.settings.sort_every = 1;
    let mut mirror = Mirror::from_md(&cpu).unwrap();
    cpu.run(1500).unwrap();
    for n in [1, 7, 492, 1000] {
        mirror.advance(n).unwrap();
    }
    assert!(mirror.builds >= 3, "{} list builds", mirror.builds);
    let walls = (0..mirror.wall_springs.len())
        .filter(|&k| mirror.wall_springs.get(k) != [0.0; 3])
        .count();
    assert!(walls > 10, "{walls} stretched wall springs");
    assert_stored_in_morton_order(&mirror);
    assert_same_bits(&cpu, &mirror, "bed after 1500 steps");
}

/// Stored in the CPU engine's own cell order, the same bits, and every
/// grain at its rank.
#[test]
fn bed_in_the_cpu_engines_order_same_bits() {
    let mut cpu = bed();
    cpu.settings.sort_every = 1;
    let mut mirror = Mirror::from_md_in(&cpu, CellOrder::Cpu).unwrap();
    cpu.run(800).unwrap();
    for n in [300, 500] {
        mirror.advance(n).unwrap();
    }
    assert!(mirror
        .rank
        .iter()
        .enumerate()
        .all(|(k, &r)| r as usize == k));
    assert_same_bits(&cpu, &mirror, "bed in CPU order after 800 steps");
}

/// The device's way through a full list buffer: with no room in either
/// buffer, each first rebuild into a buffer halts the stretch after its
/// wrap and re-sort, the host grows the buffer, and the stretch resumes at
/// the list build. The bed with walls, re-sorted at every rebuild, in
/// uneven stretches: the same bits as the CPU engine, and both buffers
/// grown to hold the list they were refused.
#[test]
fn a_list_that_outgrows_its_buffer_resumes_with_the_same_bits() {
    let mut cpu = bed();
    cpu.settings.sort_every = 1;
    let mut mirror = Mirror::from_md(&cpu).unwrap();
    mirror.capacity = [0, 0];
    cpu.run(1500).unwrap();
    for n in [3, 497, 1000] {
        mirror.advance(n).unwrap();
    }
    assert!(mirror.builds >= 3, "{} list builds", mirror.builds);
    let entries = mirror.list.partner.len();
    for (b, &cap) in mirror.capacity.iter().enumerate() {
        assert!(
            cap >= entries / 2 && cap < 2 * entries + 2048,
            "buffer {b}: {cap} entries for a list of {entries}"
        );
    }
    assert_same_bits(&cpu, &mirror, "bed after 1500 steps through full buffers");
}

/// The step words stop a stretch at the step the CPU engine stops: an
/// overlap beyond the limit halts the device's stretch, and the host
/// reports it at that step.
#[test]
fn an_overlap_beyond_the_limit_stops_at_the_cpu_engines_step() {
    let mut cpu = bed();
    cpu.settings.max_overlap_fraction = 0.002;
    let mut mirror = Mirror::from_md(&cpu).unwrap();
    let a = cpu.run(2000).unwrap_err().to_string();
    let b = mirror.advance(2000).unwrap_err().to_string();
    let at = |e: &str| e.split(" (t =").next().unwrap().to_string();
    assert!(a.contains("overlap"), "{a}");
    assert_eq!(at(&a), at(&b), "CPU: {a}\nmirror: {b}");
    let step: u64 = at(&a).rsplit(' ').next().unwrap().parse().unwrap();
    assert!(step > 100, "{a}: the check should stop a stretch midway");
}

/// A grain whose velocity is not finite stops the stretch at the CPU
/// engine's step: the kick of a checking step flags it, the next step's
/// start halts the stretch, and the host reports the flagged step.
#[test]
fn a_non_finite_grain_stops_at_the_cpu_engines_step() {
    let mut cpu = bed();
    cpu.settings.nan_check_every = 7;
    let mut mirror = Mirror::from_md(&cpu).unwrap();
    cpu.particles.vel[100].x = f64::NAN;
    mirror.vel.x[100] = f64::NAN;
    let a = cpu.run(50).unwrap_err().to_string();
    let b = mirror.advance(50).unwrap_err().to_string();
    let at = |e: &str| e.split(" (t =").next().unwrap().to_string();
    assert!(
        a.contains("non-finite") && b.contains("non-finite"),
        "{a}\n{b}"
    );
    assert_eq!(at(&a), at(&b), "CPU: {a}\nmirror: {b}");
    assert!(at(&a).ends_with("step 7"), "{a}");
}

/// The list build against all pairs and all 27 images: the same set of
/// pairs within r_i + r_j + skin (frozen pairs left out), each in both
/// rows with the lower index's image code, rows in the reduction's order.
#[test]
fn list_build_matches_brute_force() {
    for (md, steps) in [(bed(), 700), (chute(), 300)] {
        let mut m = Mirror::from_md(&md).unwrap();
        m.advance(steps).unwrap();
        m.rebuild();
        let n = m.len();
        // The chute is too large to pair every grain: a window of grains
        // against all others.
        let first = if n > 5000 { 0..500 } else { 0..n };
        let shifts = m.shifts;
        let skin = m.params.skin;
        let mut want: HashMap<(usize, usize), usize> = HashMap::new();
        for i in first.clone() {
            for j in 0..n {
                if i == j || (m.frozen[i] != 0 && m.frozen[j] != 0) {
                    continue;
                }
                // The pair's image code is that of its lower rank's side.
                let (lo, hi) = if m.rank[i] < m.rank[j] {
                    (i, j)
                } else {
                    (j, i)
                };
                for (code, s) in shifts.iter().enumerate() {
                    // Axes that are not periodic have one image only.
                    let digits = [code % 3, code / 3 % 3, code / 9];
                    if (0..3).any(|a| !m.params.bx.periodic[a] && digits[a] != 1) {
                        continue;
                    }
                    let d: V3 = sub(sub(m.pos.get(lo), m.pos.get(hi)), *s);
                    let cut = m.radius[lo] + m.radius[hi] + skin;
                    if dot(d, d) < cut * cut {
                        let old = want.insert((i, j), code);
                        assert!(old.is_none(), "pair {i} {j} within reach twice");
                    }
                }
            }
        }
        let mut got: HashMap<(usize, usize), usize> = HashMap::new();
        let block = m.params.block;
        for i in first {
            let row = m.list.row(i);
            let keys: Vec<_> = row
                .clone()
                .map(|e| {
                    let p = m.list.partner[e] as usize;
                    row_key(m.rank[i] as usize, m.rank[p] as usize, block)
                })
                .collect();
            // Lower partners ascending within their class; higher ones as
            // the stencil met them.
            assert!(
                keys.windows(2).all(|w| w[0] <= w[1]),
                "row {i} out of order"
            );
            for e in row {
                got.insert((i, m.list.partner[e] as usize), m.list.image[e] as usize);
            }
        }
        assert!(want.len() > 1000, "{} pairs", want.len());
        assert_eq!(got, want);
        // Both rows of each pair.
        for g in 0..n {
            for e in m.list.row(g) {
                let p = m.list.partner[e] as usize;
                let back = m.list.row(p).filter(|&k| m.list.partner[k] as usize == g);
                let codes: Vec<u8> = back.map(|k| m.list.image[k]).collect();
                assert_eq!(codes, vec![m.list.image[e]], "pair {g} {p}");
            }
        }
    }
}

/// What the pipeline does not run is refused by name before any step.
#[test]
fn refuses_what_it_does_not_run() {
    let mut md = bed();
    md.settings.integrator = grains::integrate::Integrator::Gear5;
    let e = Mirror::from_md(&md).unwrap_err().to_string();
    assert!(e.contains("run.integrator = \"gear5\""), "{e}");
    let mut md = bed();
    if let grains::contact::Law::SpringDashpot(law) = &mut md.settings.law {
        law.beta = 1.5;
    }
    let e = Mirror::from_md(&md).unwrap_err().to_string();
    assert!(e.contains("Hooke-with-history"), "{e}");
    let mut md = bed();
    md.walls[1] = grains::boundary::Wall::new(
        "post",
        grains::boundary::Shape::Obstacle {
            center: glam::DVec3::new(8.0, 9.0, 2.0),
            diameter: 2.0,
        },
        Default::default(),
    )
    .unwrap();
    let e = Mirror::from_md(&md).unwrap_err().to_string();
    assert!(e.contains("wall 'post' (shape obstacle)"), "{e}");
}

/// `run.device = "gpu"` is checked before the run: refused naming the
/// feature in a build without it, naming what the GPU engine does not run
/// with it.
#[test]
fn scenario_device_gpu_is_refused_by_name() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-chute.toml");
    let sets = ["run.device=gpu".to_string()];
    let loaded = load_file(&path, &sets).unwrap();
    let checked = grains::scenario::device::check_device(&loaded);
    if cfg!(feature = "cuda") {
        assert!(checked.is_ok(), "{checked:?}");
        let sets = [
            "run.device=gpu".to_string(),
            "run.integrator=gear5".to_string(),
        ];
        let loaded = load_file(&path, &sets).unwrap();
        let e = grains::scenario::device::check_device(&loaded)
            .unwrap_err()
            .to_string();
        assert!(e.contains("run.integrator = \"gear5\""), "{e}");
    } else {
        let e = checked.unwrap_err().to_string();
        assert!(e.contains("--features cuda"), "{e}");
    }
    let plain = load_file(&path, &[]).unwrap();
    assert!(grains::scenario::device::check_device(&plain).is_ok());
    let sets = [
        "run.device=mirror".to_string(),
        "run.gpu_fma=true".to_string(),
    ];
    let e = grains::scenario::device::check_device(&load_file(&path, &sets).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("run.gpu_fma"), "{e}");
    let bad = load_file(&path, &["run.device=tpu".to_string()]);
    let e = match bad {
        Ok(_) => panic!("device tpu accepted"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("gpu"), "{e}");
}
