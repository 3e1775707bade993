//! What one GPU thread does for one grain: the kernels of the pipeline as
//! plain functions of a grain index, over structure-of-arrays data.
//!
//! `kernels/*.cu` are these functions in CUDA C, operation for operation:
//! the vector helpers below keep glam's evaluation order (a dot product is
//! `(x x' + y y') + z z'`, a cross product `y z' − y' z, …`), which is the
//! CPU engine's, so that without fused multiply-add the three agree bit for
//! bit. Change one, change the other (`tools/make_ptx.py` rebuilds the PTX).

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

/// Coefficients of the Hooke law with history (LAMMPS `gran/hooke/history`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hooke {
    pub kn: f64,
    pub gamma_n: f64,
    pub gamma_t: f64,
    pub kt: f64,
    pub mu: f64,
}

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

/// The periodic box, per axis: lower bound, length (0 on an axis that is
/// not periodic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Box3 {
    pub lo: V3,
    pub length: V3,
    pub periodic: [bool; 3],
}

/// `Domain::wrap`: a coordinate outside a periodic axis's [lo, lo + L)
/// moved back by whole lengths.
#[inline(always)]
pub fn wrap(b: &Box3, mut p: V3) -> V3 {
    for (a, x) in p.iter_mut().enumerate() {
        if !b.periodic[a] {
            continue;
        }
        let (lo, l) = (b.lo[a], b.length[a]);
        if *x < lo || *x >= lo + l {
            *x -= l * ((*x - lo) / l).floor();
            if *x >= lo + l {
                *x -= l;
            }
        }
    }
    p
}

/// A cell grid (`neighbors::cell_grid::GridShape`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub dims: [usize; 3],
    pub lo: V3,
    pub inv_width: V3,
}

impl Grid {
    #[inline(always)]
    pub fn coord(&self, a: usize, x: f64) -> usize {
        let f = (x - self.lo[a]) * self.inv_width[a];
        (f.max(0.0) as usize).min(self.dims[a] - 1)
    }

    #[inline(always)]
    pub fn cell_of(&self, p: V3) -> usize {
        self.coord(0, p[0])
            + self.dims[0] * (self.coord(1, p[1]) + self.dims[1] * self.coord(2, p[2]))
    }

    pub fn ncells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }
}

/// Grains binned into cells: cell c holds `members[start[c]..start[c + 1]]`,
/// ascending.
#[derive(Clone, Debug, Default)]
pub struct Bins {
    pub start: Vec<u32>,
    pub members: Vec<u32>,
    pub cell: Vec<u32>,
}

/// The cells of one axis a grain's stencil visits, with their image
/// digits (−1, 0, +1), as the CPU list build visits them.
#[derive(Clone, Copy, Debug)]
pub struct AxisCells {
    pub cells: [(usize, i32); 3],
    pub len: usize,
    /// Periodic with fewer than 3 cells: the image is the minimum one.
    pub min_image: bool,
}

#[inline(always)]
pub fn axis_cells(n: usize, periodic: bool, c: usize) -> AxisCells {
    let mut st = AxisCells {
        cells: [(0, 0); 3],
        len: 0,
        min_image: false,
    };
    if periodic && n < 3 {
        for k in 0..n {
            st.cells[k] = (k, 0);
        }
        st.len = n;
        st.min_image = true;
    } else if periodic {
        let below = if c == 0 { (n - 1, -1) } else { (c - 1, 0) };
        let above = if c + 1 == n { (0, 1) } else { (c + 1, 0) };
        st.cells = [below, (c, 0), above];
        st.len = 3;
    } else {
        let mut k = c.saturating_sub(1);
        while k <= (c + 1).min(n - 1) {
            st.cells[st.len] = (k, 0);
            st.len += 1;
            k += 1;
        }
    }
    st
}

/// What the list kernels read.
pub struct ListArgs<'a> {
    pub pos: &'a Soa3,
    pub radius: &'a [f64],
    pub frozen: &'a [u8],
    /// CPU-order index of each grain (rows are ordered by it).
    pub rank: &'a [u32],
    pub bins: &'a Bins,
    pub grid: Grid,
    pub periodic: [bool; 3],
    pub length: V3,
    pub shifts: &'a [V3; 27],
    pub skin: f64,
    /// Grains per block of the CPU engine's pair reduction.
    pub block: usize,
}

/// The list kernel for grain `g`: visits its stencil (z, y, x; members
/// by ascending rank) and calls `found(partner, image code of g's side)` for every
/// partner within r_g + r_p + skin. Run twice: to count, then to fill.
#[inline(always)]
pub fn visit_partners(a: &ListArgs, g: usize, mut found: impl FnMut(usize, usize)) {
    let grid = &a.grid;
    let pg = a.pos.get(g);
    let rg = a.radius[g];
    let fg = a.frozen[g] != 0;
    let cell = a.bins.cell[g] as usize;
    let c = [
        cell % grid.dims[0],
        cell / grid.dims[0] % grid.dims[1],
        cell / grid.dims[0] / grid.dims[1],
    ];
    let st = [
        axis_cells(grid.dims[0], a.periodic[0], c[0]),
        axis_cells(grid.dims[1], a.periodic[1], c[1]),
        axis_cells(grid.dims[2], a.periodic[2], c[2]),
    ];
    let any_min_image = st[0].min_image || st[1].min_image || st[2].min_image;
    const POW3: [i32; 3] = [1, 3, 9];
    for &(z, sz) in &st[2].cells[..st[2].len] {
        for &(y, sy) in &st[1].cells[..st[1].len] {
            for &(x, sx) in &st[0].cells[..st[0].len] {
                let base = 13 + sx + 3 * sy + 9 * sz;
                let cl = x + grid.dims[0] * (y + grid.dims[1] * z);
                let members = a.bins.start[cl] as usize..a.bins.start[cl + 1] as usize;
                for &p in &a.bins.members[members] {
                    let p = p as usize;
                    if p == g || (fg && a.frozen[p] != 0) {
                        continue;
                    }
                    let pp = a.pos.get(p);
                    let mut code = base;
                    if any_min_image {
                        for ax in 0..3 {
                            if st[ax].min_image {
                                let dx = pg[ax] - pp[ax];
                                code += (dx / a.length[ax]).round() as i32 * POW3[ax];
                            }
                        }
                    }
                    let d = sub(sub(pg, pp), a.shifts[code as usize]);
                    let cut = rg + a.radius[p] + a.skin;
                    if dot(d, d) < cut * cut {
                        found(p, code as usize);
                    }
                }
            }
        }
    }
}

/// Where an entry of the row of the grain of rank g goes (p: the partner's
/// rank): lower partners of g's own block first (ascending), then higher
/// partners (in stencil order), then lower partners of earlier blocks
/// (ascending): the order in which the CPU engine's block reduction sums
/// g's contacts.
#[inline(always)]
pub fn row_key(g: usize, p: usize, block: usize) -> (u32, u32) {
    if p > g {
        (1, 0)
    } else if p >= g / block * block {
        (0, p as u32)
    } else {
        (2, p as u32)
    }
}

/// The fill kernel's last part for grain `g`: its row, written in stencil
/// order, put in the order of [`row_key`] (on ranks) by a stable insertion
/// sort in place (rows hold about a dozen entries).
pub fn order_row(list: &mut FullList, g: usize, block: usize, rank: &[u32]) {
    let r = list.row(g);
    let key_of = |p: u32| row_key(rank[g] as usize, rank[p as usize] as usize, block);
    for k in r.start + 1..r.end {
        let (p, code) = (list.partner[k], list.image[k]);
        let key = key_of(p);
        let mut m = k;
        while m > r.start && key_of(list.partner[m - 1]) > key {
            list.partner[m] = list.partner[m - 1];
            list.image[m] = list.image[m - 1];
            m -= 1;
        }
        list.partner[m] = p;
        list.image[m] = code;
    }
}

/// The image code of the other side of a pair (3D: each digit d becomes
/// 2 − d).
#[inline(always)]
pub fn mirrored(code: usize) -> usize {
    26 - code
}

/// The remap kernel for grain `g` after a rebuild: each new entry's spring
/// from the old list, found through `old_of` (the old index of each grain
/// after a re-sort; `None`: the grains kept their places), negated when the
/// pair's lower rank changed sides (`rank` now, `old_rank` by old index);
/// zero when the pair is new or its spring was not stretched.
pub fn remap_row(
    g: usize,
    (new, old): (&FullList, &FullList),
    old_of: Option<&[u32]>,
    (rank, old_rank): (&[u32], &[u32]),
    (old_springs, springs): (&Soa3, &mut Soa3),
) {
    let at = |k: usize| old_of.map_or(k, |o| o[k] as usize);
    let og = at(g);
    for e in new.row(g) {
        let p = new.partner[e] as usize;
        let op = at(p);
        let mut s = [0.0; 3];
        for k in old.row(og) {
            if old.partner[k] as usize == op {
                let o = old_springs.get(k);
                if !is_zero(o) {
                    s = if (rank[g] < rank[p]) == (old_rank[og] < old_rank[op]) {
                        o
                    } else {
                        neg(o)
                    };
                }
                break;
            }
        }
        springs.set(e, s);
    }
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

/// Entries a list buffer is given for `need` entries: a quarter more, so
/// that the list can grow a while before the stretch halts to reallocate.
pub fn list_capacity(need: usize) -> usize {
    need + need / 4 + 1024
}

/// Each cell's place in Morton order (bits of the x, y, z cell coordinates
/// interleaved, x lowest): cells near in space get near places, so grains
/// stored cell by cell in this order lie near in memory along all three
/// axes, not only along x.
pub fn morton_places(grid: &Grid) -> Vec<u32> {
    fn spread(mut v: u64) -> u64 {
        // 21 bits, each moved to every third place.
        v &= 0x1f_ffff;
        v = (v | v << 32) & 0x1f00000000ffff;
        v = (v | v << 16) & 0x1f0000ff0000ff;
        v = (v | v << 8) & 0x100f00f00f00f00f;
        v = (v | v << 4) & 0x10c30c30c30c30c3;
        (v | v << 2) & 0x1249249249249249
    }
    let [nx, ny, _] = grid.dims;
    let mut cells: Vec<(u64, u32)> = (0..grid.ncells())
        .map(|c| {
            let (x, y, z) = (c % nx, c / nx % ny, c / nx / ny);
            let code = spread(x as u64) | spread(y as u64) << 1 | spread(z as u64) << 2;
            (code, c as u32)
        })
        .collect();
    cells.sort_unstable();
    let mut place = vec![0u32; cells.len()];
    for (k, &(_, c)) in cells.iter().enumerate() {
        place[c as usize] = k as u32;
    }
    place
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a 4 × 4 × 4 grid every Morton code below 64 is a cell, so a
    /// cell's place is its code: x bits at 0 and 3, y at 1 and 4, z at 2
    /// and 5. On an uneven grid the places are a permutation.
    #[test]
    fn morton_places_interleave_the_cell_bits() {
        let grid = |dims| Grid {
            dims,
            lo: [0.0; 3],
            inv_width: [1.0; 3],
        };
        let places = morton_places(&grid([4, 4, 4]));
        let bit = |v: usize, b: usize| (v >> b) & 1;
        for (c, &place) in places.iter().enumerate() {
            let (x, y, z) = (c % 4, c / 4 % 4, c / 16);
            let code = (0..2)
                .map(|b| (bit(x, b) | bit(y, b) << 1 | bit(z, b) << 2) << (3 * b))
                .sum::<usize>();
            assert_eq!(place as usize, code, "cell ({x}, {y}, {z})");
        }
        let mut uneven = morton_places(&grid([5, 3, 7]));
        uneven.sort_unstable();
        assert_eq!(uneven, (0..105).collect::<Vec<u32>>());
    }
}
