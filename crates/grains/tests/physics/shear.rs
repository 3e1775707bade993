//! Lees–Edwards boundaries (Lees & Edwards 1972) through the whole engine:
//! a grain through the sliding boundary, a contact across it (force and
//! spring) against the same contact inside the box, a sheared dense cell's
//! linear profile, the momentum along the flow through the boundary, and
//! the same bits on any thread count and across a checkpoint.

use crate::common;

use common::*;
use glam::{DVec2, DVec3};
use grains::contact::{ContactLaw, MassScaling};
use grains::domain::Shear;
use grains::engine::Engine;
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Domain, ParticleRecord, D2, D3};
use rand::{Rng, SeedableRng};

/// A 2D box periodic on both axes, sheared along x at `rate`.
fn sheared(lx: f64, ly: f64, rate: f64) -> Domain<D2> {
    let mut d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(lx, ly), [true, true, false]);
    d.shear = Some(Shear {
        axis: 0,
        gradient: 1,
        rate,
    });
    d
}

fn index(md: &Md<D2>, id: u64) -> usize {
    md.particles.id.iter().position(|&i| i == id).unwrap()
}

/// The tangential spring of the pair (a, b), oriented as the displacement
/// of `a` (the engine keeps it for its pair order), if the pair is listed.
fn spring(md: &Md<D2>, a: u64, b: u64) -> Option<DVec2> {
    let st = md.export_state().unwrap();
    let id = &st.particles.id;
    st.list
        .pairs
        .iter()
        .zip(&st.springs)
        .find_map(|(&[i, j], &s)| match (id[i as usize], id[j as usize]) {
            (gi, gj) if (gi, gj) == (a, b) => Some(s),
            (gi, gj) if (gi, gj) == (b, a) => Some(-s),
            _ => None,
        })
}

/// A free grain through the top comes back at the bottom with x shifted
/// by −Δ(t) and u reduced by γ̇ L_y (the opposite through the bottom):
/// after n crossings at time t, y = y_free − n L_y, u = u_0 − n γ̇ L_y and
/// x = x_free − n γ̇ L_y t modulo L_x. Every number here is a short binary
/// fraction, so the arithmetic is exact and so is the comparison.
#[test]
fn a_grain_through_the_sliding_boundary_is_shifted_and_slowed_exactly() {
    let (lx, ly, rate) = (8.0, 4.0, 0.25);
    let jump = rate * ly;
    let dt = 1.0 / 64.0;
    for (start, v0) in [
        (DVec2::new(1.0, 3.5), DVec2::new(0.5, 1.0)),
        (DVec2::new(5.0, 0.5), DVec2::new(-0.25, -1.0)),
    ] {
        let mut g = ParticleRecord::new(1, start, 0.5, 1.0, 0.1);
        g.vel = v0;
        let mut s = MdSettings::<D2>::new(dt, hooke(1.0e3, 0.0, MassScaling::Reduced), 0.25);
        s.integrator = Integrator::Verlet;
        let mut md = engine(vec![g], sheared(lx, ly, rate), s);
        let mut crossings = 0.0f64;
        for k in 1..=400u32 {
            md.step().unwrap();
            let t = k as f64 * dt;
            let free = start + v0 * t;
            let (p, v) = (md.particles.pos[0], md.particles.vel[0]);
            let n = ((free.y - p.y) / ly).round();
            assert_eq!(p.y, free.y - n * ly, "step {k}");
            assert_eq!(v, DVec2::new(v0.x - n * jump, v0.y), "step {k}");
            let r = (p.x - (free.x - n * jump * t)).rem_euclid(lx);
            assert!(r == 0.0 || r == lx, "step {k}: x = {} off by {r}", p.x);
            crossings = crossings.max(n.abs());
        }
        assert_eq!(crossings, 2.0, "the grain crossed the boundary twice");
    }
}

/// Hooke with damping, friction and rotation (the wall tests' law).
fn frictional() -> ContactLaw {
    wall_law::<D2>(0.5)
}

/// What a pair across the boundary went through.
#[derive(Default, Debug)]
struct Seen {
    /// Largest contact force and its largest tangential part.
    peak: f64,
    tangential: f64,
    /// Neighbour-list rebuilds while the grains touched.
    touching_builds: u64,
    /// Steps in contact with grain 1 in the top half and grain 2 in the
    /// bottom half: the contact through the sliding images.
    across: u64,
    /// Whether grain 1 went through the top while the spring was stretched.
    wrapped_stretched: bool,
    wrapped: bool,
}

/// Runs grains 1 and 2 (unit disks) through a contact across the sliding
/// boundary of a sheared box, grain 1 starting at height `y1` with
/// velocity `va`, grain 2 near the bottom with `vb`, its image above at
/// grain 1 − r0 at t = 0; and the same pair inside an unsheared open box,
/// grain 2 at −r0 with vb plus the jump. Every step, the separation through
/// the images, the relative velocity less the jump, both grains' forces,
/// grain 1's torque and the pair's tangential spring must be the inside
/// pair's. Tolerance: round-off of positions of order 1 (1e-15) through
/// the stiffness, 1e-9 of the peak force (and of the largest spring).
fn across_and_inside(y1: f64, va: DVec2, vb: DVec2, law: ContactLaw, steps: usize) -> Seen {
    let (lx, ly, rate) = (8.0, 4.0, 0.5);
    let jump = rate * ly;
    let dt = 5.0e-5;
    let r0 = DVec2::new(0.3, -1.02);
    let a = grain::<D2>(1, DVec2::new(4.0, y1), 1.0);
    let b = grain::<D2>(2, DVec2::new(4.0, y1) - r0 - DVec2::new(0.0, ly), 1.0);
    let with = |mut g: ParticleRecord<D2>, v: DVec2| {
        g.vel = v;
        g
    };
    let settings = || MdSettings::<D2>::new(dt, law.clone(), 0.004);
    let mut le = engine(
        vec![with(a.clone(), va), with(b, vb)],
        sheared(lx, ly, rate),
        settings(),
    );
    let b_in = grain::<D2>(2, -r0, 1.0);
    let mut inside = engine(
        vec![
            with(
                ParticleRecord {
                    pos: DVec2::ZERO,
                    ..a
                },
                va,
            ),
            with(b_in, vb + DVec2::new(jump, 0.0)),
        ],
        open_box::<D2>(5.0),
        settings(),
    );
    let mut seen = Seen::default();
    let mut stretch = 0.0f64;
    for k in 0..steps {
        let builds = le.neighbor_builds();
        le.step().unwrap();
        inside.step().unwrap();
        let (ia, ib) = (index(&le, 1), index(&le, 2));
        let (ja, jb) = (index(&inside, 1), index(&inside, 2));
        let (_, offset) = le.domain.shear_offset(le.time);
        let p = &le.particles;
        let (sep, dv) = le
            .domain
            .minimum_image_sheared(p.pos[ia] - p.pos[ib], offset);
        let q = &inside.particles;
        let want = q.pos[ja] - q.pos[jb];
        assert!((sep - want).length() < 1e-9, "step {k}: {sep} vs {want}");
        let v_rel = p.vel[ia] - p.vel[ib] - dv;
        let want_v = q.vel[ja] - q.vel[jb];
        assert!(
            (v_rel - want_v).length() < 1e-9,
            "step {k}: {v_rel} vs {want_v}"
        );
        let (f, g) = (p.force[ia], q.force[ja]);
        seen.peak = seen.peak.max(g.length());
        let tol = 1e-9 * seen.peak.max(1.0);
        assert!((f - g).length() <= tol, "step {k}: {f} vs {g}");
        assert!((p.torque[ia] - q.torque[ja]).abs() <= tol);
        assert!((p.force[ib] - q.force[jb]).length() <= tol);
        let n = want.normalize();
        seen.tangential = seen.tangential.max((g - n * g.dot(n)).length());
        if g != DVec2::ZERO && le.neighbor_builds() > builds {
            seen.touching_builds += 1;
        }
        if g != DVec2::ZERO && p.pos[ia].y > 0.5 * ly && p.pos[ib].y < 0.5 * ly {
            seen.across += 1;
        }
        let (s_le, s_in) = (spring(&le, 1, 2), spring(&inside, 1, 2));
        let (s_le, s_in) = (s_le.unwrap_or_default(), s_in.unwrap_or_default());
        stretch = stretch.max(s_in.length());
        let off = (s_le - s_in).length();
        assert!(
            off <= 1e-9 * stretch.max(1e-12),
            "step {k}: spring {s_le} vs {s_in}"
        );
        let through = p.pos[ia].y < 1.0;
        seen.wrapped_stretched |= through && !seen.wrapped && s_in != DVec2::ZERO;
        seen.wrapped |= through;
    }
    seen
}

/// Two grains colliding across the sliding boundary (grain 1 near the top,
/// grain 2 near the bottom, both moving down so that neither wraps in the
/// contact) feel the force, torque and spring of the same pair inside an
/// unsheared box, while the offset moves and the list is rebuilt during
/// the contact ([`across_and_inside`]).
#[test]
fn a_contact_across_the_sliding_boundary_is_the_same_contact_inside() {
    let (va, vb) = (DVec2::new(0.0, -0.5), DVec2::new(-1.0, -1.5));
    let seen = across_and_inside(3.99, va, vb, frictional(), 2000);
    assert!(seen.peak > 100.0, "the grains collided: {seen:?}");
    assert!(seen.tangential > 10.0, "the contact slid: {seen:?}");
    assert!(
        seen.across > 20,
        "the contact was through the images: {seen:?}"
    );
    assert!(
        seen.touching_builds > 0,
        "the list was rebuilt in the contact: {seen:?}"
    );
}

/// A grain that goes through the sliding boundary in the middle of a
/// frictional contact keeps its spring: a softer contact (k_n = 1e4, a
/// contact time of 16 ms, 320 steps) that begins with grain 1 just below
/// the top, both grains moving up, so that grain 1 wraps to the bottom
/// with the spring stretched; the spring after the wrap is the inside
/// pair's ([`across_and_inside`]).
#[test]
fn a_grain_through_the_sliding_boundary_keeps_its_spring() {
    let law = ContactLaw {
        kn: 1.0e4,
        kt: 1.0e4 / 3.0,
        gamma_n: 30.0,
        gamma_t: 10.0,
        ..frictional()
    };
    // The pair touches at t = 0.0513 (|r0 + (va − vb − jump) t| = 1), when
    // grain 1 is at 3.995, moving up at about 2.5.
    let (va, vb) = (DVec2::new(0.0, 2.5), DVec2::new(-1.0, 1.5));
    let seen = across_and_inside(3.995 - 2.5 * 0.0513, va, vb, law, 2000);
    assert!(
        seen.wrapped_stretched,
        "grain 1 wrapped in the contact: {seen:?}"
    );
    assert!(seen.tangential > 2.0, "the contact slid: {seen:?}");
}

/// In 3D, two spheres colliding across the sliding boundary of a box
/// sheared along x, with the gradient along y and then along z, feel at
/// every step the forces of the same pair inside an unsheared box (grain 2
/// at −r0 moving with its velocity plus the jump), through the offset's
/// motion and the list's rebuilds. Tolerance as in
/// [`across_and_inside`]: 1e-9 of the peak force.
#[test]
fn a_contact_across_the_sliding_boundary_in_3d_is_the_same_contact_inside() {
    for gradient in [1, 2] {
        let (l, rate) = (DVec3::new(8.0, 5.0, 6.0), 0.5);
        let lg = l[gradient];
        let jump = DVec3::new(rate * lg, 0.0, 0.0);
        let mut domain = Domain::<D3>::new(DVec3::ZERO, l, [true; 3]);
        domain.shear = Some(Shear {
            axis: 0,
            gradient,
            rate,
        });
        let up = if gradient == 1 { DVec3::Y } else { DVec3::Z };
        let across = DVec3::ONE - DVec3::X - up;
        let r0 = DVec3::new(0.3, 0.0, 0.0) + 0.2 * across - 1.02 * up;
        // Both move down: the contact stays through the sliding images.
        let (va, vb) = (-0.5 * up, DVec3::new(-1.0, 0.0, 0.0) - 1.5 * up);
        let a_pos = DVec3::new(4.0, 2.5, 3.0) * (DVec3::ONE - up) + (lg - 0.01) * up;
        let moving = |id: u64, pos: DVec3, v: DVec3| {
            let mut g = grain::<D3>(id, pos, 1.0);
            g.vel = v;
            g
        };
        let settings = || MdSettings::<D3>::new(5.0e-5, wall_law::<D3>(0.5), 0.004);
        let mut le = engine(
            vec![moving(1, a_pos, va), moving(2, a_pos - r0 - lg * up, vb)],
            domain,
            settings(),
        );
        let mut inside = engine(
            vec![moving(1, DVec3::ZERO, va), moving(2, -r0, vb + jump)],
            open_box::<D3>(5.0),
            settings(),
        );
        let at = |md: &Md<D3>, id: u64| md.particles.id.iter().position(|&i| i == id).unwrap();
        let (mut peak, mut across) = (0.0f64, 0);
        for k in 0..2000 {
            le.step().unwrap();
            inside.step().unwrap();
            let (ia, ib, ja, jb) = (at(&le, 1), at(&le, 2), at(&inside, 1), at(&inside, 2));
            let (p, q) = (&le.particles, &inside.particles);
            peak = peak.max(q.force[ja].length());
            let tol = 1e-9 * peak.max(1.0);
            assert!(
                (p.force[ia] - q.force[ja]).length() <= tol,
                "gradient {gradient}, step {k}: {} vs {}",
                p.force[ia],
                q.force[ja]
            );
            assert!((p.force[ib] - q.force[jb]).length() <= tol);
            assert!((p.torque[ia] - q.torque[ja]).length() <= tol);
            if q.force[ja] != DVec3::ZERO && p.pos[ia][gradient] > 0.5 * lg {
                across += (p.pos[ib][gradient] < 0.5 * lg) as u32;
            }
        }
        assert!(
            peak > 100.0,
            "gradient {gradient}: the grains collided ({peak})"
        );
        assert!(
            across > 20,
            "gradient {gradient}: through the images ({across})"
        );
    }
}

/// A dense sheared cell: 440 disks of diameters uniform in [0.8, 1.2]
/// (±20 %, density 1) on a triangular lattice of spacing 1.07, 20 sites by
/// 22 rows (area fraction 0.80, below random close packing of such disks,
/// near 0.84, so the cell flows without jamming), frictional and
/// dissipative (Hooke k_n = 1e4, k_t = k_n/3, μ = 0.5, rotation; γ_n = 80
/// gives e ≈ 0.5 for two unit disks), started on the profile γ̇ (y − y_mid).
/// The contact time of the lightest pair is π/√(k_n/m*) ≈ 0.0115, 29 steps.
pub(crate) fn dense_cell(rate: f64, integrator: Integrator) -> Md<D2> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(2026);
    let a = 1.07;
    let (nx, ny) = (20, 22);
    let row = a * 0.75f64.sqrt();
    let (lx, ly) = (nx as f64 * a, ny as f64 * row);
    let mut grains = Vec::new();
    for r in 0..ny {
        for c in 0..nx {
            let x = (c as f64 + 0.5 * (r % 2) as f64 + 0.25) * a;
            let y = (r as f64 + 0.5) * row;
            let d = rng.gen_range(0.8..1.2);
            let mut g = grain::<D2>((r * nx + c) as u64 + 1, DVec2::new(x, y), d);
            g.vel = DVec2::new(rate * (y - 0.5 * ly), 0.0);
            grains.push(g);
        }
    }
    let law = ContactLaw {
        kt: 1.0e4 / 3.0,
        mu: 0.5,
        rotation: true,
        ..hooke(1.0e4, 80.0, MassScaling::Reduced)
    };
    let mut settings = MdSettings::new(DENSE_DT, law, 0.2);
    settings.integrator = integrator;
    engine(grains, sheared(lx, ly, rate), settings)
}

const DENSE_DT: f64 = 4.0e-4;

/// The dense cell's mean velocity u(y) along the flow, sampled every 20
/// steps over 20000 steps (a strain of 16) after 2000 to settle (1.6), in
/// 10 bins across the gradient, is the homogeneous simple shear u = γ̇ y +
/// c (Lees & Edwards 1972): the least-squares slope is γ̇ within 2 %, under
/// either integrator. The bins scatter about the fitted line by the
/// cell's slow shear modes, which change sign from one realization to the
/// next: 0.7–2.4 % of the velocity jump γ̇ L_y over diameter seeds 1–3 and
/// 2026, 1.8 % and 0.7 % in this one; each bin must lie within 3 % of it.
#[test]
fn a_sheared_dense_cell_keeps_a_linear_profile_of_slope_the_shear_rate() {
    let rate = 2.0;
    for integrator in [Integrator::Gear5, Integrator::Verlet] {
        let mut md = dense_cell(rate, integrator);
        let ly = md.domain.length(1);
        md.advance(2000).unwrap();
        const BINS: usize = 10;
        let (mut sum, mut count) = ([0.0; BINS], [0.0; BINS]);
        for _ in 0..20000 / 20 {
            md.advance(20).unwrap();
            let offset = md.domain.shear_offset(md.time).1;
            let p = &md.particles;
            for (x, v) in p.pos.iter().zip(&p.vel) {
                // Positions wrap at rebuilds only: use the wrapped place.
                let (mut x, mut v) = (*x, *v);
                md.domain.wrap_sheared(&mut x, &mut v, offset);
                let b = ((x.y / ly * BINS as f64) as usize).min(BINS - 1);
                sum[b] += v.x;
                count[b] += 1.0;
            }
        }
        let ys: Vec<f64> = (0..BINS)
            .map(|b| (b as f64 + 0.5) * ly / BINS as f64)
            .collect();
        let us: Vec<f64> = (0..BINS).map(|b| sum[b] / count[b]).collect();
        let my = ys.iter().sum::<f64>() / BINS as f64;
        let mu = us.iter().sum::<f64>() / BINS as f64;
        let sxy: f64 = ys.iter().zip(&us).map(|(y, u)| (y - my) * (u - mu)).sum();
        let sxx: f64 = ys.iter().map(|y| (y - my) * (y - my)).sum();
        let slope = sxy / sxx;
        let worst = (ys.iter().zip(&us))
            .map(|(y, u)| (u - (mu + slope * (y - my))).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{integrator:?}: slope {slope:.5} (γ̇ {rate}), worst bin {worst:.4} off the line \
             ({:.2} % of γ̇ L_y), bins {us:.3?}",
            100.0 * worst / (rate * ly)
        );
        assert!(
            (slope - rate).abs() < 0.02 * rate,
            "{integrator:?}: slope {slope}"
        );
        assert!(
            worst < 0.03 * rate * ly,
            "{integrator:?}: a bin is {worst} off"
        );
    }
}

/// Total momentum along the flow is conserved through the sliding
/// boundary: a grain through the top loses the velocity jump γ̇ L_y, so
/// Σ m (u + n γ̇ L_y), n its net crossings of the top, is the momentum of
/// the unwrapped grains, on which the pair forces act as action and
/// reaction (Hooke with the reduced-mass damping). It stays constant to
/// round-off over 3000 steps (some 20 crossings): velocity Verlet rounds
/// each grain's m u at most twice a step, so the bound is 4 × steps × ε ×
/// Σ m |u| (a factor 2 for the forces' sums). Gear-5 (whose corrections
/// are linear in the forces) is held to the same bound.
#[test]
fn momentum_along_the_flow_is_conserved_through_the_sliding_boundary() {
    momentum_conserved(Integrator::Verlet);
    momentum_conserved(Integrator::Gear5);
}

fn momentum_conserved(integrator: Integrator) {
    let rate = 2.0;
    let mut md = dense_cell(rate, integrator);
    let ly = md.domain.length(1);
    let jump = rate * ly;
    let p = &md.particles;
    // Each grain's height at the last step and net crossings of the top.
    let mut seen: std::collections::HashMap<u64, (f64, f64)> = (p.id.iter().zip(&p.pos))
        .map(|(&id, x)| (id, (x.y, 0.0)))
        .collect();
    let momentum = |md: &Md<D2>, seen: &std::collections::HashMap<u64, (f64, f64)>| {
        let p = &md.particles;
        (0..p.len())
            .map(|i| p.mass[i] * (p.vel[i].x + seen[&p.id[i]].1 * jump))
            .sum::<f64>()
    };
    let start = momentum(&md, &seen);
    let scale: f64 = (0..p.len()).map(|i| p.mass[i] * p.vel[i].x.abs()).sum();
    let steps = 3000;
    let bound = 4.0 * steps as f64 * f64::EPSILON * scale;
    let (mut crossings, mut drift) = (0, 0.0f64);
    for k in 0..steps {
        md.step().unwrap();
        let p = &md.particles;
        for (&id, x) in p.id.iter().zip(&p.pos) {
            let (y, n) = seen.get_mut(&id).unwrap();
            if x.y - *y < -0.5 * ly {
                *n += 1.0;
                crossings += 1;
            } else if x.y - *y > 0.5 * ly {
                *n -= 1.0;
                crossings += 1;
            }
            *y = x.y;
        }
        drift = drift.max((momentum(&md, &seen) - start).abs());
        assert!(
            drift <= bound,
            "step {k}: momentum drifted by {drift} (bound {bound})"
        );
    }
    eprintln!("{integrator:?}: {crossings} crossings, drift {drift:.3e} of Σ m|u| = {scale:.1}");
    assert!(crossings >= 5, "{crossings} crossings");
}

/// A gas of `n × n` disks of diameter 1 on a lattice in a sheared box of
/// side `side`, on the linear profile γ̇ (y − y_mid) plus a little noise.
fn sheared_gas(n: usize, side: f64, rate: f64, law: ContactLaw, dt: f64) -> Md<D2> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(47);
    let step = side / n as f64;
    let mut grains = Vec::new();
    for i in 0..n * n {
        let pos = DVec2::new((i % n) as f64 + 0.5, (i / n) as f64 + 0.5) * step;
        let mut g = grain::<D2>(i as u64 + 1, pos, 1.0);
        let noise = DVec2::new(rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5));
        g.vel = DVec2::new(rate * (pos.y - 0.5 * side), 0.0) + noise;
        grains.push(g);
    }
    engine(
        grains,
        sheared(side, side, rate),
        MdSettings::new(dt, law, 0.1),
    )
}

/// The bits of the positions and velocities of a sheared run.
fn bits(md: &Md<D2>) -> Vec<u64> {
    let p = &md.particles;
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by_key(|&i| p.id[i]);
    order
        .iter()
        .flat_map(|&i| {
            let (x, v) = (p.pos[i], p.vel[i]);
            [x.x, x.y, v.x, v.y].map(f64::to_bits)
        })
        .collect()
}

/// A sheared gas of 4900 disks runs to the same bits on 1 and 2 threads,
/// and across a checkpoint taken half way (the images' offset carried).
#[test]
fn a_sheared_run_gives_the_same_bits_on_threads_and_across_a_checkpoint() {
    let law = hooke(1.0e4, 30.0, MassScaling::Reduced);
    let make = || sheared_gas(70, 120.0, 1.0, law.clone(), 4.0e-4);
    let on = |threads: usize, f: &mut (dyn FnMut() + Send)| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    };
    let mut one = make();
    on(1, &mut || one.advance(600).unwrap());
    let mut two = make();
    on(2, &mut || two.advance(600).unwrap());
    assert!(one.neighbor_builds() > 2);
    assert_eq!(bits(&one), bits(&two), "1 vs 2 threads");

    let mut first = make();
    on(2, &mut || first.advance(300).unwrap());
    let saved = first.export().unwrap();
    let mut resumed = make();
    resumed.import(&saved, "test").unwrap();
    assert_eq!(resumed.export().unwrap(), saved);
    on(2, &mut || resumed.advance(300).unwrap());
    assert_eq!(bits(&resumed), bits(&one), "resumed vs uninterrupted");
}

/// `measure.rheology` on two unit disks pressed together through the
/// sliding boundary, both on the shear profile (no velocity fluctuation):
/// the stress is the one contact's virial over the box area A,
/// σ = k_n ξ |r| n ⊗ n / A (Hooke without damping, force k_n ξ n), so
/// P = tr σ / 2 = k_n ξ |r| / 2A, τ = −σ_xy = −k_n ξ |r| n_x n_y / A,
/// μ = −2 n_x n_y, I = γ̇ d / √(P/ρ) with ρ = m/(π r²), φ = 2π r²/A and
/// Z = 2 × 1 contact / 2 grains = 1, to round-off.
#[test]
fn rheology_of_one_contact_through_the_sliding_boundary_is_its_virial() {
    use grains::measure::Rheology;
    let (lx, ly, rate) = (8.0, 4.0, 0.5);
    let kn = 1.0e4;
    // Grain 2's image above the box sits at grain 1 + r, |r| < 1.
    let r = DVec2::new(0.3, 0.95);
    let a = DVec2::new(4.0, 3.8);
    let b = a + r - DVec2::new(0.0, ly);
    let on_profile = |id: u64, pos: DVec2| {
        let mut g = grain::<D2>(id, pos, 1.0);
        g.vel = DVec2::new(rate * (pos.y - 0.5 * ly), 0.0);
        g
    };
    let md = engine(
        vec![on_profile(1, a), on_profile(2, b)],
        sheared(lx, ly, rate),
        MdSettings::new(1e-4, hooke(kn, 0.0, MassScaling::Reduced), 0.1),
    );
    let view = md.view();
    let mut rh = Rheology::begin(&view).unwrap();
    rh.sample(&view);
    let got = rh.rows()[0];
    let area = lx * ly;
    let (dist, n) = (r.length(), r.normalize());
    let xi = 1.0 - dist;
    let pressure = kn * xi * dist / (2.0 * area);
    let tau = -kn * xi * dist * n.x * n.y / area;
    let m = md.particles.mass[0];
    let rho = m / (std::f64::consts::PI * 0.25);
    let want = [
        0.0,
        tau,
        pressure,
        -2.0 * n.x * n.y,
        rate * 1.0 / (pressure / rho).sqrt(),
        2.0 * std::f64::consts::PI * 0.25 / area,
        1.0,
    ];
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!(
            (g - w).abs() <= 1e-12 * w.abs().max(1e-12),
            "column {k}: {g} vs {w}"
        );
    }
}
