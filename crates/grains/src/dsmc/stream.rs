//! Streaming: one step of ballistic flight under gravity, x += v τ + g τ²/2,
//! v += g τ; reflection at axis-aligned plane walls (at the wall's place and
//! velocity at the end of the step); periodic wrap; the particle's new cell.
//!
//! A wall reflects a particle whose centre is past its surface (plane + R)
//! at the end of the step: the normal velocity relative to the wall becomes
//! −e_w times itself and the overshoot is mirrored (times e_w).

use super::sort::CellGrid;
use super::store::Particle;
use crate::boundary::Motion;
use crate::dim::Dim;
use crate::domain::Domain;

/// An axis-aligned plane wall, possibly moving (vibrating bottom).
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneWall<D: Dim> {
    pub name: String,
    /// The axis the normal lies along.
    pub axis: usize,
    /// +1 when the particles live on the high side of the plane.
    pub sign: f64,
    /// Coordinate of the plane along `axis` at rest.
    pub offset: f64,
    /// Prescribed motion ([`crate::boundary::Motion`] kinematics).
    pub motion: Motion<D>,
}

impl<D: Dim> PlaneWall<D> {
    /// Whether the displacement is the same at every point of the plane.
    fn is_rigid(&self) -> bool {
        !self.motion.is_modulated()
    }

    /// The plane's coordinate along `axis` and its velocity, at time `t`,
    /// under the point `at` (which only matters for a modulated vibration).
    fn surface(&self, at: D::V, t: f64) -> (f64, D::V) {
        let mut q = at;
        D::set(&mut q, self.axis, self.offset);
        let moved = self.motion.place(q, t);
        (D::get(moved, self.axis), self.motion.velocity_at(moved, t))
    }
}

/// A wall and, when rigid, its place and velocity at the end of the step.
type WallNow<'a, D> = (&'a PlaneWall<D>, Option<(f64, <D as Dim>::V)>);

/// Everything one step of flight needs, evaluated once per step.
pub struct Flight<'a, D: Dim> {
    dt: f64,
    t_end: f64,
    drift: D::V,
    kick: D::V,
    radius: f64,
    wall_restitution: f64,
    walls: Vec<WallNow<'a, D>>,
    /// Per axis: periodic or not, lower and upper bound, length.
    periodic: [bool; 3],
    lo: [f64; 3],
    hi: [f64; 3],
    length: [f64; 3],
    grid: &'a CellGrid,
}

impl<'a, D: Dim> Flight<'a, D> {
    /// The flight from `t` to `t + dt`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        t: f64,
        dt: f64,
        gravity: D::V,
        radius: f64,
        wall_restitution: f64,
        walls: &'a [PlaneWall<D>],
        domain: &Domain<D>,
        grid: &'a CellGrid,
    ) -> Self {
        let t_end = t + dt;
        let (mut periodic, mut lo, mut hi, mut length) = ([false; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
        for a in 0..D::D {
            periodic[a] = domain.is_periodic(a);
            lo[a] = D::get(domain.lo, a);
            length[a] = domain.length(a);
            hi[a] = lo[a] + length[a];
        }
        Self {
            dt,
            t_end,
            drift: gravity * (0.5 * dt * dt),
            kick: gravity * dt,
            radius,
            wall_restitution,
            // Rigid walls: place and velocity once per step.
            walls: walls
                .iter()
                .map(|w| (w, w.is_rigid().then(|| w.surface(D::zero(), t_end))))
                .collect(),
            periodic,
            lo,
            hi,
            length,
            grid,
        }
    }

    /// Moves `q` over the step and returns its new cell.
    #[inline(always)]
    pub fn advance(&self, q: &mut Particle<D>) -> u32 {
        let mut x = q.x + q.v * self.dt + self.drift;
        let mut v = q.v + self.kick;
        let ew = self.wall_restitution;
        for (w, rigid) in &self.walls {
            let (plane, u) = match rigid {
                Some(s) => *s,
                None => w.surface(x, self.t_end),
            };
            let touch = plane + w.sign * self.radius;
            let pen = w.sign * (touch - D::get(x, w.axis));
            if pen > 0.0 {
                let ua = D::get(u, w.axis);
                let vn = D::get(v, w.axis) - ua;
                if w.sign * vn < 0.0 {
                    D::set(&mut v, w.axis, ua - ew * vn);
                }
                D::set(&mut x, w.axis, touch + w.sign * ew * pen);
            }
        }
        for a in 0..D::D {
            let xa = D::get(x, a);
            if self.periodic[a] && (xa < self.lo[a] || xa >= self.hi[a]) {
                let (lo, l) = (self.lo[a], self.length[a]);
                let mut w = xa - l * ((xa - lo) / l).floor();
                if w >= self.hi[a] {
                    w -= l;
                }
                D::set(&mut x, a, w);
            }
        }
        q.x = x;
        q.v = v;
        self.grid.cell_of::<D>(x)
    }
}
