//! Mass, centre of mass and principal moments of unions of spheres
//! against closed forms: a touching dimer (parallel-axis theorem), two
//! overlapping spheres (the lens volume π(4r + d)(2r − d)²/12, Weisstein,
//! "Sphere-Sphere Intersection", MathWorld), collinear rods by slices, a
//! pair of unequal spheres, disks in 2D; and a shape given turned and
//! shifted has the same moments and the same principal-frame spheres.
//!
//! The slices: a union of equal spheres on a line is cut across the line
//! into disks, each from the sphere whose centre is nearest, of radius²
//! ρ² = r² − u² (u the distance along the line from that centre). Then
//! V = ∫πρ², I_axis = ρ_m ∫πρ⁴/2 and I_perp = ρ_m ∫(πρ⁴/4 + x²πρ²), all
//! polynomials of degree ≤ 4 in u on each piece, which the 3-point
//! Gauss–Legendre rule (exact to degree 5) integrates exactly.

use glam::{DMat3, DQuat, DVec3};
use grains::rigid::mass::Ball;
use grains::rigid::shape::{clump, Props};
use grains::rigid::Shape;
use grains::{MassModel, D2, D3};
use std::f64::consts::PI;

const RHO: f64 = 2500.0;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn shape(balls: &[Ball]) -> (Shape<D3>, Props) {
    clump::<D3>("s", balls, RHO, MassModel::Sphere)
}

fn on_x(xs: &[f64], r: f64) -> Vec<Ball> {
    xs.iter().map(|&x| (DVec3::new(x, 0.0, 0.0), r)).collect()
}

/// Volume, I_axis and I_perp (about the centre, at x = 0 by symmetry of
/// `xs`) of equal spheres on the x axis, by slices.
fn slices(xs: &[f64], r: f64) -> (f64, f64, f64) {
    let (nodes, weights) = (
        [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()],
        [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0],
    );
    let (mut v, mut ia, mut ip) = (0.0, 0.0, 0.0);
    for (k, &c) in xs.iter().enumerate() {
        // The piece nearest to c: to the midpoints with its neighbours.
        let lo = if k == 0 {
            c - r
        } else {
            (0.5 * (xs[k - 1] + c)).max(c - r)
        };
        let hi = if k + 1 == xs.len() {
            c + r
        } else {
            (0.5 * (xs[k + 1] + c)).min(c + r)
        };
        let (a, b) = (lo - c, hi - c);
        for (z, w) in nodes.iter().zip(&weights) {
            let u = 0.5 * (a + b) + 0.5 * (b - a) * z;
            let w = 0.5 * (b - a) * w;
            let p2 = r * r - u * u;
            let x = c + u;
            v += w * PI * p2;
            ia += w * RHO * PI * p2 * p2 / 2.0;
            ip += w * RHO * (PI * p2 * p2 / 4.0 + x * x * PI * p2);
        }
    }
    (v, ia, ip)
}

#[test]
fn touching_dimer_by_the_parallel_axis_theorem() {
    let r = 0.5e-3;
    let (s, p) = shape(&on_x(&[-r, r], r));
    let ms = RHO * 4.0 / 3.0 * PI * r.powi(3);
    let axis = 2.0 * 0.4 * ms * r * r;
    let perp = 2.0 * (0.4 * ms * r * r + ms * r * r);
    assert!(rel(s.mass, 2.0 * ms) < 1e-12, "{} {}", s.mass, 2.0 * ms);
    assert!(rel(s.inertia[0], axis) < 1e-12, "{:?} {axis}", s.inertia);
    assert!(
        rel(s.inertia[1], perp) < 1e-12 && rel(s.inertia[2], perp) < 1e-12,
        "{:?} {perp}",
        s.inertia
    );
    assert!(p.exact && p.com.length() < 1e-15);
    assert!((p.bounding_radius - 2.0 * r).abs() < 1e-15);
    // In the principal frame the spheres lie on the body x axis.
    for sub in &s.spheres {
        assert!((sub.center.x.abs() - r).abs() < 1e-15 && sub.center.y.abs() < 1e-15);
    }
}

#[test]
fn overlapping_pair_loses_its_lens_once() {
    let r = 0.5e-3;
    for d in [0.2 * r, r, 1.5 * r, 1.99 * r] {
        let (s, p) = shape(&on_x(&[-d / 2.0, d / 2.0], r));
        let lens = PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
        let v = 2.0 * 4.0 / 3.0 * PI * r.powi(3) - lens;
        assert!(rel(p.measure, v) < 1e-12, "d = {d}: {} {v}", p.measure);
        assert!(rel(s.mass, RHO * v) < 1e-12);
        assert!(p.com.length() < 1e-12 * r, "{}", p.com);
        let (vs, ia, ip) = slices(&[-d / 2.0, d / 2.0], r);
        assert!(
            rel(vs, v) < 1e-12,
            "the slices agree with the lens formula: {vs} {v}"
        );
        assert!(
            rel(s.inertia[0], ia) < 1e-10,
            "d = {d}: {:?} {ia}",
            s.inertia
        );
        assert!(
            rel(s.inertia[1], ip) < 1e-10 && rel(s.inertia[2], ip) < 1e-10,
            "d = {d}: {:?} {ip}",
            s.inertia
        );
    }
}

/// Three-sphere rods: touching and overlapping spheres (closed forms),
/// and spheres so close that the third meets both others (quadrature).
#[test]
fn three_sphere_rods_by_slices() {
    let r = 0.5e-3;
    for (d, exact) in [(2.0 * r, true), (1.4 * r, true), (0.8 * r, false)] {
        let xs = [-d, 0.0, d];
        let (s, p) = shape(&on_x(&xs, r));
        let (v, ia, ip) = slices(&xs, r);
        let tol = if exact { 1e-10 } else { 1e-6 };
        assert_eq!(p.exact, exact, "d = {d}");
        eprintln!(
            "rod d = {:.1} r: volume {:.1e}, I_axis {:.1e}, I_perp {:.1e} relative error ({})",
            d / r,
            rel(p.measure, v),
            rel(s.inertia[0], ia),
            rel(s.inertia[1], ip),
            if exact { "closed forms" } else { "quadrature" }
        );
        assert!(rel(p.measure, v) < tol, "d = {d}: {} {v}", p.measure);
        assert!(rel(s.inertia[0], ia) < tol, "d = {d}: {:?} {ia}", s.inertia);
        assert!(
            rel(s.inertia[1], ip) < tol && rel(s.inertia[2], ip) < tol,
            "d = {d}: {:?} {ip}",
            s.inertia
        );
    }
}

#[test]
fn unequal_touching_spheres_shift_the_centre() {
    let (r1, r2) = (1.0e-3, 0.5e-3);
    let (s, p) = shape(&[(DVec3::ZERO, r1), (DVec3::new(r1 + r2, 0.0, 0.0), r2)]);
    let (m1, m2) = (
        RHO * 4.0 / 3.0 * PI * r1.powi(3),
        RHO * 4.0 / 3.0 * PI * r2.powi(3),
    );
    let xc = m2 * (r1 + r2) / (m1 + m2);
    let perp = 0.4 * m1 * r1 * r1 + m1 * xc * xc + 0.4 * m2 * r2 * r2 + m2 * (r1 + r2 - xc).powi(2);
    assert!(rel(p.com.x, xc) < 1e-12, "{} {xc}", p.com);
    assert!(rel(s.mass, m1 + m2) < 1e-12);
    assert!(rel(s.inertia[0], 0.4 * (m1 * r1 * r1 + m2 * r2 * r2)) < 1e-12);
    assert!(rel(s.inertia[1], perp) < 1e-12, "{:?} {perp}", s.inertia);
}

/// An irregular clump whose later spheres meet two earlier ones, as
/// written and turned by a rotation and shifted: the same principal
/// moments, and the same spheres in the principal frame (each axis up to
/// its sign, which no rule fixes).
#[test]
fn a_turned_shape_has_the_same_principal_frame() {
    let balls = vec![
        (DVec3::new(0.0, 0.0, 0.0), 0.5),
        (DVec3::new(0.7, 0.0, 0.0), 0.4),
        (DVec3::new(0.3, 0.55, 0.0), 0.45),
        (DVec3::new(0.3, 0.2, 0.5), 0.35),
    ];
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 2.1);
    let shift = DVec3::new(3.0, -1.0, 2.0);
    let moved: Vec<Ball> = balls.iter().map(|&(c, r)| (turn * c + shift, r)).collect();
    let (a, pa) = shape(&balls);
    let (b, pb) = shape(&moved);
    assert!(!pa.exact && !pb.exact, "the quadrature is what this tests");
    for k in 0..3 {
        assert!(
            rel(a.inertia[k], b.inertia[k]) < 1e-6,
            "{:?} {:?}",
            a.inertia,
            b.inertia
        );
    }
    assert!(a.inertia[0] < a.inertia[1] && a.inertia[1] < a.inertia[2]);
    for (sa, sb) in a.spheres.iter().zip(&b.spheres) {
        let (ca, cb) = (sa.center.abs(), sb.center.abs());
        assert!(
            (ca - cb).abs().max_element() < 1e-6,
            "{} {}",
            sa.center,
            sb.center
        );
    }
    assert!((pb.com - (turn * pa.com + shift)).length() < 1e-6);
    // The principal frame put back gives the spheres as written.
    for (sub, &(c, _)) in b.spheres.iter().zip(&moved) {
        let back = pb.com + pb.to_input * sub.center;
        assert!((back - c).length() < 1e-12, "{back} {c}");
    }
    // The inertia tensor in the principal frame is diagonal.
    let body =
        DMat3::from_quat(pb.to_input).transpose() * pb.inertia * DMat3::from_quat(pb.to_input);
    assert!(body.y_axis.x.abs() < 1e-9 * a.inertia[2] && body.z_axis.x.abs() < 1e-9 * a.inertia[2]);
}

/// A regular tetrahedron of four overlapping spheres is a spherical top.
#[test]
fn tetrahedral_clump_is_a_spherical_top() {
    let r = 0.5;
    let e = 0.8; // edge < 2r: every pair overlaps
    let k = e / (2.0 * 2.0f64.sqrt());
    let balls: Vec<Ball> = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ]
    .iter()
    .map(|c| (DVec3::from_array(*c) * k, r))
    .collect();
    let (s, p) = shape(&balls);
    assert!(rel(s.inertia[0], s.inertia[2]) < 1e-6, "{:?}", s.inertia);
    assert!(p.com.length() < 1e-6, "{}", p.com);
    // Bounded by the four whole spheres and above the largest one alone.
    let ball = 4.0 / 3.0 * PI * r.powi(3);
    assert!(p.measure < 4.0 * ball && p.measure > ball);
}

/// Disks: a union of disks under the disk mass model (area, ½ m r²) and
/// under the sphere model (a disk weighs its sphere, 2/5 m r²).
#[test]
fn disk_dimers_in_two_dimensions() {
    let r = 0.5e-3;
    let touching = on_x(&[-r, r], r);
    let (s, p) = clump::<D2>("d", &touching, RHO, MassModel::Disk);
    let md = RHO * PI * r * r;
    assert!(rel(s.mass, 2.0 * md) < 1e-12 && rel(p.measure, 2.0 * PI * r * r) < 1e-12);
    let iz = 2.0 * (0.5 * md * r * r + md * r * r);
    assert!(rel(s.inertia[2], iz) < 1e-12, "{:?} {iz}", s.inertia);
    let (s3, _) = clump::<D2>("d", &touching, RHO, MassModel::Sphere);
    let ms = RHO * 4.0 / 3.0 * PI * r.powi(3);
    assert!(rel(s3.inertia[2], 2.0 * (0.4 * ms * r * r + ms * r * r)) < 1e-12);
    // Overlapping disks lose their lens 2r² acos(d/2r) − (d/2)√(4r² − d²).
    let d = 1.2 * r;
    let (_, p) = clump::<D2>("d", &on_x(&[-d / 2.0, d / 2.0], r), RHO, MassModel::Disk);
    let lens = 2.0 * r * r * (d / (2.0 * r)).acos() - 0.5 * d * (4.0 * r * r - d * d).sqrt();
    assert!(
        rel(p.measure, 2.0 * PI * r * r - lens) < 1e-12,
        "{} {}",
        p.measure,
        2.0 * PI * r * r - lens
    );
    // Three disks in a row, the third meeting both: the quadrature.
    let (_, p) = clump::<D2>(
        "d",
        &on_x(&[-0.8 * r, 0.0, 0.8 * r], r),
        RHO,
        MassModel::Disk,
    );
    let lens =
        |d: f64| 2.0 * r * r * (d / (2.0 * r)).acos() - 0.5 * d * (4.0 * r * r - d * d).sqrt();
    // Inclusion–exclusion: the triple region is the outer pair's lens.
    let area = 3.0 * PI * r * r - 2.0 * lens(0.8 * r) - lens(1.6 * r) + lens(1.6 * r);
    assert!(
        !p.exact && rel(p.measure, area) < 1e-6,
        "{} {area}",
        p.measure
    );
}
