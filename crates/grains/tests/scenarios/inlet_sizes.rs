//! The diameters an inlet draws follow its `size` law: 10^4 grains
//! inserted by one inlet, their diameters against the law's CDF written
//! here from its closed form (or, for laws by mass, the number density
//! w(d) d^−3 integrated here on a fine grid), by the Kolmogorov–Smirnov
//! test at the 1 % level: sup |F_n − F| < 1.628/√n (Kolmogorov's
//! asymptotic quantile, Smirnov 1948 table). Discrete classes by Pearson's
//! chi-square at 1 % (2 degrees of freedom: 9.210).

use crate::common::normal::phi_cdf;
use grains::dim::D3;
use grains::scenario::flow::FlowRun;
use grains::scenario::{build_md, load_str};
use std::path::Path;

const N: usize = 10_000;

fn drawn(size: &str) -> Vec<f64> {
    let text = format!(
        r#"name = "inlet-sizes"
dimension = "3d"
seed = 11
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.12, 0.12, 0.12]
[particles]
placement = "none"
d0 = 1.0e-3
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-5
duration = 1.0e-3
[[inlets]]
region = {{ shape = "box", lo = [0.0, 0.0, 0.0], hi = [0.12, 0.12, 0.12] }}
count = {N}
size = {size}
"#
    );
    let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    let loaded = load_str(&text, "inlet-sizes.toml", scenarios, &[]).unwrap();
    let (mut md, _) = build_md::<D3>(&loaded).unwrap();
    let mut flow = FlowRun::begin(&loaded, &md).unwrap();
    flow.after_step(&mut md);
    let p = &md.particles;
    assert_eq!(p.n_owned(), N, "every grain found room");
    p.radius.iter().map(|r| 2.0 * r).collect()
}

/// sup |F_n − F| of the sample `d` against the CDF `f`.
fn ks(mut d: Vec<f64>, f: impl Fn(f64) -> f64) -> f64 {
    d.sort_by(f64::total_cmp);
    let n = d.len() as f64;
    d.iter()
        .enumerate()
        .map(|(i, &x)| {
            let fx = f(x);
            (fx - i as f64 / n).max((i + 1) as f64 / n - fx)
        })
        .fold(0.0, f64::max)
}

fn passes_ks(what: &str, d: Vec<f64>, f: impl Fn(f64) -> f64) {
    let n = d.len() as f64;
    let stat = ks(d, f);
    let critical = 1.628 / n.sqrt();
    eprintln!("{what}: KS {stat:.4} (1 % critical {critical:.4})");
    assert!(
        stat < critical,
        "{what}: KS statistic {stat:.4} above the 1 % critical value {critical:.4}"
    );
}

/// The CDF of the density `w` (unnormalised) on [a, b]: the trapezoid
/// rule on 2·10^5 cells (its error, a few 1e-10 on smooth densities and
/// h·jump at a sieve's kinks, is far below the KS threshold 0.016).
fn numeric_cdf(a: f64, b: f64, w: impl Fn(f64) -> f64) -> impl Fn(f64) -> f64 {
    let cells = 200_000;
    let h = (b - a) / cells as f64;
    let mut cum = vec![0.0; cells + 1];
    for k in 0..cells {
        let (x0, x1) = (a + k as f64 * h, a + (k + 1) as f64 * h);
        cum[k + 1] = cum[k] + 0.5 * h * (w(x0) + w(x1));
    }
    let total = cum[cells];
    move |d: f64| {
        let s = ((d - a) / h).clamp(0.0, cells as f64);
        let k = (s.floor() as usize).min(cells - 1);
        let frac = s - k as f64;
        (cum[k] + frac * (cum[k + 1] - cum[k])) / total
    }
}

#[test]
fn uniform_by_number_and_by_mass() {
    let (a, b): (f64, f64) = (0.8e-3, 1.2e-3);
    let d = drawn(&format!(
        "{{ distribution = \"uniform\", min = {a:e}, max = {b:e} }}"
    ));
    passes_ks("uniform by number", d, |x| (x - a) / (b - a));
    // By mass: the number density ∝ d^−3, F = (a^−2 − d^−2)/(a^−2 − b^−2).
    let (a, b): (f64, f64) = (0.5e-3, 1.5e-3);
    let d = drawn(&format!(
        "{{ distribution = \"uniform\", weight = \"mass\", min = {a:e}, max = {b:e} }}"
    ));
    let f = |x: f64| (a.powi(-2) - x.powi(-2)) / (a.powi(-2) - b.powi(-2));
    passes_ks("uniform by mass", d, f);
}

#[test]
fn normal_by_number_and_by_mass() {
    let (m, s, a, b): (f64, f64, f64, f64) = (1.0e-3, 0.2e-3, 0.6e-3, 1.6e-3);
    let spec = |w: &str| {
        format!(
            "{{ distribution = \"normal\", weight = \"{w}\", mean = {m:e}, std = {s:e}, \
             min = {a:e}, max = {b:e} }}"
        )
    };
    let z = |x: f64| phi_cdf((x - m) / s);
    passes_ks("normal by number", drawn(&spec("number")), |x| {
        (z(x) - z(a)) / (z(b) - z(a))
    });
    let f = numeric_cdf(a, b, |x| (-0.5 * ((x - m) / s).powi(2)).exp() * x.powi(-3));
    passes_ks("normal by mass", drawn(&spec("mass")), f);
}

#[test]
fn truncated_lognormal_by_number_and_by_mass() {
    // Mean m and deviation s of d: ln d ~ N(μ, σ²) with σ² = ln(1 + s²/m²),
    // μ = ln m − σ²/2 (the lognormal's moments).
    let (m, s, a, b): (f64, f64, f64, f64) = (1.0e-3, 0.3e-3, 0.5e-3, 2.5e-3);
    let sigma = (1.0 + (s / m).powi(2)).ln().sqrt();
    let mu = m.ln() - 0.5 * sigma * sigma;
    let spec = |w: &str| {
        format!(
            "{{ distribution = \"lognormal\", weight = \"{w}\", mean = {m:e}, std = {s:e}, \
             min = {a:e}, max = {b:e} }}"
        )
    };
    let z = |x: f64| phi_cdf((x.ln() - mu) / sigma);
    passes_ks("lognormal by number", drawn(&spec("number")), |x| {
        (z(x) - z(a)) / (z(b) - z(a))
    });
    // By mass: the lognormal density of the mass share times d^−3.
    let pdf = |x: f64| (-0.5 * ((x.ln() - mu) / sigma).powi(2)).exp() / x;
    let f = numeric_cdf(a, b, |x| pdf(x) * x.powi(-3));
    passes_ks("lognormal by mass", drawn(&spec("mass")), f);
}

/// The sieve curve of scenarios/sieve-glass.csv: (opening m, % passing).
const SIEVE: [(f64, f64); 7] = [
    (0.0005, 0.0),
    (0.0006, 5.0),
    (0.0008, 20.0),
    (0.0010, 45.0),
    (0.00125, 70.0),
    (0.0016, 90.0),
    (0.0020, 100.0),
];

/// The curve's share (0–1) passing `d`, interpolated linearly.
fn passing(d: f64) -> f64 {
    for w in SIEVE.windows(2) {
        let ((x0, p0), (x1, p1)) = (w[0], w[1]);
        if d <= x1 {
            return (p0 + (p1 - p0) * ((d - x0) / (x1 - x0)).clamp(0.0, 1.0)) / 100.0;
        }
    }
    1.0
}

/// The curve's density: the share of each interval spread evenly.
fn sieve_density(d: f64) -> f64 {
    for w in SIEVE.windows(2) {
        let ((x0, p0), (x1, p1)) = (w[0], w[1]);
        if d <= x1 {
            return (p1 - p0) / (x1 - x0);
        }
    }
    0.0
}

#[test]
fn sieve_curve_by_mass_and_by_number() {
    let (a, b) = (SIEVE[0].0, SIEVE[6].0);
    let d = drawn("{ distribution = \"sieve\", file = \"sieve-glass.csv\" }");
    let f = numeric_cdf(a, b, |x| sieve_density(x) * x.powi(-3));
    passes_ks("sieve by mass", d, f);
    let d = drawn("{ distribution = \"sieve\", weight = \"number\", file = \"sieve-glass.csv\" }");
    passes_ks("sieve by number", d, passing);
}

#[test]
fn discrete_classes_by_number_and_by_mass() {
    let classes: [(f64, f64); 3] = [(0.8e-3, 0.2), (1.0e-3, 0.5), (1.3e-3, 0.3)];
    let table = "[[0.8e-3, 0.2], [1.0e-3, 0.5], [1.3e-3, 0.3]]";
    for weight in ["number", "mass"] {
        let d = drawn(&format!(
            "{{ distribution = \"discrete\", weight = \"{weight}\", classes = {table} }}"
        ));
        // By mass, class i holds the share p_i d_i^−3 of the grains.
        let w: Vec<f64> = classes
            .iter()
            .map(|&(di, p)| if weight == "mass" { p * di.powi(-3) } else { p })
            .collect();
        let total: f64 = w.iter().sum();
        let mut chi2 = 0.0;
        for (&(di, _), wi) in classes.iter().zip(&w) {
            let seen = d.iter().filter(|&&x| (x - di).abs() < 1e-12).count() as f64;
            let want = N as f64 * wi / total;
            chi2 += (seen - want).powi(2) / want;
        }
        assert!(
            d.iter()
                .all(|x| classes.iter().any(|c| (x - c.0).abs() < 1e-12)),
            "a diameter outside the classes"
        );
        eprintln!("discrete by {weight}: chi-square {chi2:.2} (1 % critical 9.210)");
        assert!(
            chi2 < 9.210,
            "discrete by {weight}: chi-square {chi2:.2} >= 9.210"
        );
    }
}
