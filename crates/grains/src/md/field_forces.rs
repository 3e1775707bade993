//! Forces that act on one grain at a time: contacts with walls and gravity.
//! Grains are independent here: the pair loop adds them block by block,
//! in parallel, once a block's contact sums are complete (one pass over the
//! force sums fewer); each grain's sum is formed in wall order, whatever
//! the threads.

use super::wall_springs::{ChunkSprings, WallSprings};
use super::MdStats;
use crate::boundary::PlacedWall;
use crate::contact::ContactLaw;
use crate::dim::Dim;

pub struct FieldInput<'a, D: Dim> {
    pub law: &'a ContactLaw,
    /// The walls placed at the evaluation's time, once for all blocks.
    pub walls: &'a [PlacedWall<'a, D>],
    pub gravity: D::V,
    pub dt: f64,
    pub update: bool,
}

#[derive(Clone, Copy, Debug, Default)]
struct PartStats {
    contacts: usize,
    max_overlap: f64,
    max_fraction: f64,
    worst: u64,
}

/// The per-grain arrays the contact loops read (the pair loop and the
/// wall contacts).
pub struct GrainView<'a, D: Dim> {
    pub pos: &'a [D::V],
    pub vel: &'a [D::V],
    pub omega: &'a [D::A],
    pub radius: &'a [f64],
    pub mass: &'a [f64],
    pub frozen: &'a [bool],
    pub id: &'a [u64],
    /// Grains past this index (ghosts) get no field force.
    pub owned: usize,
}

/// One range of grains' wall contacts and gravity, and their springs.
pub struct FieldPart<D: Dim> {
    stats: PartStats,
    kept: ChunkSprings<D>,
}

impl<D: Dim> FieldInput<'_, D> {
    /// Whether there is anything to add.
    pub fn acts(&self) -> bool {
        !self.walls.is_empty() || self.gravity != D::zero()
    }
}

/// Adds wall contacts and gravity to the owned, non-frozen grains among
/// `first..first + force.len()`, after whatever their sums already hold
/// (each grain's walls in wall order, then gravity). The pair loop calls it
/// per block, once the block's contact sums are complete.
pub fn field_part<D: Dim>(
    input: &FieldInput<D>,
    g: &GrainView<D>,
    springs_in: &WallSprings<D>,
    first: usize,
    force: &mut [D::V],
    torque: &mut [D::A],
) -> FieldPart<D> {
    let empty = || FieldPart {
        stats: PartStats::default(),
        kept: ChunkSprings::default(),
    };
    let len = force.len().min(g.owned.saturating_sub(first));
    if !input.acts() || len == 0 {
        return empty();
    }
    let range = first..first + len;
    let (force, torque) = (&mut force[..len], &mut torque[..len]);
    let part = if input.walls.is_empty() {
        empty()
    } else {
        wall_contacts(input, g, springs_in, first, force, torque)
    };
    // Gravity after the walls, as each grain's sum has always been formed:
    // a loop of its own, without the walls' machinery around it.
    if input.gravity != D::zero() {
        let (frozen, mass) = (&g.frozen[range.clone()], &g.mass[range]);
        for ((f, &frozen), &m) in force.iter_mut().zip(frozen).zip(mass) {
            if !frozen {
                *f += input.gravity * m;
            }
        }
    }
    part
}

/// Adds the wall contacts of the owned, non-frozen grains among
/// `first..first + force.len()` (each grain's walls in wall order); their
/// statistics and springs.
fn wall_contacts<D: Dim>(
    input: &FieldInput<D>,
    g: &GrainView<D>,
    springs_in: &WallSprings<D>,
    first: usize,
    force: &mut [D::V],
    torque: &mut [D::A],
) -> FieldPart<D> {
    let mut s = PartStats::default();
    let mut kept = ChunkSprings::default();
    let range = first..first + force.len();
    let law = input.law;
    let mut springs = springs_in.cursor(range.clone());
    // The range's own slices: no bounds check per array and grain.
    let (frozen, radius, mass) = (
        &g.frozen[range.clone()],
        &g.radius[range.clone()],
        &g.mass[range.clone()],
    );
    let (pos, vel, omega) = (
        &g.pos[range.clone()],
        &g.vel[range.clone()],
        &g.omega[range],
    );
    // The grains some wall may touch, found by the walls' quick tests over
    // the whole range first; the contact code then runs for those grains
    // only. Most grains are far from every wall, and one loop over all of
    // them around the contact code took about 10 ns per grain on vib2d
    // (one plate).
    let near = near_walls(input.walls, pos, radius);
    let candidates = (0..force.len()).filter(|&k| near[k] && !frozen[k]);
    for k in candidates {
        let (i, ri, mi) = (first + k, radius[k], mass[k]);
        for (w, wall) in input.walls.iter().enumerate() {
            // An open contact keeps no spring.
            let Some(contact) = wall.contact(pos[k], ri) else {
                continue;
            };
            let mut spring = springs.get(i, w);
            let mut v_rel = vel[k] - contact.velocity;
            if law.rotation {
                v_rel -= D::ang_cross(omega[k] * ri, contact.normal);
            }
            let out = law.evaluate::<D>(
                contact.overlap,
                contact.normal,
                v_rel,
                law.damping_mass(mi, f64::INFINITY),
                &mut spring,
                input.dt,
                input.update,
            );
            kept.keep(i, w, spring);
            let fi = law.scaling.force_factor(mi);
            force[k] += out.force * fi;
            if law.rotation {
                torque[k] -= D::torque(contact.normal, out.tangential) * (ri * fi);
            }
            s.contacts += 1;
            s.max_overlap = s.max_overlap.max(contact.overlap);
            let frac = contact.overlap / ri;
            if frac > s.max_fraction {
                s.max_fraction = frac;
                s.worst = g.id[i];
            }
        }
    }
    FieldPart { stats: s, kept }
}

/// Which grains of `pos` and `radius` some wall may touch: each wall's
/// quick test ([`PlacedWall::mark_near`]) over all of them.
fn near_walls<D: Dim>(walls: &[PlacedWall<D>], pos: &[D::V], radius: &[f64]) -> Vec<bool> {
    let mut near = vec![false; pos.len()];
    for wall in walls {
        wall.mark_near(pos, radius, &mut near);
    }
    near
}

/// Keeps the parts' springs (given in grain order) and adds their
/// statistics.
pub fn finish_fields<D: Dim>(
    parts: Vec<FieldPart<D>>,
    wall_springs: &mut WallSprings<D>,
    stats: &mut MdStats,
) {
    let mut part_stats = Vec::with_capacity(parts.len());
    wall_springs.assemble(parts.into_iter().map(|part| {
        part_stats.push(part.stats);
        part.kept
    }));
    for s in &part_stats {
        stats.contacts += s.contacts;
        stats.max_overlap = stats.max_overlap.max(s.max_overlap);
        if s.max_fraction > stats.max_overlap_fraction {
            stats.max_overlap_fraction = s.max_fraction;
            stats.worst_pair = (s.worst, None);
        }
    }
}
