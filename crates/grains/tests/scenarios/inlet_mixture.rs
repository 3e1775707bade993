//! An inlet's mixture of materials by number or by mass fraction: 6000
//! grains drawn by one inlet, their counts (by number) or their masses
//! (by mass) per material against the fractions by a chi-square at the
//! 1 % level (2 degrees of freedom: 9.210, the chi-square table of
//! Pearson & Hartley 1966); each grain's mass is its material's density
//! times its volume; 1 and 2 threads give the same bits; `grains check`
//! prints the mixture; bad mixtures are refused by name.

use grains::dim::D3;
use grains::md::Md;
use grains::scenario::flow::FlowRun;
use grains::scenario::{build_md, load_str, Loaded};
use std::path::PathBuf;

/// Three softened materials; a floor; `inlet` as the one `[[inlets]]`.
fn scenario(inlet: &str) -> String {
    format!(
        r#"name = "mixture"
dimension = "3d"
seed = 17
gravity = [0.0, 0.0, -9.81]
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.12, 0.12, 0.12]
[particles]
placement = "none"
d0 = 1.0e-3
[contact]
model = "hertz-mindlin"
[[materials]]
name = "glass"
density = 2500.0
youngs_modulus = 1.8e6
poisson_ratio = 0.23
restitution = 0.9
friction = 0.4
[[materials]]
name = "steel"
density = 7800.0
youngs_modulus = 5.7e6
poisson_ratio = 0.3
restitution = 0.8
friction = 0.3
[[materials]]
name = "sand"
density = 2650.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25
restitution = 0.6
friction = 0.6
[[walls]]
name = "floor"
shape = {{ type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
material = "steel"
[run]
integrator = "verlet"
dt = 2.0e-6
duration = 1.0e-3
skin = 0.2
[[inlets]]
{inlet}
"#
    )
}

const MIX: &str = r#"materials = [{ name = "glass", fraction = 0.6 }, { name = "steel", fraction = 0.3, kind = 7 }, { name = "sand", fraction = 0.1 }]
size = { distribution = "uniform", min = 0.8e-3, max = 1.2e-3 }"#;

fn load(inlet: &str) -> Result<Loaded, String> {
    load_str(&scenario(inlet), "mixture.toml", PathBuf::from("."), &[]).map_err(|e| e.to_string())
}

fn error(inlet: &str) -> String {
    let loaded = match load(inlet) {
        Err(e) => return e,
        Ok(l) => l,
    };
    match build_md::<D3>(&loaded) {
        Err(e) => e.to_string(),
        Ok((md, _)) => match FlowRun::begin(&loaded, &md) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {inlet}"),
        },
    }
}

#[test]
fn counts_per_material_follow_the_fractions() {
    const N: usize = 6000;
    let box_ = r#"region = { shape = "box", lo = [0.0, 0.0, 0.0], hi = [0.12, 0.12, 0.12] }"#;
    let loaded = load(&format!("{box_}\ncount = {N}\n{MIX}")).unwrap();
    let (mut md, _) = build_md::<D3>(&loaded).unwrap();
    let mut flow = FlowRun::begin(&loaded, &md).unwrap();
    flow.after_step(&mut md);
    let p = &md.particles;
    assert_eq!(p.n_owned(), N, "every grain found room");
    // glass is materials[0]: kind 1; steel kind 7 as given; sand kind 3.
    let expected = [(1u32, 0.6, 2500.0), (7, 0.3, 7800.0), (3, 0.1, 2650.0)];
    let mut chi2 = 0.0;
    for (kind, fraction, _) in expected {
        let n = p.kind.iter().filter(|&&k| k == kind).count() as f64;
        let e = fraction * N as f64;
        chi2 += (n - e) * (n - e) / e;
        println!("kind {kind}: {n} grains, {e} expected");
    }
    let counted: usize = (expected.iter())
        .map(|(kind, _, _)| p.kind.iter().filter(|&k| k == kind).count())
        .sum();
    assert_eq!(counted, N, "a grain of another kind");
    println!("chi-square {chi2:.3} (2 degrees of freedom, 1 % level 9.210)");
    assert!(chi2 < 9.210, "chi-square {chi2} over the 1 % level");
    for i in 0..N {
        let density = expected.iter().find(|e| e.0 == p.kind[i]).unwrap().2;
        let r = p.radius[i];
        let m = density * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        assert!(
            (p.mass[i] - m).abs() <= 1e-12 * m,
            "grain {i} of kind {} weighs {} kg, not {m} kg",
            p.kind[i],
            p.mass[i]
        );
    }
}

fn bits(md: &Md<D3>) -> Vec<u64> {
    let p = &md.particles;
    let mut out = Vec::new();
    for i in 0..p.n_owned() {
        out.push(p.id[i]);
        out.push(p.kind[i] as u64);
        for v in [p.pos[i], p.vel[i], p.omega[i]] {
            out.extend(v.to_array().map(f64::to_bits));
        }
    }
    out
}

#[test]
fn a_mixture_gives_the_same_bits_on_one_and_two_threads() {
    let pour = r#"region = { shape = "box", lo = [0.02, 0.02, 0.005], hi = [0.04, 0.04, 0.02] }
rate = 100000.0
stop = 2.0e-3
velocity = [0.0, 0.0, -0.3]"#;
    let loaded = load(&format!("{pour}\n{MIX}")).unwrap();
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (mut md, _) = build_md::<D3>(&loaded).unwrap();
            let mut flow = FlowRun::begin(&loaded, &md).unwrap();
            while md.step < 1500 {
                let next = flow.next_act(md.step, (md.step + 256).min(1500));
                md.advance(next - md.step).unwrap();
                flow.after_step(&mut md);
            }
            bits(&md)
        })
    };
    let one = on(1);
    assert!(one.len() > 100 * 11, "{} grains", one.len() / 11);
    assert!(one == on(2), "1 and 2 threads differ");
}

/// By mass: the fractions 0.6, 0.3, 0.1 are shares of the inserted mass.
/// Grain i carries y_ic = m_i (1[i is of c] − w_c), whose mean is zero
/// when the mass fractions are w_c; the sums S_c = M_c − w_c M over N
/// grains are then asymptotically normal with covariance N Σ, Σ_cd =
/// E[y_c y_d] estimated from the grains, and S' Σ'^{-1} S' / N over two of
/// the three materials (the third is fixed by them: S sums to zero) is
/// chi-square with 2 degrees of freedom (Wald's test).
#[test]
fn masses_per_material_follow_a_mixture_by_mass() {
    const N: usize = 6000;
    let box_ = r#"region = { shape = "box", lo = [0.0, 0.0, 0.0], hi = [0.12, 0.12, 0.12] }"#;
    let inlet = format!("{box_}\ncount = {N}\n{MIX}\nmaterials_weight = \"mass\"");
    let loaded = load(&inlet).unwrap();
    let (mut md, _) = build_md::<D3>(&loaded).unwrap();
    let mut flow = FlowRun::begin(&loaded, &md).unwrap();
    flow.after_step(&mut md);
    let p = &md.particles;
    assert_eq!(p.n_owned(), N, "every grain found room");
    let kinds = [1u32, 7, 3];
    let w = [0.6, 0.3, 0.1];
    let total: f64 = p.mass[..N].iter().sum();
    let mut s = [0.0; 3];
    let mut cov = [[0.0; 2]; 2];
    for i in 0..N {
        let c = kinds
            .iter()
            .position(|&k| k == p.kind[i])
            .expect("a mixture's kind");
        let y: [f64; 3] = std::array::from_fn(|d| p.mass[i] * (f64::from(c == d) - w[d]));
        for d in 0..3 {
            s[d] += y[d];
        }
        for a in 0..2 {
            for b in 0..2 {
                cov[a][b] += y[a] * y[b];
            }
        }
    }
    // Wald: S' (N Σ')^{-1} S' with N Σ' = Σ_i y_i y_i'.
    let det = cov[0][0] * cov[1][1] - cov[0][1] * cov[1][0];
    let inv = [
        [cov[1][1] / det, -cov[0][1] / det],
        [-cov[1][0] / det, cov[0][0] / det],
    ];
    let chi2 =
        s[0] * (inv[0][0] * s[0] + inv[0][1] * s[1]) + s[1] * (inv[1][0] * s[0] + inv[1][1] * s[1]);
    for c in 0..3 {
        let m: f64 = (0..N)
            .filter(|&i| p.kind[i] == kinds[c])
            .map(|i| p.mass[i])
            .sum();
        let n = (0..N).filter(|&i| p.kind[i] == kinds[c]).count();
        println!(
            "kind {}: {n} grains, mass fraction {:.4} (asked {})",
            kinds[c],
            m / total,
            w[c]
        );
    }
    println!("chi-square of the mass fractions {chi2:.3} (2 degrees of freedom, 1 % level 9.210)");
    assert!(chi2 < 9.210, "chi-square {chi2} over the 1 % level");
    // The number fractions it was drawn with, (w_c / ρ_c) / Σ (w_j / ρ_j):
    // 0.759, 0.122, 0.119; a by-number draw (0.6, 0.3, 0.1) is far off.
    let rho = [2500.0, 7800.0, 2650.0];
    let norm: f64 = (0..3).map(|c| w[c] / rho[c]).sum();
    let mut chi2_n = 0.0;
    for c in 0..3 {
        let n = p.kind.iter().filter(|&&k| k == kinds[c]).count() as f64;
        let e = w[c] / rho[c] / norm * N as f64;
        chi2_n += (n - e) * (n - e) / e;
    }
    println!("chi-square of the counts {chi2_n:.3}");
    assert!(chi2_n < 9.210, "counts: chi-square {chi2_n}");
    // `grains check` prints the inlet's mixture as drawn.
    let report = grains::runner::check(&loaded).unwrap();
    let mix = &report["inlets"][0]["mixture"];
    assert_eq!(mix["weight"], "mass", "{mix}");
    let parts = mix["materials"].as_array().unwrap();
    assert_eq!(parts.len(), 3);
    for c in 0..3 {
        assert_eq!(parts[c]["kind"], kinds[c]);
        let mf = parts[c]["mass_fraction"].as_f64().unwrap();
        let nf = parts[c]["number_fraction"].as_f64().unwrap();
        assert!((mf - w[c]).abs() < 1e-12, "{mix}");
        assert!((nf - w[c] / rho[c] / norm).abs() < 1e-12, "{mix}");
    }
}

#[test]
fn bad_mixtures_are_named() {
    let r = r#"region = { shape = "box", lo = [0.0, 0.0, 0.0], hi = [0.12, 0.12, 0.12] }
count = 10"#;
    let e = error(&format!(
        "{r}\nmaterials = [{{ name = \"glass\", fraction = 0.6 }}, {{ name = \"steel\", fraction = 0.3 }}]"
    ));
    assert!(
        e.contains("inlets[0].materials") && e.contains("must sum to 1"),
        "{e}"
    );
    let e = error(&format!(
        "{r}\nmaterials = [{{ name = \"glas\", fraction = 1.0 }}]"
    ));
    assert!(
        e.contains("inlets[0].materials[0].name") && e.contains("\"glass\""),
        "{e}"
    );
    let e = error(&format!(
        "{r}\nkind = 2\nmaterials = [{{ name = \"glass\", fraction = 1.0 }}]"
    ));
    assert!(e.contains("inlets[0].kind") && e.contains("exclude"), "{e}");
    let e = error(&format!(
        "{r}\nmaterials = [{{ name = \"glass\", fraction = -0.5 }}, {{ name = \"steel\", fraction = 1.5 }}]"
    ));
    assert!(e.contains("inlets[0].materials[0].fraction"), "{e}");
    let e = error(&format!(
        "{r}\nmaterials = [{{ name = \"glass\", fraction = 0.5 }}, {{ name = \"steel\", fraction = 0.5, kind = 1 }}]"
    ));
    assert!(
        e.contains("kind 1") && e.contains("inlets[0].materials[1]"),
        "{e}"
    );
    let e = error(&format!("{r}\nmaterials_weight = \"mass\""));
    assert!(e.contains("inlets[0].materials_weight"), "{e}");
    let e = match load(&format!("{r}\nmaterials_weight = \"volume\"")) {
        Err(e) => e,
        Ok(_) => panic!("materials_weight = \"volume\" accepted"),
    };
    assert!(e.contains("materials_weight") && e.contains("mass"), "{e}");
}
