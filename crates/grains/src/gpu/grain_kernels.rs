//! What one GPU thread does for one grain: the kernels of the pipeline as
//! plain functions of a grain index, over structure-of-arrays data.
//!
//! `kernels/*.cu` are these functions in CUDA C, operation for operation:
//! the vector helpers below keep glam's evaluation order (a dot product is
//! `(x x' + y y') + z z'`, a cross product `y z' − y' z, …`), which is the
//! CPU engine's, so that without fused multiply-add the three agree bit for
//! bit. Change one, change the other (`tools/make_ptx.py` rebuilds the PTX).
//!
//! Here: the vector helpers, the force and integration kernels and the step
//! words; the list build's kernels are in [`list`].

pub mod list;

pub use list::{
    axis_cells, list_capacity, mirrored, morton_places, order_row, remap_row, row_key,
    visit_partners, wrap, AxisCells, Bins, Box3, Grid, ListArgs,
};

/// A 3-vector in registers.
pub type V3 = [f64; 3];

/// One vector quantity per grain (or per list entry), a component per array.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Soa3 {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Soa3 {
    pub fn zeros(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
        }
    }

    pub fn from_vecs(v: impl Iterator<Item = V3>) -> Self {
        let mut s = Self::default();
        for [a, b, c] in v {
            s.x.push(a);
            s.y.push(b);
            s.z.push(c);
        }
        s
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    #[inline(always)]
    pub fn get(&self, i: usize) -> V3 {
        [self.x[i], self.y[i], self.z[i]]
    }

    #[inline(always)]
    pub fn set(&mut self, i: usize, v: V3) {
        self.x[i] = v[0];
        self.y[i] = v[1];
        self.z[i] = v[2];
    }

    /// Entry k of the result is entry `order[k]` of this one.
    pub fn gather(&self, order: &[u32]) -> Self {
        Self::from_vecs(order.iter().map(|&k| self.get(k as usize)))
    }
}

#[inline(always)]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub fn neg(a: V3) -> V3 {
    [-a[0], -a[1], -a[2]]
}

#[inline(always)]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// glam's order: x = a.y b.z − b.y a.z, and so on.
#[inline(always)]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - b[1] * a[2],
        a[2] * b[0] - b[2] * a[0],
        a[0] * b[1] - b[0] * a[1],
    ]
}

#[inline(always)]
pub fn is_zero(a: V3) -> bool {
    a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0
}

/// Coefficients of the Hooke law with history (LAMMPS
/// `gran/hooke/history`): the CPU engine's own kernel, as the run's law
/// resolved it ([`crate::contact::Law::hooke_history`]), laid out as
/// `Hooke` in `kernels/common.cuh`.
pub use crate::contact::hooke_history::HookeHistory as Hooke;

/// A contact's result: the force on the first body and the vector whose
/// multiples by each radius are the torques to subtract.
#[derive(Clone, Copy, Debug)]
pub struct Push {
    pub force: V3,
    /// n × F_t.
    pub nt: V3,
}

/// The Hooke law with history on one contact: normal `n`, overlap, relative
/// velocity at the contact point, damping mass; updates `spring` (kept in
/// the tangent plane, cut back to the Coulomb cap while sliding). The
/// operations of `contact::law::spring_dashpot` with the Cundall–Strack
/// spring of `contact::cundall_strack` (`known` shape: spring on, cap
/// finite).
#[inline(always)]
pub fn hooke(
    law: &Hooke,
    (n, overlap, v_rel, damping_mass): (V3, f64, V3, f64),
    spring: &mut V3,
    (dt, update): (f64, bool),
) -> Push {
    let vn = dot(v_rel, n);
    let fn_total = law.kn * overlap + -law.gamma_n * damping_mass * vn;
    let vt = sub(v_rel, scale(n, vn));
    let gamma = law.gamma_t * damping_mass;
    if update {
        *spring = add(*spring, scale(vt, dt));
        let along = dot(*spring, n);
        *spring = sub(*spring, scale(n, along));
    }
    let fs = neg(add(scale(*spring, law.kt), scale(vt, gamma)));
    let cap = law.mu * fn_total.abs();
    let fs2 = dot(fs, fs);
    let sliding = fs2 > cap * cap;
    let s = cap / fs2.sqrt();
    let s2 = dot(*spring, *spring);
    let cut = sliding && s2 != 0.0;
    let kill = sliding && s2 == 0.0;
    let damp = scale(vt, gamma / law.kt);
    let cut_spring = sub(scale(add(*spring, damp), s), damp);
    if cut {
        *spring = cut_spring;
    }
    let capped = if sliding { scale(fs, s) } else { fs };
    let tangential = if kill { [0.0; 3] } else { capped };
    Push {
        force: add(scale(n, fn_total), tangential),
        nt: cross(n, tangential),
    }
}

/// Reduced mass of a contact, a frozen grain counting as infinitely heavy.
#[inline(always)]
pub fn damping_mass(mi: f64, frozen_i: bool, mj: f64, frozen_j: bool) -> f64 {
    if frozen_j {
        mi
    } else if frozen_i {
        mj
    } else {
        mi * mj / (mi + mj)
    }
}

/// The grains as the force kernel reads them.
pub struct GrainsIn<'a> {
    pub pos: &'a Soa3,
    pub vel: &'a Soa3,
    pub omega: &'a Soa3,
    pub radius: &'a [f64],
    pub mass: &'a [f64],
    pub frozen: &'a [u8],
    /// Each grain's index in the CPU engine's order: it decides a pair's
    /// orientation (lower rank first), whatever order the arrays are in.
    pub rank: &'a [u32],
}

/// The full neighbour list: grain g's entries are `start[g]..start[g + 1]`,
/// each a partner and the image code of the pair's lower index.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FullList {
    pub start: Vec<u32>,
    pub partner: Vec<u32>,
    pub image: Vec<u8>,
}

impl FullList {
    #[inline(always)]
    pub fn row(&self, g: usize) -> std::ops::Range<usize> {
        self.start[g] as usize..self.start[g + 1] as usize
    }
}

/// A fixed plane wall: point, unit normal, and the normal damping of its
/// contacts (0 for an elastic wall).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub point: V3,
    pub normal: V3,
    pub gamma_n: f64,
}

/// What the force kernel needs besides the grains.
pub struct ForceArgs<'a> {
    pub law: Hooke,
    pub list: &'a FullList,
    pub shifts: &'a [V3; 27],
    pub walls: &'a [Plane],
    pub gravity: V3,
    pub dt: f64,
    pub update: bool,
}

/// One grain's sums and statistics from the force kernel.
#[derive(Clone, Copy, Debug, Default)]
pub struct GrainForce {
    pub force: V3,
    pub torque: V3,
    /// Contacts with other grains (each pair is counted in both rows).
    pub pair_contacts: u32,
    pub wall_contacts: u32,
    /// Largest overlap over the smaller radius among its contacts.
    pub max_fraction: f64,
}

/// The force kernel for grain `g`: its contacts in its row's order (each in
/// the pair's canonical orientation, lower index first, as the CPU engine
/// evaluates it), its wall contacts in wall order, gravity. Writes the
/// springs of its own row (`springs`) and of its own wall contacts
/// (`wall_springs`, `walls.len()` per grain), nothing else.
pub fn grain_forces(
    g: &GrainsIn,
    a: &ForceArgs,
    gi: usize,
    springs: &mut Soa3,
    wall_springs: &mut Soa3,
) -> GrainForce {
    let mut out = GrainForce::default();
    let mut f = [0.0; 3];
    let mut t = [0.0; 3];
    for e in a.list.row(gi) {
        let p = a.list.partner[e] as usize;
        let (i, j) = if g.rank[gi] < g.rank[p] {
            (gi, p)
        } else {
            (p, gi)
        };
        let del = sub(
            g.pos.get(i),
            add(g.pos.get(j), a.shifts[a.list.image[e] as usize]),
        );
        let (ri, rj) = (g.radius[i], g.radius[j]);
        let radsum = ri + rj;
        let r2 = dot(del, del);
        if r2 >= radsum * radsum {
            springs.set(e, [0.0; 3]);
            continue;
        }
        let r = r2.sqrt();
        let overlap = ri + rj - r;
        let n = scale(del, 1.0 / r);
        let spin = add(scale(g.omega.get(i), ri), scale(g.omega.get(j), rj));
        let v_rel = sub(sub(g.vel.get(i), g.vel.get(j)), cross(spin, n));
        let (fi, fj) = (g.frozen[i] != 0, g.frozen[j] != 0);
        let dm = damping_mass(g.mass[i], fi, g.mass[j], fj);
        let mut spring = springs.get(e);
        let push = hooke(
            &a.law,
            (n, overlap, v_rel, dm),
            &mut spring,
            (a.dt, a.update),
        );
        springs.set(e, spring);
        if gi == i {
            f = add(f, push.force);
            t = sub(t, scale(push.nt, ri));
        } else {
            f = add(f, neg(push.force));
            t = sub(t, scale(push.nt, rj));
        }
        out.pair_contacts += 1;
        out.max_fraction = out.max_fraction.max(overlap / ri.min(rj));
    }
    let nw = a.walls.len();
    if g.frozen[gi] == 0 {
        let (x, r, m) = (g.pos.get(gi), g.radius[gi], g.mass[gi]);
        for (w, wall) in a.walls.iter().enumerate() {
            let k = gi * nw + w;
            let s = dot(sub(x, wall.point), wall.normal);
            let overlap = r - s;
            if overlap <= 0.0 || s < -r {
                wall_springs.set(k, [0.0; 3]);
                continue;
            }
            let n = wall.normal;
            let v_rel = sub(g.vel.get(gi), cross(scale(g.omega.get(gi), r), n));
            let law = Hooke {
                gamma_n: wall.gamma_n,
                ..a.law
            };
            let mut spring = wall_springs.get(k);
            let push = hooke(&law, (n, overlap, v_rel, m), &mut spring, (a.dt, a.update));
            // A spring that is not stretched is kept as +0 (the CPU
            // engine keeps none).
            wall_springs.set(k, if is_zero(spring) { [0.0; 3] } else { spring });
            f = add(f, push.force);
            t = sub(t, scale(push.nt, r));
            out.wall_contacts += 1;
            out.max_fraction = out.max_fraction.max(overlap / r);
        }
        f = add(f, scale(a.gravity, m));
    }
    out.force = f;
    out.torque = t;
    out
}

/// The grains as the integration kernel changes them.
pub struct Moving<'a> {
    pub pos: &'a mut Soa3,
    pub vel: &'a mut Soa3,
    pub omega: &'a mut Soa3,
}

/// Inputs of the integration kernel.
pub struct KickArgs<'a> {
    pub force: &'a Soa3,
    pub torque: &'a Soa3,
    pub inv_mass: &'a [f64],
    pub inv_inertia: &'a [f64],
    pub frozen: &'a [u8],
    /// Positions at the last list build, and (skin/2)².
    pub reference: &'a Soa3,
    pub limit2: f64,
    pub dt: f64,
}

/// Velocity Verlet for grain `g` (LAMMPS `nve/sphere`): `kicks` half-kicks
/// (the corrector of one step, the predictor of the next, or one of them),
/// the drift when `drift`. Returns whether the grain now stands farther than
/// the skin test allows from its reference (checked only after a drift),
/// and, when `check`, whether a mobile grain's position or velocity after
/// the first kick is not finite.
#[inline(always)]
pub fn kick_drift(
    m: &mut Moving,
    a: &KickArgs,
    g: usize,
    (kicks, drift, check): (u32, bool, bool),
) -> (bool, bool) {
    let mut bad = false;
    if a.frozen[g] == 0 {
        let half = 0.5 * a.dt;
        let kick = half * a.inv_mass[g];
        let spin_kick = half * a.inv_inertia[g];
        let f = a.force.get(g);
        let tq = a.torque.get(g);
        let mut v = m.vel.get(g);
        let mut w = m.omega.get(g);
        for k in 0..kicks {
            v = add(v, scale(f, kick));
            w = add(w, scale(tq, spin_kick));
            if check && k == 0 {
                let x = m.pos.get(g);
                bad = !(x.iter().all(|c| c.is_finite()) && v.iter().all(|c| c.is_finite()));
            }
        }
        m.vel.set(g, v);
        m.omega.set(g, w);
        if drift {
            m.pos.set(g, add(m.pos.get(g), scale(v, a.dt)));
        }
    }
    if !drift {
        return (false, bad);
    }
    let d = sub(m.pos.get(g), a.reference.get(g));
    (dot(d, d) > a.limit2, bad)
}

/// The step words: flags and counters in device memory that the kernels
/// read and write (`ST_*` of common.cuh), so that a stretch of steps runs
/// with no decision on the host. Only integer stores, and the maximum of a
/// non-negative double as the maximum of its bits.
pub mod words {
    /// A grain beyond the skin test (set by the drift).
    pub const FAR: usize = 0;
    /// A grain found not finite (set by a checking kick).
    pub const NONFINITE: usize = 1;
    /// Pair-contact ends, wall contacts, bits of the largest overlap
    /// fraction: the last force evaluation's statistics.
    pub const PAIR_ENDS: usize = 2;
    pub const WALLS: usize = 3;
    pub const MAX_FRACTION: usize = 4;
    /// This step rebuilds the list; this step re-sorts too.
    pub const BUILD: usize = 5;
    pub const SORT: usize = 6;
    /// List builds so far (its parity names the current list buffer), and
    /// rebuilds since the last re-sort (the CPU engine's counters).
    pub const BUILDS: usize = 7;
    pub const SINCE_SORT: usize = 8;
    /// Why the stretch stopped (0: it did not), at which step, and how
    /// many entries the list needed when it overflowed its buffer.
    pub const HALT: usize = 9;
    pub const HALT_STEP: usize = 10;
    pub const NEED: usize = 11;
    /// Steps taken: the launches of a step read it rather than take it as
    /// an argument, so that every step launches the same (a CUDA graph).
    pub const STEP: usize = 12;
    pub const LEN: usize = 13;

    /// HALT's values.
    pub const HALT_OVERLAP: u64 = 1;
    pub const HALT_NONFINITE: u64 = 2;
    pub const HALT_OVERFLOW: u64 = 3;
}

/// Whether a gated kernel runs: nothing has halted the stretch and, unless
/// `word` is `None`, that word is set.
#[inline(always)]
pub fn gate(st: &[u64; words::LEN], word: Option<usize>) -> bool {
    st[words::HALT] == 0 && word.is_none_or(|w| st[w] != 0)
}

/// The one-thread kernel that opens the next step: a grain found not
/// finite by the last kick halts the stretch (at the step before);
/// otherwise the step is counted, the rebuild (a grain beyond the skin
/// test, or no list yet) and the re-sort (every `sort_every` rebuilds)
/// decided, and the step's flags and statistics cleared.
pub fn step_begin(st: &mut [u64; words::LEN], sort_every: u32) {
    use words::*;
    if st[HALT] != 0 {
        return;
    }
    if st[NONFINITE] != 0 {
        st[HALT] = HALT_NONFINITE;
        st[HALT_STEP] = st[STEP];
        return;
    }
    st[STEP] += 1;
    let build = st[FAR] != 0 || st[BUILDS] == 0;
    let since = st[SINCE_SORT] as u32;
    st[BUILD] = build as u64;
    st[SORT] = (build && sort_every > 0 && since.is_multiple_of(sort_every)) as u64;
    if build {
        st[SINCE_SORT] = since.wrapping_add(1) as u64;
    }
    for w in [FAR, PAIR_ENDS, WALLS, MAX_FRACTION] {
        st[w] = 0;
    }
}
