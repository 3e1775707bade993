//! `particles.size`: drawn diameters against the closed forms of their
//! laws, by number and by mass, tables recovered by count, a sieve curve
//! recovered by mass, the same bits on 1 and 2 threads, the old band's
//! bits, what `grains check` prints, and bad input named by key.
//!
//! Tolerances are 5 standard errors of the estimate from the sample size:
//! σ/√N for a mean, √((μ₄ − σ⁴)/N) for a variance, √(p(1 − p)/N) for a
//! fraction counted (binomial), and the delta method for the ratios that
//! weight by mass (Σ X / Σ Y: Var(X − R Y) / (N E[Y]²)).

use crate::common::normal::phi_cdf;
use grains::dim::D3;
use grains::particles::MassModel;
use grains::scenario::schema::SizeSpec;
use grains::scenario::sizes::SizeLaw;
use grains::scenario::{build_md, load_str, Loaded};
use std::path::{Path, PathBuf};

const N: usize = 40_000;

fn phi_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// E[dⁿ] of ln d ~ N(μ, σ²) cut to [a, b] (Johnson, Kotz & Balakrishnan,
/// Continuous Univariate Distributions, ch. 14: the moments of a truncated
/// lognormal).
fn lognormal_moment(n: f64, mu: f64, sigma: f64, a: f64, b: f64) -> f64 {
    let z = |x: f64, shift: f64| (x.ln() - mu - shift) / sigma;
    let kept = phi_cdf(z(b, 0.0)) - phi_cdf(z(a, 0.0));
    let shifted = phi_cdf(z(b, n * sigma * sigma)) - phi_cdf(z(a, n * sigma * sigma));
    (n * mu + 0.5 * n * n * sigma * sigma).exp() * shifted / kept
}

/// Mean and variance of N(m, s²) cut to [a, b] (Johnson, Kotz &
/// Balakrishnan, ch. 13, the truncated normal).
fn truncated_normal(m: f64, s: f64, a: f64, b: f64) -> (f64, f64) {
    let (al, be) = ((a - m) / s, (b - m) / s);
    let z = phi_cdf(be) - phi_cdf(al);
    let r = (phi_pdf(al) - phi_pdf(be)) / z;
    let mean = m + s * r;
    let var = s * s * (1.0 + (al * phi_pdf(al) - be * phi_pdf(be)) / z - r * r);
    (mean, var)
}

fn law(text: &str, model: MassModel) -> SizeLaw {
    law_in(text, model, Path::new("."))
}

fn law_in(text: &str, model: MassModel, base: &Path) -> SizeLaw {
    let spec: SizeSpec = toml::from_str(text).unwrap();
    SizeLaw::new(&spec, model, base).unwrap()
}

fn sample_mean_var(d: &[f64]) -> (f64, f64, f64) {
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let m4 = d.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n;
    (mean, var, m4)
}

/// Σ xᵢ / Σ yᵢ with its standard error (delta method).
fn ratio(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let r = x.iter().sum::<f64>() / y.iter().sum::<f64>();
    let ybar = y.iter().sum::<f64>() / n;
    let var = x
        .iter()
        .zip(y)
        .map(|(a, b)| (a - r * b).powi(2))
        .sum::<f64>()
        / n;
    (r, (var / n).sqrt() / ybar)
}

fn within(what: &str, got: f64, want: f64, se: f64) {
    assert!(
        (got - want).abs() <= 5.0 * se,
        "{what}: drawn {got:e}, closed form {want:e}, 5 standard errors {:e}",
        5.0 * se
    );
}

/// Lognormal by number: mean exp(μ + σ²/2) and the variance of the law
/// cut to [min, max].
#[test]
fn lognormal_by_number_has_its_moments() {
    let (m, s, a, b): (f64, f64, f64, f64) = (1.0e-3, 0.3e-3, 0.3e-3, 3.0e-3);
    let l = law(
        &format!(
            "distribution = \"lognormal\"\nmean = {m:e}\nstd = {s:e}\nmin = {a:e}\nmax = {b:e}"
        ),
        MassModel::Sphere,
    );
    let d = l.draw(N, 7).unwrap();
    assert!(d.iter().all(|&x| (a..=b).contains(&x)));
    let sigma = (1.0 + (s / m).powi(2)).ln().sqrt();
    let mu = m.ln() - 0.5 * sigma * sigma;
    let e: Vec<f64> = (1..=4)
        .map(|n| lognormal_moment(n as f64, mu, sigma, a, b))
        .collect();
    let mean = e[0];
    let var = e[1] - mean * mean;
    let mu4 = e[3] - 4.0 * e[2] * mean + 6.0 * e[1] * mean * mean - 3.0 * mean.powi(4);
    let (got_mean, got_var, _) = sample_mean_var(&d);
    within("lognormal mean", got_mean, mean, (var / N as f64).sqrt());
    within(
        "lognormal variance",
        got_var,
        var,
        ((mu4 - var * var) / N as f64).sqrt(),
    );
    // The untruncated mean is the one asked for: the cut is small here.
    assert!((mean / m - 1.0).abs() < 2e-3, "{mean}");
}

/// Normal by number, cut hard on both sides: the truncated normal's mean
/// and variance.
#[test]
fn truncated_normal_by_number_has_its_moments() {
    let (m, s, a, b): (f64, f64, f64, f64) = (1.0e-3, 0.5e-3, 0.4e-3, 2.0e-3);
    let l = law(
        &format!("distribution = \"normal\"\nmean = {m:e}\nstd = {s:e}\nmin = {a:e}\nmax = {b:e}"),
        MassModel::Sphere,
    );
    let d = l.draw(N, 11).unwrap();
    let (mean, var) = truncated_normal(m, s, a, b);
    let (got_mean, got_var, m4) = sample_mean_var(&d);
    within("normal mean", got_mean, mean, (var / N as f64).sqrt());
    within(
        "normal variance",
        got_var,
        var,
        ((m4 - got_var * got_var) / N as f64).sqrt(),
    );
}

/// By mass, the mass-weighted mean diameter Σd^(k+1)/Σd^k of the drawn
/// grains is the mean of the law given: lognormal (μ shifted by −3σ²),
/// normal of disks (k = 2, rejection) and uniform (piecewise inverse).
#[test]
fn mass_weighted_mean_of_a_draw_by_mass() {
    // Lognormal of spheres.
    let (m, s, a, b): (f64, f64, f64, f64) = (1.0e-3, 0.4e-3, 0.25e-3, 4.0e-3);
    let l = law(
        &format!(
            "distribution = \"lognormal\"\nweight = \"mass\"\nmean = {m:e}\nstd = {s:e}\nmin = {a:e}\nmax = {b:e}"
        ),
        MassModel::Sphere,
    );
    let d = l.draw(N, 3).unwrap();
    let sigma = (1.0 + (s / m).powi(2)).ln().sqrt();
    let mu_mass = m.ln() - 0.5 * sigma * sigma;
    let want = lognormal_moment(1.0, mu_mass, sigma, a, b);
    let x: Vec<f64> = d.iter().map(|v| v.powi(4)).collect();
    let y: Vec<f64> = d.iter().map(|v| v.powi(3)).collect();
    let (got, se) = ratio(&x, &y);
    within("lognormal by mass, mass-weighted mean", got, want, se);
    // The number mean sits well below: the draw is not the mass law itself.
    let number_mean = d.iter().sum::<f64>() / N as f64;
    assert!(number_mean < 0.8 * want, "{number_mean} vs {want}");

    // Normal of disks (mass ∝ d²).
    let (m, s, a, b): (f64, f64, f64, f64) = (1.0e-3, 0.4e-3, 0.3e-3, 2.0e-3);
    let l = law(
        &format!(
            "distribution = \"normal\"\nweight = \"mass\"\nmean = {m:e}\nstd = {s:e}\nmin = {a:e}\nmax = {b:e}"
        ),
        MassModel::Disk,
    );
    let d = l.draw(N, 5).unwrap();
    let (want, _) = truncated_normal(m, s, a, b);
    let x: Vec<f64> = d.iter().map(|v| v.powi(3)).collect();
    let y: Vec<f64> = d.iter().map(|v| v.powi(2)).collect();
    let (got, se) = ratio(&x, &y);
    within("normal of disks by mass, mass-weighted mean", got, want, se);

    // Uniform by mass: the mass-weighted mean is the middle of the band.
    let (a, b) = (0.5e-3, 2.5e-3);
    let l = law(
        &format!("distribution = \"uniform\"\nweight = \"mass\"\nmin = {a:e}\nmax = {b:e}"),
        MassModel::Sphere,
    );
    let d = l.draw(N, 9).unwrap();
    let x: Vec<f64> = d.iter().map(|v| v.powi(4)).collect();
    let y: Vec<f64> = d.iter().map(|v| v.powi(3)).collect();
    let (got, se) = ratio(&x, &y);
    within(
        "uniform by mass, mass-weighted mean",
        got,
        0.5 * (a + b),
        se,
    );
}

/// A discrete table: class counts by number, and by mass the number
/// shares p_i d_i⁻³ / Σ, each within its binomial bound.
#[test]
fn discrete_fractions_recovered_by_count() {
    let table = [(1.0e-3, 0.5), (2.0e-3, 0.3), (3.0e-3, 0.2)];
    let rows: Vec<String> = table.iter().map(|(d, f)| format!("[{d:e}, {f}]")).collect();
    for by_mass in [false, true] {
        let weight = if by_mass { "mass" } else { "number" };
        let l = law(
            &format!(
                "distribution = \"discrete\"\nweight = \"{weight}\"\nclasses = [{}]",
                rows.join(", ")
            ),
            MassModel::Sphere,
        );
        let d = l.draw(N, 13).unwrap();
        let w: Vec<f64> = table
            .iter()
            .map(|&(d, f)| if by_mass { f / (d * d * d) } else { f })
            .collect();
        let total: f64 = w.iter().sum();
        for (&(size, _), wi) in table.iter().zip(&w) {
            let p = wi / total;
            let count = d.iter().filter(|&&x| x == size).count() as f64;
            let bound = 5.0 * (N as f64 * p * (1.0 - p)).sqrt();
            assert!(
                (count - N as f64 * p).abs() <= bound,
                "{weight}: class {size}: {count} grains, expected {} ± {bound}",
                N as f64 * p
            );
        }
        assert_eq!(
            d.iter()
                .filter(|x| !table.iter().any(|c| c.0 == **x))
                .count(),
            0
        );
    }
}

/// A sieve curve by mass: the drawn grains' cumulative mass fraction at
/// each sieve reproduces the CSV's % passing.
#[test]
fn sieve_curve_recovered_by_mass() {
    let dir = std::env::temp_dir().join(format!("grains-sieve-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let curve = [
        (0.5e-3, 0.0),
        (0.8e-3, 10.0),
        (1.0e-3, 35.0),
        (1.25e-3, 70.0),
        (1.6e-3, 92.0),
        (2.0e-3, 100.0),
    ];
    let mut csv = String::from("diameter_m,passing_percent\n");
    for (d, c) in curve {
        csv.push_str(&format!("{d:e},{c}\n"));
    }
    std::fs::write(dir.join("curve.csv"), csv).unwrap();
    let l = law_in(
        "distribution = \"sieve\"\nfile = \"curve.csv\"",
        MassModel::Sphere,
        &dir,
    );
    assert!(l.by_mass());
    let d = l.draw(N, 17).unwrap();
    let y: Vec<f64> = d.iter().map(|v| v.powi(3)).collect();
    for &(sieve, passing) in &curve[1..curve.len() - 1] {
        let x: Vec<f64> = d
            .iter()
            .map(|&v| if v < sieve { v.powi(3) } else { 0.0 })
            .collect();
        let (got, se) = ratio(&x, &y);
        within(
            &format!("mass passing {sieve:e} m"),
            got,
            passing / 100.0,
            se,
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

const BASE: &str = r#"name = "sizes"
dimension = "3d"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.03, 0.03, 0.03]
[particles]
placement = "random"
count = 300
random_velocity = 0.05
[contact]
preset = "lammps-hooke-history"
[run]
dt = 1.0e-6
duration = 1.0e-4
"#;

/// BASE with `particles` added to its `[particles]` table (a `placement`
/// there replaces the random one).
fn scenario(particles: &str) -> Result<Loaded, String> {
    let base = if particles.contains("placement") {
        BASE.replace("placement = \"random\"\n", "")
    } else {
        BASE.to_string()
    };
    let text = base.replace("count = 300\n", &format!("count = 300\n{particles}\n"));
    load_str(&text, "sizes.toml", PathBuf::from("."), &[]).map_err(|e| e.to_string())
}

fn radii_and_positions(loaded: &Loaded, threads: usize) -> (Vec<f64>, Vec<[f64; 3]>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let (mut md, _) = build_md::<D3>(loaded).unwrap();
        md.run(20).unwrap();
        let p = &md.particles;
        (
            p.radius.clone(),
            p.pos.iter().map(|v| v.to_array()).collect(),
        )
    })
}

/// A lognormal mix placed at random, then 20 steps: the same bits on one
/// and on two threads.
#[test]
fn same_bits_on_one_and_two_threads() {
    let loaded = scenario(
        "size = { distribution = \"lognormal\", weight = \"mass\", mean = 1.0e-3, std = 0.4e-3, min = 0.4e-3, max = 2.0e-3 }",
    )
    .unwrap();
    let one = radii_and_positions(&loaded, 1);
    let two = radii_and_positions(&loaded, 2);
    assert_eq!(
        one.0.iter().map(|r| r.to_bits()).collect::<Vec<_>>(),
        two.0.iter().map(|r| r.to_bits()).collect::<Vec<_>>()
    );
    assert_eq!(one.1, two.1);
    assert!(one.0.iter().any(|&r| r < 0.45e-3) && one.0.iter().any(|&r| r > 0.6e-3));
}

/// The band written the old way (d0, width) and as a uniform law by number
/// with the band's bounds give the same grains, bit for bit, on a lattice.
#[test]
fn uniform_law_gives_the_bands_bits() {
    let band = grains::particles::SizeBand {
        d0: 1.0e-3,
        width: 0.4,
    };
    let old = scenario("placement = \"lattice\"\nd0 = 1.0e-3\nwidth = 0.4").unwrap();
    let new = scenario(&format!(
        "placement = \"lattice\"\nd0 = 1.0e-3\nsize = {{ distribution = \"uniform\", min = {:?}, max = {:?} }}",
        band.min(),
        band.max()
    ))
    .unwrap();
    assert_eq!(radii_and_positions(&old, 1), radii_and_positions(&new, 1));
}

/// `grains check` prints the law's means and quantiles: for the uniform band
/// by number on [a, b], the number mean and d50 are (a + b)/2 and the mass
/// mean ∫d⁴/∫d³ = 4/5 (b⁵ − a⁵)/(b⁴ − a⁴). Without d0, d0 is the number
/// mean of the law (a truncated lognormal's, in closed form).
#[test]
fn check_prints_the_distribution() {
    let (a, b) = (0.8e-3, 1.2e-3);
    let loaded = scenario("d0 = 1.0e-3\nwidth = 0.4").unwrap();
    let v = grains::runner::check(&loaded).unwrap();
    let s = &v["sizes"]["summary"];
    let close = |x: &serde_json::Value, want: f64| {
        let x = x.as_f64().unwrap();
        assert!((x / want - 1.0).abs() < 1e-6, "{x} vs {want}");
    };
    close(&s["number"]["mean"], 0.5 * (a + b));
    close(&s["number"]["d50"], 0.5 * (a + b));
    close(&s["number"]["d10"], a + 0.1 * (b - a));
    close(
        &s["mass"]["mean"],
        0.8 * (b.powi(5) - a.powi(5)) / (b.powi(4) - a.powi(4)),
    );
    close(&s["max_over_min"], b / a);

    let (m, sd, lo, hi): (f64, f64, f64, f64) = (1.0e-3, 0.3e-3, 0.4e-3, 3.0e-3);
    let loaded = scenario(&format!(
        "size = {{ distribution = \"lognormal\", mean = {m:e}, std = {sd:e}, min = {lo:e}, max = {hi:e} }}"
    ))
    .unwrap();
    let sigma = (1.0 + (sd / m).powi(2)).ln().sqrt();
    let mu = m.ln() - 0.5 * sigma * sigma;
    let want = lognormal_moment(1.0, mu, sigma, lo, hi);
    let d0 = loaded.scenario.particles.d0;
    assert!((d0 / want - 1.0).abs() < 1e-5, "d0 {d0} vs {want}");
    let v = grains::runner::check(&loaded).unwrap();
    assert_eq!(v["sizes"]["weight"], "number");
    // Median of the (nearly uncut) lognormal: exp(μ).
    let d50 = v["sizes"]["summary"]["number"]["d50"].as_f64().unwrap();
    assert!((d50 / mu.exp() - 1.0).abs() < 1e-3, "{d50} vs {}", mu.exp());
}

/// Bad input names the key and what is allowed.
#[test]
fn bad_sizes_are_named() {
    let err = |p: &str| -> String {
        match scenario(p) {
            Err(e) => e,
            Ok(l) => match build_md::<D3>(&l) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("accepted: {p}"),
            },
        }
    };
    let e = err("size = { distribution = \"discrete\", classes = [[1.0e-3, 0.5], [2.0e-3, 0.4]] }");
    assert!(
        e.contains("particles.size.classes") && e.contains("sum to 0.9"),
        "{e}"
    );
    // One class: its size is both bounds once the scenario is read.
    let one =
        scenario("size = { distribution = \"discrete\", classes = [[1.5e-3, 1.0]] }").unwrap();
    let (radii, _) = radii_and_positions(&one, 1);
    assert!(radii.iter().all(|&r| r == 0.75e-3));
    let e = err("size = { distribution = \"uniform\", min = 2.0e-3, max = 1.0e-3 }");
    assert!(
        e.contains("particles.size") && e.contains("must be below max"),
        "{e}"
    );
    let e = err("size = { distribution = \"uniform\", min = -1.0e-3, max = 1.0e-3 }");
    assert!(
        e.contains("particles.size.min = -0.001") && e.contains("positive"),
        "{e}"
    );
    let e = err("size = { distribution = \"normal\", mean = 1.0e-3, min = 0.5e-3, max = 2.0e-3 }");
    assert!(e.contains("particles.size.std is required"), "{e}");
    let e = err("size = { distribution = \"uniform\", min = 0.1e-3, max = 3.0e-3 }");
    assert!(
        e.contains("30.0 times the smallest") && e.contains("at most 20"),
        "{e}"
    );
    let e = err("size = { distribution = \"gamma\", min = 0.1e-3, max = 3.0e-3 }");
    assert!(
        e.contains("uniform") && e.contains("sieve") && e.contains("gamma"),
        "{e}"
    );
    let e = err("size = { distribution = \"uniform\", min = 1.0e-3, max = 2.0e-3, classes = [] }");
    assert!(e.contains("particles.size.classes does not apply"), "{e}");
    let e = err("width = 0.2\nsize = { distribution = \"uniform\", min = 1.0e-3, max = 2.0e-3 }");
    assert!(e.contains("particles.width"), "{e}");
    let e = err("size = { distribution = \"uniform\", min = 0.01, max = 0.04 }");
    assert!(
        e.contains("particles.size.max") && e.contains("placement region"),
        "{e}"
    );
    let e = err("size = { distribution = \"sieve\", file = \"no-such-curve.csv\" }");
    assert!(
        e.contains("particles.size.file = \"no-such-curve.csv\""),
        "{e}"
    );

    let dir = std::env::temp_dir().join(format!("grains-sieve-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("falls.csv"),
        "0.5e-3,0\n1.0e-3,60\n1.5e-3,40\n2.0e-3,100\n",
    )
    .unwrap();
    std::fs::write(dir.join("short.csv"), "0.5e-3,5\n2.0e-3,100\n").unwrap();
    let spec = |f: &str| -> String {
        let spec: SizeSpec =
            toml::from_str(&format!("distribution = \"sieve\"\nfile = \"{f}\"")).unwrap();
        SizeLaw::new(&spec, MassModel::Sphere, &dir)
            .unwrap_err()
            .to_string()
    };
    let e = spec("falls.csv");
    assert!(
        e.contains("falls.csv") && e.contains("row 3") && e.contains("never decreases"),
        "{e}"
    );
    let e = spec("short.csv");
    assert!(e.contains("must start at 0 %"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
