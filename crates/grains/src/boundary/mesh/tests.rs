//! The mesh's contacts against the planes they stand for.

use super::*;

/// An n × n grid of squares over [0, size]², each cut into two triangles
/// along alternating diagonals, in the plane z = `z`.
pub(crate) fn flat_sheet(n: usize, size: f64, z: f64) -> Vec<[[f64; 3]; 3]> {
    let h = size / n as f64;
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x0, y0, x1, y1) = (
                i as f64 * h,
                j as f64 * h,
                (i + 1) as f64 * h,
                (j + 1) as f64 * h,
            );
            let (a, b, c, d) = ([x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]);
            if (i + j) % 2 == 0 {
                out.push([a, b, c]);
                out.push([a, c, d]);
            } else {
                out.push([a, b, d]);
                out.push([b, c, d]);
            }
        }
    }
    out
}

fn mesh(tris: &[[[f64; 3]; 3]]) -> Mesh {
    Mesh::new("test", tris, &MeshPlacement::default()).unwrap()
}

fn touches(m: &Mesh, p: DVec3, r: f64) -> Vec<MeshTouch> {
    let mut s = MeshScratch::default();
    m.touches(p, r, &mut s);
    s.touches().to_vec()
}

/// A little random stream for positions.
fn stream(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn a_flat_sheet_is_one_patch_that_pushes_once_like_a_plane() {
    let m = mesh(&flat_sheet(10, 1.0, 0.0));
    assert_eq!(m.triangles(), 200);
    assert_eq!(m.patches(), 1);
    let mut rnd = stream(7);
    let r = 0.05;
    // Over the inside, on edges and corners of the triangles too.
    for k in 0..2000 {
        let (x, y) = if k % 3 == 0 {
            ((rnd() * 10.0).round() / 10.0, 0.1 + 0.8 * rnd())
        } else {
            (0.1 + 0.8 * rnd(), 0.1 + 0.8 * rnd())
        };
        let z = (rnd() - 0.3) * r;
        let t = touches(&m, DVec3::new(x, y, z), r);
        assert_eq!(t.len(), 1, "({x}, {y}, {z})");
        let want = r - z.abs();
        // A centre right above an inner edge may be met by the edge's
        // nearest point, which rounding leaves 1e-15 from the plane's.
        assert!(
            (t[0].touch.overlap - want).abs() <= 1e-15,
            "{}",
            t[0].touch.overlap
        );
        assert!((t[0].touch.normal - DVec3::Z * z.signum()).length() < 1e-12);
        assert!((t[0].touch.point - DVec3::new(x, y, 0.0)).length() < 1e-15);
    }
}

#[test]
fn a_concave_corner_pushes_from_both_faces_and_a_ridge_once() {
    // Floor z = 0 over x in [0, 1] and a wall x = 0 over z in [0, 1]: an L
    // sharing the edge x = z = 0 (y in [0, 1]).
    let floor = flat_sheet(4, 1.0, 0.0);
    let wall: Vec<_> = floor
        .iter()
        .map(|t| t.map(|[x, y, _]| [0.0, y, x]))
        .collect();
    let m = mesh(&[floor.clone(), wall].concat());
    assert_eq!(m.patches(), 2);
    let r = 0.1;
    let p = DVec3::new(0.07, 0.4, 0.08);
    let t = touches(&m, p, r);
    assert_eq!(t.len(), 2);
    let mut got: Vec<(f64, DVec3)> = t
        .iter()
        .map(|t| (t.touch.overlap, t.touch.normal))
        .collect();
    got.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!((got[0].0 - (r - 0.08)).abs() < 1e-15 && got[0].1 == DVec3::Z);
    assert!((got[1].0 - (r - 0.07)).abs() < 1e-15 && got[1].1 == DVec3::X);

    // The same floor with a wall going down from x = 1: a convex ridge
    // along x = 1, z = 0. A grain beyond it meets the edge once.
    let down: Vec<_> = floor
        .iter()
        .map(|t| t.map(|[x, y, _]| [1.0, y, -x]))
        .collect();
    let m = mesh(&[floor, down].concat());
    let p = DVec3::new(1.03, 0.5, 0.04);
    let t = touches(&m, p, r);
    assert_eq!(t.len(), 1);
    assert!((t[0].touch.overlap - (r - 0.05)).abs() < 1e-15);
    // On the floor's side near the ridge: the floor's face only.
    let t = touches(&m, DVec3::new(0.97, 0.5, 0.04), r);
    assert_eq!(t.len(), 1);
    assert_eq!(t[0].touch.normal, DVec3::Z);
}

#[test]
fn placement_scales_turns_and_shifts() {
    let place = MeshPlacement {
        scale: 2.0,
        rotate_deg: [0.0, 0.0, 90.0],
        translate: [1.0, 0.0, 0.0],
    };
    let x = place.apply([1.0, 0.0, 0.0]);
    assert!((x - DVec3::new(1.0, 2.0, 0.0)).length() < 1e-15);
    // About x first, then z: (0, 1, 0) -> (0, 0, 1) -> (0, 0, 1).
    let place = MeshPlacement {
        rotate_deg: [90.0, 0.0, 90.0],
        ..MeshPlacement::default()
    };
    assert!((place.apply([0.0, 1.0, 0.0]) - DVec3::Z).length() < 1e-15);
    assert!((place.apply([1.0, 0.0, 0.0]) - DVec3::Y).length() < 1e-15);
}

#[test]
fn bad_triangles_are_named() {
    let mut tris = flat_sheet(2, 1.0, 0.0);
    tris[5][1] = tris[5][0];
    let e = Mesh::new("m.stl", &tris, &MeshPlacement::default()).unwrap_err();
    assert!(e.contains("triangle 5") && e.contains("degenerate"), "{e}");
    let mut tris = flat_sheet(2, 1.0, 0.0);
    tris[3][2][1] = f64::NAN;
    let e = Mesh::new("m.stl", &tris, &MeshPlacement::default()).unwrap_err();
    assert!(e.contains("triangle 3") && e.contains("not finite"), "{e}");
    let bad = MeshPlacement {
        scale: 0.0,
        ..MeshPlacement::default()
    };
    let e = Mesh::new("m.stl", &flat_sheet(1, 1.0, 0.0), &bad).unwrap_err();
    assert!(e.contains("scale"), "{e}");
}

#[test]
fn the_grid_finds_what_a_scan_of_all_triangles_finds() {
    // A bumpy sheet: many patches, contacts of every kind.
    let mut tris = flat_sheet(12, 1.0, 0.0);
    let bump = |x: f64, y: f64| 0.03 * ((7.0 * x).sin() + (5.0 * y).cos());
    for t in &mut tris {
        for v in t.iter_mut() {
            v[2] = bump(v[0], v[1]);
        }
    }
    let m = mesh(&tris);
    let mut rnd = stream(3);
    for _ in 0..500 {
        let p = DVec3::new(rnd(), rnd(), 0.1 * rnd() - 0.02);
        let r = 0.02 + 0.1 * rnd();
        let mut seen = Vec::new();
        let none = &mut Vec::new();
        let (lo, hi) = (p - DVec3::splat(r), p + DVec3::splat(r));
        m.grid
            .visit((lo, hi), none, |_, _| false, |t, _| seen.push(t));
        seen.sort_unstable();
        seen.dedup();
        let all: Vec<usize> = (0..m.triangles())
            .filter(|&t| m.candidate(t, p, r).is_some())
            .collect();
        for t in &all {
            assert!(seen.binary_search(t).is_ok(), "triangle {t} missed");
        }
    }
}

/// The contacts by the rule the module states, from a scan of every
/// triangle: per patch its face when one triangle is met at its face, else
/// its nearest edge or corner; then nearest first, less the edges and
/// corners of patches already counted; in patch order.
fn touches_by_scan(m: &Mesh, p: DVec3, r: f64) -> Vec<MeshTouch> {
    let all: Vec<Candidate> = (0..m.triangles())
        .filter_map(|t| m.candidate(t, p, r))
        .collect();
    let mut best: Vec<Candidate> = Vec::new();
    for c in all {
        let key = |c: &Candidate| (c.rank > 0, c.dist, c.rank, c.ends, c.tri);
        match best.iter_mut().find(|b| b.patch == c.patch) {
            Some(b) if key(&c).partial_cmp(&key(b)) == Some(std::cmp::Ordering::Less) => *b = c,
            Some(_) => {}
            None => best.push(c),
        }
    }
    best.sort_by(|a, b| {
        (a.dist, a.rank, a.patch, a.ends)
            .partial_cmp(&(b.dist, b.rank, b.patch, b.ends))
            .unwrap()
    });
    let mut out: Vec<MeshTouch> = Vec::new();
    for c in best {
        let on = |a: &MeshTouch| m.on_patch(c.ends[0], a.patch) && m.on_patch(c.ends[1], a.patch);
        if c.rank == 0 || !out.iter().any(on) {
            out.push(MeshTouch {
                patch: c.patch,
                touch: c.touch,
            });
        }
    }
    out.sort_by_key(|t| t.patch);
    out
}

#[test]
fn contacts_do_not_depend_on_the_order_triangles_are_read_in() {
    // Half flat (one patch of 144 triangles), half bumpy (many patches).
    let mut tris = flat_sheet(12, 1.0, 0.0);
    let bump = |x: f64, y: f64| {
        if x > 0.5 {
            0.03 * ((7.0 * x).sin() - 3.5f64.sin()) * (1.0 + 0.5 * (5.0 * y).cos())
        } else {
            0.0
        }
    };
    for t in &mut tris {
        for v in t.iter_mut() {
            v[2] = bump(v[0], v[1]);
        }
    }
    let m = mesh(&tris);
    assert!(m.patches() > 20, "{} patches", m.patches());
    let mut rnd = stream(11);
    let h = 1.0 / 12.0;
    let bits = |v: &[MeshTouch]| -> Vec<(u32, [u64; 7])> {
        v.iter()
            .map(|t| {
                let (n, q) = (t.touch.normal, t.touch.point);
                let b = [t.touch.overlap, n.x, n.y, n.z, q.x, q.y, q.z].map(f64::to_bits);
                (t.patch, b)
            })
            .collect()
    };
    for k in 0..3000 {
        let mut p = DVec3::new(rnd(), rnd(), 0.08 * rnd() - 0.02);
        // Every third point on a triangle's edge or corner in plan view,
        // where the triangles that meet there tie.
        if k % 3 == 0 {
            p.x = (p.x / h).round() * h;
        }
        if k % 6 == 0 {
            p.y = (p.y / h).round() * h;
        }
        let r = 0.02 + 0.1 * rnd();
        let (got, want) = (touches(&m, p, r), touches_by_scan(&m, p, r));
        assert_eq!(bits(&got), bits(&want), "at {p} with r = {r}");
    }
}

#[test]
fn a_patch_bent_within_tolerance_pushes_with_its_face_where_an_edge_is_nearer() {
    // Two rectangles of two triangles meeting along x = 0 in a valley bent
    // by 5e-6 rad each side (within the 1e-5 rad of one patch):
    // z = ε|x|. The right side is wider, so its plane (that of the patch's
    // largest triangle) is the patch's; over the left side it runs below
    // the surface, by 2εX at X from the crease. A grain at height h over
    // the middle of the left side (X = 1/2), just beside the diagonal of
    // the left rectangle: one left triangle meets it at its face, measured
    // from the patch's plane (h + εX, about); the other at the diagonal,
    // nearer (h − εX plus a little). One face contact all the same,
    // whatever order the triangles come in and whichever way they are
    // wound.
    let eps = 5e-6;
    let z = |x: f64| eps * x.abs();
    let v = |x: f64, y: f64| [x, y, z(x)];
    let left = [
        [v(-1.0, -1.0), v(0.0, -1.0), v(0.0, 1.0)],
        [v(-1.0, -1.0), v(0.0, 1.0), v(-1.0, 1.0)],
    ];
    let right = [
        [v(0.0, -1.0), v(2.0, -1.0), v(2.0, 1.0)],
        [v(0.0, -1.0), v(2.0, 1.0), v(0.0, 1.0)],
    ];
    let all: Vec<[[f64; 3]; 3]> = left.iter().chain(&right).copied().collect();
    // The left diagonal runs y = 2x + 1: this is 4.5e-4 from it in plan.
    let p = DVec3::new(-0.5, 0.001, 0.5);
    let r = 0.5 * (1.0 + 1e-5);
    let bits = |t: &MeshTouch| {
        let (n, q) = (t.touch.normal, t.touch.point);
        [t.touch.overlap, n.x, n.y, n.z, q.x, q.y, q.z].map(f64::to_bits)
    };
    let mut seen = [None; 2];
    let mut first = None;
    let mut orders = 0;
    // All 24 orders of the four triangles, each wound both ways.
    for a in 0..4 {
        for b in (0..4).filter(|&b| b != a) {
            for c in (0..4).filter(|&c| c != a && c != b) {
                let d = 6 - a - b - c;
                for flip in [false, true] {
                    let tris: Vec<_> = [a, b, c, d]
                        .iter()
                        .map(|&k| {
                            let [x, y, w] = all[k];
                            if flip {
                                [x, w, y]
                            } else {
                                [x, y, w]
                            }
                        })
                        .collect();
                    let m = mesh(&tris);
                    assert_eq!(m.patches(), 1);
                    // An edge of the patch is nearer than its face.
                    let cands: Vec<Candidate> =
                        (0..4).filter_map(|t| m.candidate(t, p, r)).collect();
                    let face = cands.iter().find(|c| c.rank == 0).expect("a face").dist;
                    assert!(
                        cands.iter().any(|c| c.rank == 1 && c.dist < face),
                        "no edge nearer than the face: {cands:?}"
                    );
                    let got = touches(&m, p, r);
                    assert_eq!(got.len(), 1, "{got:?}");
                    assert_eq!(bits(&got[0]), bits(&touches_by_scan(&m, p, r)[0]));
                    // The face: along the patch's normal, from its plane.
                    let (point, n) = m.planes[0];
                    let s = (p - point).dot(n);
                    let want = if s < 0.0 { -n } else { n };
                    assert_eq!(got[0].touch.normal, want);
                    assert_eq!(got[0].touch.overlap, r - s.abs());
                    // Bit for bit whatever the order; across windings the
                    // same numbers (a zero component may change its sign).
                    match seen[flip as usize] {
                        None => seen[flip as usize] = Some(bits(&got[0])),
                        Some(s) => assert_eq!(s, bits(&got[0]), "order {a}{b}{c}{d} {flip}"),
                    }
                    match first {
                        None => first = Some(got[0].touch),
                        Some(t) => assert_eq!(t, got[0].touch),
                    }
                    orders += 1;
                }
            }
        }
    }
    assert_eq!(orders, 48);
}

/// The contacts as bits (Debug prints each number so that it reads back).
fn bits(t: &[MeshTouch]) -> String {
    format!("{t:?}")
}

#[test]
fn a_grains_list_gives_the_grids_contacts_while_it_stays_within_the_margin() {
    // Half flat, half bumpy (many patches, every kind of contact), with a
    // wall x = 0 standing on it (concave corners).
    let mut tris = flat_sheet(12, 1.0, 0.0);
    for t in &mut tris {
        for v in t.iter_mut() {
            if v[0] > 0.5 {
                v[2] = 0.03 * ((9.0 * v[0]).sin() + (7.0 * v[1]).cos());
            }
        }
    }
    let wall: Vec<_> = flat_sheet(6, 1.0, 0.0)
        .iter()
        .map(|t| t.map(|[x, y, _]| [0.0, y, 0.5 * x]))
        .collect();
    let m = mesh(&[tris, wall].concat());
    let mut rnd = stream(11);
    let margin = 0.04;
    let (mut served, mut touching, mut refused) = (0, 0, 0);
    for _ in 0..400 {
        let c = DVec3::new(rnd() * 1.1 - 0.05, rnd(), 0.12 * rnd() - 0.03);
        let r0 = 0.03 + 0.06 * rnd();
        let lists = MeshCandidates::build(&m, |_| c, &[r0], |_| false, margin);
        for _ in 0..20 {
            // Within the margin, the radius a little smaller or larger,
            // and at times exactly on the margin's bound.
            let dir = DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
            let grow = 0.01 * (rnd() - 0.5);
            let room = margin - grow.max(0.0);
            let step = if rnd() < 0.2 { room } else { room * rnd() };
            let (p, r) = (c + dir * step * (1.0 - 1e-12), r0 + grow);
            let Some(list) = lists.list(0, p, r) else {
                panic!("a grain {step} from its list's centre (margin {margin}) was refused");
            };
            let mut s = MeshScratch::default();
            m.touches_among(p, r, list, &mut s);
            let want = touches(&m, p, r);
            assert_eq!(bits(s.touches()), bits(&want), "at {p}, r {r}");
            served += 1;
            touching += usize::from(!want.is_empty());
            // Past the margin the list is not used.
            if lists.list(0, c + dir * (margin * 1.001), r0).is_none() {
                refused += 1;
            }
        }
    }
    assert_eq!(refused, served);
    // Most of the grains touched the mesh (the test tests something).
    assert!(touching > served / 2, "{touching} of {served}");
}

#[test]
fn a_grain_resting_on_a_large_sheet_reads_one_triangle_from_its_list() {
    // The benchmark's floor (bench/mesh-floor.toml): 224 x 224 squares,
    // 100 352 triangles 0.45 mm wide, under a layer of 1 mm grains in
    // contact; the margin is half the benchmark's skin (0.3 mm).
    let m = mesh(&flat_sheet(224, 0.1, 0.0));
    let (r, margin) = (0.5e-3, 0.15e-3);
    let pos: Vec<DVec3> = (0..10_000)
        .map(|k| {
            let (i, j) = ((k % 100) as f64, (k / 100) as f64);
            DVec3::new(0.5e-3 + i * 1e-3, 0.5e-3 + j * 1e-3, 0.49e-3)
        })
        .collect();
    let radius = vec![r; pos.len()];
    let lists = MeshCandidates::build(&m, |i| pos[i], &radius, |_| false, margin);
    let (grains, listed) = lists.counts();
    assert_eq!(grains, pos.len());
    // Every triangle within r + margin of a centre 0.49 mm above the
    // sheet: a disc of radius √(0.65² − 0.49²) = 0.43 mm, 0.57 mm², some
    // six triangles' area, and those its rim cuts (from 9 to 16 by where
    // the centre falls on the squares).
    let per_grain = listed as f64 / grains as f64;
    assert!(
        (8.0..=16.0).contains(&per_grain),
        "{per_grain} triangles a list"
    );
    // At rest where its list was made, and moved a little since (the
    // foot then at times on the square's other triangle). A grain whose
    // foot lies on a triangle's edge (the lattice puts one in twelve on
    // a diagonal) meets no face and tests its whole list.
    let moves = [
        (DVec3::ZERO, 0.85),
        (DVec3::new(0.05e-3, -0.03e-3, 0.0), 0.6),
    ];
    for (shift, least) in moves {
        let (mut grid_read, mut list_read, mut one) = (0, 0, 0);
        let mut s = MeshScratch::default();
        for (i, &p) in pos.iter().enumerate() {
            let p = p + shift;
            m.touches(p, r, &mut s);
            grid_read += s.tested;
            let want = bits(s.touches());
            let list = lists.list(i, p, r).expect("within the margin");
            m.touches_among(p, r, list, &mut s);
            list_read += s.tested;
            one += usize::from(s.tested == 1);
            assert_eq!(bits(s.touches()), want);
            assert_eq!(s.touches().len(), 1);
        }
        // The list's first triangle is the one under the grain, kept with
        // the list: its face answers for the sheet's one patch, and the
        // other triangles are passed over by their patch's number.
        let (grid, list) = (grid_read as f64 / 1e4, list_read as f64 / 1e4);
        let one = one as f64 / 1e4;
        eprintln!(
            "moved {shift}: triangles tested per lookup: grid {grid}, list {list}; \
             one triangle only: {one}"
        );
        assert!(one >= least, "{one} of the grains tested one triangle");
    }
}
