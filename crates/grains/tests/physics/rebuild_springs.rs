//! Tangential springs carried across neighbour-list rebuilds: a pair whose
//! index order flips under the spatial sort, and a pair that changes
//! periodic image, keep their spring (sign and length), checked against
//! the spring integrated by hand along the known straight-line motion.

use crate::common;

use common::*;
use glam::DVec2;
use grains::contact::{ContactLaw, MassScaling};
use grains::integrate::Integrator;
use grains::md::{Md, MdSettings};
use grains::{Domain, ParticleRecord, Particles, D2};

const L: f64 = 10.0;
const DT: f64 = 1.0e-3;
/// Sliding speed of the moving grain of each pair.
const U: f64 = 1.0;
/// Height of the moving grain's line above its partner's centre: an
/// overlap of 3 % of d while they pass.
const H: f64 = 0.97;
/// Mass of every grain: so heavy that the contact forces change no
/// velocity within round-off, so the motion is known by hand.
const HEAVY: f64 = 1.0e15;

/// A grain of diameter 1 with the given id, position and velocity.
fn heavy(id: u64, pos: DVec2, vel: DVec2) -> ParticleRecord<D2> {
    let mut g = ParticleRecord::new(id, pos, 0.5, HEAVY, 0.1 * HEAVY);
    g.vel = vel;
    g
}

/// The spring of a Cundall–Strack contact as `contact/cundall_strack.rs`
/// documents it (add v_t dt, then drop the normal part; zero when apart),
/// integrated along the motion each step's force sees: the mover of a pair
/// at `a0 + U x̂ k dt`, its partner at rest at `b`, in the periodic box.
struct HandSpring {
    a0: DVec2,
    b: DVec2,
    s: DVec2,
}

impl HandSpring {
    fn step(&mut self, k: u64) {
        let a = self.a0 + DVec2::new(U * k as f64 * DT, 0.0);
        let mut del = a - self.b;
        del.x -= L * (del.x / L).round();
        let r = del.length();
        if r >= 1.0 {
            self.s = DVec2::ZERO;
            return;
        }
        let n = del / r;
        let v = DVec2::new(U, 0.0);
        let vt = v - n * v.dot(n);
        self.s += vt * DT;
        self.s -= n * self.s.dot(n);
    }
}

/// The spring of the pair (a, b) in the engine, oriented as the
/// displacement of `a` (the engine stores it for its pair order `[i, j]`),
/// whether `a` is the pair's first grain, and the pair's image code.
fn engine_spring(md: &Md<D2>, a: u64, b: u64) -> Option<(DVec2, bool, u8)> {
    let st = md.export_state().unwrap();
    let id = &st.particles.id;
    st.list
        .pairs
        .iter()
        .zip(&st.springs)
        .zip(&st.list.image)
        .find_map(|((&[i, j], &s), &code)| {
            let (gi, gj) = (id[i as usize], id[j as usize]);
            if (gi, gj) == (a, b) {
                Some((s, true, code))
            } else if (gi, gj) == (b, a) {
                Some((-s, false, code))
            } else {
                None
            }
        })
}

/// What one run saw: whether the pair's order flipped and whether its
/// image changed while the spring was stretched.
#[derive(Default, Debug)]
struct Seen {
    flipped: bool,
    image_changed: bool,
}

/// Height of the middle pair's resting grain: the sort's cells are
/// 10/9 m (the list's cut-off 2 r + skin, rounded up to divide the box),
/// and both grains of the pair lie in the same row of them, [−2.78, −1.67),
/// so that their order follows their x cells.
const YB: f64 = -2.72;

/// Runs two pairs past each other: pair (0, 1) in the middle of the box at
/// `xb`, pair (2, 3) across the periodic boundary at x = 0 = L. Checks
/// every step's springs against [`HandSpring`] and returns what happened.
fn run_pairs(xb: f64) -> [Seen; 2] {
    let law = ContactLaw {
        kt: 2.0e3,
        mu: f64::INFINITY,
        ..hooke(1.0e4, 0.0, MassScaling::Reduced)
    };
    let mut s = MdSettings::<D2>::new(DT, law, 0.02);
    s.integrator = Integrator::Verlet;
    // Sort at every rebuild, so the pairs' index order follows the cells.
    s.sort_every = 1;
    let domain = Domain::new(
        DVec2::new(0.0, -5.0),
        DVec2::new(L, 5.0),
        [true, false, false],
    );
    let start = 0.3;
    let pairs = [
        (DVec2::new(xb - start, YB + H), DVec2::new(xb, YB)),
        (DVec2::new(L - start + 0.1, 2.0 + H), DVec2::new(0.1, 2.0)),
    ];
    let mut p = Particles::new();
    for (k, &(a, b)) in pairs.iter().enumerate() {
        p.push_record(heavy(2 * k as u64, a, DVec2::new(U, 0.0)));
        p.push_record(heavy(2 * k as u64 + 1, b, DVec2::ZERO));
    }
    let mut md = Md::new(p, domain, Vec::new(), s).unwrap();
    let mut hand = pairs.map(|(a0, b)| HandSpring {
        a0,
        b,
        s: DVec2::ZERO,
    });
    let mut seen = [Seen::default(), Seen::default()];
    let mut last: [Option<(bool, u8)>; 2] = [None, None];
    let builds0 = md.neighbor_builds();
    let steps = (2.0 * start / (U * DT)) as u64;
    for k in 1..=steps {
        md.step().unwrap();
        for (q, h) in hand.iter_mut().enumerate() {
            h.step(k);
            let (a, b) = (2 * q as u64, 2 * q as u64 + 1);
            let got = engine_spring(&md, a, b);
            let (s, first, code) = got.unwrap_or((DVec2::ZERO, true, 0));
            // The spring grows to about 0.3 m; round-off of the two sums
            // (and velocity changes of 1e-15 relative) stay far below 1e-9.
            assert!(
                (s - h.s).length() <= 1e-9 * h.s.length().max(1e-3),
                "pair {q}, xb = {xb}, step {k}: engine {s}, by hand {}",
                h.s
            );
            if h.s != DVec2::ZERO {
                if let (Some((f0, c0)), Some(_)) = (last[q], got) {
                    seen[q].flipped |= f0 != first;
                    seen[q].image_changed |= c0 != code;
                }
                last[q] = got.map(|(_, f, c)| (f, c));
            }
        }
    }
    // The springs were stretched and the run rebuilt its list many times.
    assert!(hand.iter().all(|h| h.s == DVec2::ZERO), "pairs still touch");
    assert!(md.neighbor_builds() - builds0 > 20, "too few rebuilds");
    seen
}

#[test]
fn springs_keep_sign_and_length_when_pair_order_flips_or_image_changes() {
    // Place the middle pair at several points across a sort cell (about
    // 1.0 m wide) so that in some runs the mover crosses into the next cell
    // while touching, which puts it after its partner in the sorted order.
    let mut flips = 0;
    let mut image_changes = 0;
    for k in 0..12 {
        let [middle, edge] = run_pairs(3.0 + 0.1 * k as f64);
        flips += middle.flipped as usize + edge.flipped as usize;
        image_changes += edge.image_changed as usize;
    }
    eprintln!("{flips} order flips, {image_changes} image changes while stretched");
    assert!(flips > 0, "no run flipped a touching pair's order");
    assert_eq!(image_changes, 12, "the edge pair must change image");
}
