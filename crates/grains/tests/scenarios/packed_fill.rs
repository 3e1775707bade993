//! `particles.placement = "packed"`: a region filled to a target packing
//! fraction. Measured here from the built engine's positions and radii,
//! not from the fill's own numbers: every grain inside the region (a
//! radius from its walled faces), the packing fraction Σ V_grain / V_region
//! within 0.005 of the target (the count is whole grains: half a grain's
//! volume is 3e-4 of these regions), no pair overlapping by more than
//! `packed::FINAL_OVERLAP` of its smaller diameter (pairs checked all
//! against all, periodic images included), the diameters those of the
//! random placement of as many grains (the same stream), and the same bits
//! on 1 and 2 threads. Packings beyond random close packing are refused by
//! name.

use grains::dim::{Dim, D2, D3};
use grains::md::Md;
use grains::scenario::packed::FINAL_OVERLAP;
use grains::scenario::{build_md, load_str, Loaded};
use std::path::PathBuf;

/// A 3D box periodic in x and y, floor and lid at the region's faces
/// (z = 0 and 10 mm), lognormal beads about 1 mm.
const BOX_3D: &str = r#"name = "packed-3d"
dimension = "3d"
seed = 23
[domain]
lo = [0.0, 0.0, -0.001]
hi = [0.01, 0.01, 0.03]
periodic = [true, true, false]
[particles]
placement = "packed"
packing = 0.60
region = { lo = [0.0, 0.0, 0.0], hi = [0.01, 0.01, 0.01] }
size = { distribution = "lognormal", mean = 1.0e-3, std = 1.0e-4, min = 0.8e-3, max = 1.3e-3 }
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-6
duration = 1.0e-5
"#;

/// A 2D box walled all round, disks of 0.85–1.15 mm.
const BOX_2D: &str = r#"name = "packed-2d"
dimension = "2d"
seed = 29
[domain]
lo = [0.0, 0.0]
hi = [0.03, 0.03]
[particles]
placement = "packed"
packing = 0.80
d0 = 1.0e-3
width = 0.3
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-6
duration = 1.0e-5
"#;

fn load(text: &str, sets: &[&str]) -> Loaded {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_str(text, "packed.toml", PathBuf::from("."), &sets).unwrap()
}

/// The region, the axes that wrap, and the target.
struct Fill<D: Dim> {
    lo: D::V,
    hi: D::V,
    wraps: [bool; 3],
    packing: f64,
}

/// Checks the fill of `md` against `f`; returns the packing measured.
fn check<D: Dim>(md: &Md<D>, f: &Fill<D>) -> f64 {
    let p = &md.particles;
    let n = p.n_owned();
    let mut volume = 1.0;
    for a in 0..D::D {
        volume *= D::get(f.hi, a) - D::get(f.lo, a);
    }
    let mut solid = 0.0;
    for i in 0..n {
        let (x, r) = (p.pos[i], p.radius[i]);
        solid += if D::D == 2 {
            std::f64::consts::PI * r * r
        } else {
            4.0 / 3.0 * std::f64::consts::PI * r * r * r
        };
        for a in 0..D::D {
            let v = D::get(x, a);
            let (lo, hi) = (D::get(f.lo, a), D::get(f.hi, a));
            let inside = if f.wraps[a] {
                v >= lo && v < hi
            } else {
                v - r >= lo - 1e-12 * r && v + r <= hi + 1e-12 * r
            };
            assert!(inside, "grain {} at {v} (r {r}) outside axis {a}", p.id[i]);
        }
    }
    let phi = solid / volume;
    let mut worst: f64 = 0.0;
    for i in 0..n {
        for j in i + 1..n {
            let mut d2 = 0.0;
            for a in 0..D::D {
                let mut d = D::get(p.pos[i], a) - D::get(p.pos[j], a);
                if f.wraps[a] {
                    let l = D::get(f.hi, a) - D::get(f.lo, a);
                    d -= l * (d / l).round();
                }
                d2 += d * d;
            }
            let overlap = p.radius[i] + p.radius[j] - d2.sqrt();
            worst = worst.max(overlap / (2.0 * p.radius[i].min(p.radius[j])));
        }
    }
    println!(
        "{} grains: packing {phi:.5} (target {}), largest overlap {worst:.2e} of d",
        n, f.packing
    );
    assert!(
        (phi - f.packing).abs() < 0.005,
        "packing {phi}, target {}",
        f.packing
    );
    assert!(
        worst <= FINAL_OVERLAP,
        "an overlap of {worst:e} of d (at most {FINAL_OVERLAP:e})"
    );
    phi
}

/// Radii in id order, as bits.
fn radii<D: Dim>(md: &Md<D>) -> Vec<(u64, u64)> {
    let p = &md.particles;
    let mut v: Vec<_> = (0..p.n_owned())
        .map(|i| (p.id[i], p.radius[i].to_bits()))
        .collect();
    v.sort_unstable();
    v
}

fn bits<D: Dim>(loaded: &Loaded, threads: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let (md, _) = build_md::<D>(loaded).unwrap();
        let p = &md.particles;
        let mut out = Vec::new();
        for i in 0..p.n_owned() {
            out.push(p.id[i]);
            out.extend((0..D::D).map(|a| D::get(p.pos[i], a).to_bits()));
        }
        out
    })
}

#[test]
fn a_3d_box_is_packed_to_0_60() {
    let loaded = load(BOX_3D, &[]);
    let (md, _) = build_md::<D3>(&loaded).unwrap();
    let f = Fill::<D3> {
        lo: [0.0, 0.0, 0.0].into(),
        hi: [0.01, 0.01, 0.01].into(),
        wraps: [true, true, false],
        packing: 0.60,
    };
    check(&md, &f);
    // The random placement of as many grains (in a taller region) draws
    // the same diameters.
    let n = md.particles.n_owned();
    let count = format!("particles.count={n}");
    let random = BOX_3D.replace(
        "placement = \"packed\"\npacking = 0.60",
        "placement = \"random\"",
    );
    let random = load(&random, &[&count, "particles.region.hi=[0.01, 0.01, 0.03]"]);
    let (r, _) = build_md::<D3>(&random).unwrap();
    assert!(radii(&md) == radii(&r), "the packed fill changed the sizes");
    assert!(bits::<D3>(&loaded, 1) == bits::<D3>(&loaded, 2));
}

#[test]
fn a_walled_2d_box_is_packed_to_0_80() {
    let loaded = load(BOX_2D, &[]);
    let (md, _) = build_md::<D2>(&loaded).unwrap();
    let f = Fill::<D2> {
        lo: [0.0, 0.0].into(),
        hi: [0.03, 0.03].into(),
        wraps: [false; 3],
        packing: 0.80,
    };
    check(&md, &f);
    let n = md.particles.n_owned();
    let count = format!("particles.count={n}");
    let random = BOX_2D.replace(
        "placement = \"packed\"\npacking = 0.80",
        "placement = \"random\"",
    );
    let random = load(&random, &[&count, "domain.hi=[0.06, 0.06]"]);
    let (r, _) = build_md::<D2>(&random).unwrap();
    assert!(radii(&md) == radii(&r), "the packed fill changed the sizes");
    assert!(bits::<D2>(&loaded, 1) == bits::<D2>(&loaded, 2));
}

#[test]
fn packings_beyond_random_close_packing_are_refused() {
    let error = |text: &str, sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        match load_str(text, "packed.toml", PathBuf::from("."), &sets) {
            Err(e) => e.to_string(),
            Ok(l) => match build_md::<D3>(&l) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("accepted {sets:?}"),
            },
        }
    };
    let e = error(BOX_3D, &["particles.packing=0.7"]);
    assert!(
        e.contains("particles.packing = 0.7") && e.contains("0.64"),
        "{e}"
    );
    let e = error(BOX_3D, &["particles.count=100"]);
    assert!(
        e.contains("particles.count = 100") && e.contains("packed"),
        "{e}"
    );
    let no_packing = BOX_3D.replace("packing = 0.60\n", "");
    let e = error(&no_packing, &[]);
    assert!(e.contains("particles.packing"), "{e}");
}
