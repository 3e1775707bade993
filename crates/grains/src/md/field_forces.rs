//! Forces that act on one grain at a time: contacts with walls and gravity.
//! Grains are independent here: the pair loop adds them block by block,
//! in parallel, once a block's contact sums are complete (one pass over the
//! force sums fewer); each grain's sum is formed in wall order, whatever
//! the threads.

use super::wall_loads::WallLoad;
use super::wall_springs::{ChunkSprings, MeshKey, WallAndMesh, WallSprings};
use super::MdStats;
use crate::boundary::{MeshCandidates, MeshScratch, PlacedWall, WallContact};
use crate::contact::{Contact, ContactModel, Law, RunLaw, Step};
use crate::dim::Dim;

pub struct FieldInput<'a, D: Dim> {
    pub law: &'a Law,
    /// The walls placed at the evaluation's time, once for all blocks.
    pub walls: &'a [PlacedWall<'a, D>],
    pub gravity: D::V,
    /// The grains gravity skips when not only the frozen ones (rigid
    /// clumps: also the sub-spheres, whose body takes its weight at its
    /// centre of mass).
    pub weightless: Option<&'a [bool]>,
    pub dt: f64,
    pub update: bool,
    /// The mesh walls' springs, keyed by (grain, wall, patch).
    pub mesh_springs: &'a WallSprings<D, MeshKey>,
    /// Each mesh wall's per-grain triangle lists, by wall (empty without
    /// mesh walls).
    pub mesh_lists: &'a [Option<MeshCandidates>],
    /// The rolling springs of grain–wall contacts (a law with rolling
    /// history only), and those of mesh walls, keyed as `mesh_springs`.
    pub wall_rolling: &'a WallSprings<D>,
    pub mesh_rolling: &'a WallSprings<D, MeshKey>,
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
    /// Grain types: a material law's key to each grain's material.
    pub kind: &'a [u32],
    /// Grains past this index (ghosts) get no field force.
    pub owned: usize,
}

/// One range of grains' wall contacts and gravity, and their springs.
pub struct FieldPart<D: Dim> {
    stats: PartStats,
    kept: ChunkSprings<D>,
    mesh_kept: ChunkSprings<D, MeshKey>,
    rolling_kept: ChunkSprings<D>,
    mesh_rolling_kept: ChunkSprings<D, MeshKey>,
    /// Per wall, what this range's grains push on it (mesh and servo
    /// walls only; empty when there is none).
    loads: Vec<WallLoad>,
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
        mesh_kept: ChunkSprings::default(),
        rolling_kept: ChunkSprings::default(),
        mesh_rolling_kept: ChunkSprings::default(),
        loads: Vec::new(),
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
        input.law.with_kernel(WallRun {
            input,
            g,
            springs_in,
            first,
            sums: (force, torque),
        })
    };
    // Gravity after the walls, as each grain's sum has always been formed:
    // a loop of its own, without the walls' machinery around it.
    if input.gravity != D::zero() {
        let skip = input.weightless.unwrap_or(g.frozen);
        let (skip, mass) = (&skip[range.clone()], &g.mass[range]);
        for ((f, &skip), &m) in force.iter_mut().zip(skip).zip(mass) {
            if !skip {
                *f += input.gravity * m;
            }
        }
    }
    part
}

/// Adds the wall contacts of the owned, non-frozen grains among
/// `first..first + force.len()` (each grain's walls in wall order); their
/// statistics and springs.
fn wall_contacts<D: Dim, L: ContactModel>(
    (law, elastic): (&L, &L),
    input: &FieldInput<D>,
    g: &GrainView<D>,
    springs_in: &WallSprings<D>,
    first: usize,
    (force, torque): (&mut [D::V], &mut [D::A]),
) -> FieldPart<D> {
    let mut s = PartStats::default();
    let mut kept = ChunkSprings::default();
    let range = first..first + force.len();
    let mut rolling = input.wall_rolling.cursor(range.clone());
    let mut rolling_kept = ChunkSprings::default();
    let rotation = law.rotation();
    let step = Step {
        dt: input.dt,
        update: input.update,
    };
    let mut springs = springs_in.cursor(range.clone());
    // Mesh walls: several contacts per wall, springs per patch, and the
    // load they take, as servo walls (nothing allocated when there is
    // neither).
    let meshes = input.walls.iter().any(|w| w.mesh().is_some());
    let servos = input.walls.iter().any(|w| w.is_servo());
    let mut mesh = MeshPass {
        springs: input.mesh_springs.cursor(range.clone()),
        kept: ChunkSprings::default(),
        rolling: input.mesh_rolling.cursor(range.clone()),
        rolling_kept: ChunkSprings::default(),
        scratch: MeshScratch::default(),
        found: Vec::new(),
        loads: if meshes || servos {
            vec![WallLoad::default(); input.walls.len()]
        } else {
            Vec::new()
        },
    };
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
    let near = if L::BONDED {
        // A kept contact reaches past touching: the quick tests look that
        // much farther.
        let reach: Vec<f64> = (0..force.len())
            .map(|k| {
                let kind = g.kind[first + k];
                let r = radius[k];
                (0..input.walls.len())
                    .map(|w| law.reach(law.wall_pair_index(kind, w), r, f64::INFINITY))
                    .fold(r, |a, d| a.max(r + d))
            })
            .collect();
        near_walls(input.walls, pos, &reach)
    } else {
        near_walls(input.walls, pos, radius)
    };
    let candidates = (0..force.len()).filter(|&k| near[k] && !frozen[k]);
    for k in candidates {
        let (i, ri, mi) = (first + k, radius[k], mass[k]);
        let grain = Grain {
            vel: vel[k],
            omega: omega[k],
            radius: ri,
            mass: mi,
            kind: g.kind[i],
        };
        for (w, wall) in input.walls.iter().enumerate() {
            let wall_law = if wall.is_elastic() { elastic } else { law };
            if meshes && wall.mesh().is_some() {
                let lists = input.mesh_lists.get(w).and_then(Option::as_ref);
                let cached = lists.map(|l| (l, i));
                wall.mesh_contacts(pos[k], ri, cached, &mut mesh.scratch, &mut mesh.found);
                for &(patch, contact) in &mesh.found {
                    let key = (i as u32, w as u32, patch);
                    let mut spring = mesh.springs.get_key(key);
                    // epsd's rolling spring per patch, as the tangential
                    // one (JKR, the other law with a second history, is
                    // refused with mesh walls).
                    let mut roll = if L::ROLLING_HISTORY {
                        mesh.rolling.get_key(key)
                    } else {
                        D::zero()
                    };
                    let springs = (&mut spring, &mut roll);
                    let (f, t) = push(wall_law, step, (&grain, wall, w), &contact, springs);
                    mesh.kept.keep_key(key, spring);
                    if L::ROLLING_HISTORY {
                        mesh.rolling_kept.keep_key(key, roll);
                    }
                    force[k] += f;
                    if rotation {
                        torque[k] -= t;
                    }
                    mesh.loads[w].add::<D>(f, contact.point);
                    s.count(&contact, ri, g.id[i]);
                }
                continue;
            }
            let mut roll = if L::ROLLING_HISTORY || L::BONDED {
                rolling.get(i, w)
            } else {
                D::zero()
            };
            let found = if L::BONDED && roll != D::zero() {
                // A formed contact is kept to `reach` beyond touching: the
                // wall's contact test for a grain that much larger.
                let reach = law.reach(law.wall_pair_index(grain.kind, w), ri, f64::INFINITY);
                wall.contact(pos[k], ri + reach).map(|mut c| {
                    c.overlap -= reach;
                    c
                })
            } else {
                wall.contact(pos[k], ri)
            };
            // An open contact keeps no spring.
            let Some(contact) = found else {
                continue;
            };
            let mut spring = springs.get(i, w);
            let springs = (&mut spring, &mut roll);
            let (f, t) = push(wall_law, step, (&grain, wall, w), &contact, springs);
            kept.keep(i, w, spring);
            if L::BONDED {
                rolling_kept.keep(i, w, crate::contact::jkr::mark::<D>());
            } else if L::ROLLING_HISTORY {
                rolling_kept.keep(i, w, roll);
            }
            force[k] += f;
            if rotation {
                torque[k] -= t;
            }
            if servos && wall.is_servo() {
                mesh.loads[w].add::<D>(f, contact.point);
            }
            s.count(&contact, ri, g.id[i]);
        }
    }
    FieldPart {
        stats: s,
        kept,
        mesh_kept: mesh.kept,
        rolling_kept,
        mesh_rolling_kept: mesh.rolling_kept,
        loads: mesh.loads,
    }
}

/// [`wall_contacts`] for the run's law, as [`Law::with_kernel`] compiles it.
struct WallRun<'a, 'b, D: Dim> {
    input: &'a FieldInput<'a, D>,
    g: &'a GrainView<'a, D>,
    springs_in: &'a WallSprings<D>,
    first: usize,
    sums: (&'b mut [D::V], &'b mut [D::A]),
}

impl<D: Dim> RunLaw<FieldPart<D>> for WallRun<'_, '_, D> {
    fn run<L: ContactModel>(self, law: &L) -> FieldPart<D> {
        // An elastic wall (`Wall::with_elastic`) meets grains with the
        // law's elastic form; a material law has none (the scenario
        // refuses the key with it: its walls take restitution 1 from a
        // material instead).
        let elastic = law.elastic_wall();
        let laws = (law, elastic.as_ref().unwrap_or(law));
        wall_contacts(
            laws,
            self.input,
            self.g,
            self.springs_in,
            self.first,
            self.sums,
        )
    }
}

/// A grain's state that its wall contacts read.
struct Grain<D: Dim> {
    vel: D::V,
    omega: D::A,
    radius: f64,
    mass: f64,
    kind: u32,
}

/// What a range of grains keeps while meeting mesh walls.
struct MeshPass<'a, D: Dim> {
    springs: super::wall_springs::Cursor<'a, D, MeshKey>,
    kept: ChunkSprings<D, MeshKey>,
    rolling: super::wall_springs::Cursor<'a, D, MeshKey>,
    rolling_kept: ChunkSprings<D, MeshKey>,
    scratch: MeshScratch,
    found: Vec<(u32, WallContact<D>)>,
    loads: Vec<WallLoad>,
}

/// The force on a grain from one wall contact, and the torque to take
/// from its sum (the contact law on the relative velocity at the contact).
#[inline(always)]
fn push<D: Dim, L: ContactModel>(
    law: &L,
    step: Step,
    (g, placed, wall): (&Grain<D>, &PlacedWall<D>, usize),
    contact: &WallContact<D>,
    (spring, rolling): (&mut D::V, &mut D::V),
) -> (D::V, D::A) {
    let rotation = law.rotation();
    let mut v_rel = g.vel - contact.velocity;
    if rotation {
        v_rel -= D::ang_cross(g.omega * g.radius, contact.normal);
    }
    // A wall is infinitely heavy and flat.
    let c = Contact::<D> {
        overlap: contact.overlap,
        normal: contact.normal,
        v_rel,
        mi: g.mass,
        mj: f64::INFINITY,
        ri: g.radius,
        rj: f64::INFINITY,
        omega_rel: if L::ROLLING {
            g.omega - placed.spin()
        } else {
            D::A::default()
        },
        pair: law.wall_pair_index(g.kind, wall),
    };
    let out = law.evaluate(&c, spring, step);
    let fi = law.force_factor(g.mass);
    let mut torque = if rotation {
        D::torque(contact.normal, out.tangential) * (law.lever(g.radius, contact.overlap) * fi)
    } else {
        D::A::default()
    };
    if L::ROLLING {
        torque -= law.rolling(&c, &out, rolling, step);
    }
    (out.force * fi, torque)
}

impl PartStats {
    /// Counts a wall contact of a grain (`id`, radius `r`).
    #[inline(always)]
    fn count<D: Dim>(&mut self, contact: &WallContact<D>, r: f64, id: u64) {
        self.contacts += 1;
        self.max_overlap = self.max_overlap.max(contact.overlap);
        let frac = contact.overlap / r;
        if frac > self.max_fraction {
            self.max_fraction = frac;
            self.worst = id;
        }
    }
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
    ((wall_springs, mesh_springs), (wall_rolling, mesh_rolling)): (WallAndMesh<D>, WallAndMesh<D>),
    loads: &mut Vec<WallLoad>,
    stats: &mut MdStats,
) {
    let mut part_stats = Vec::with_capacity(parts.len());
    let mut mesh_kept = Vec::new();
    let mut rolling_kept = Vec::new();
    let mut mesh_rolling_kept = Vec::new();
    // Summed part by part in grain order: the same bits on any threads.
    loads.clear();
    wall_springs.assemble(parts.into_iter().map(|part| {
        part_stats.push(part.stats);
        if loads.len() < part.loads.len() {
            loads.resize(part.loads.len(), WallLoad::default());
        }
        for (sum, l) in loads.iter_mut().zip(&part.loads) {
            sum.force += l.force;
            sum.moment += l.moment;
        }
        mesh_kept.push(part.mesh_kept);
        rolling_kept.push(part.rolling_kept);
        mesh_rolling_kept.push(part.mesh_rolling_kept);
        part.kept
    }));
    mesh_springs.assemble(mesh_kept);
    wall_rolling.assemble(rolling_kept);
    mesh_rolling.assemble(mesh_rolling_kept);
    for s in &part_stats {
        stats.contacts += s.contacts;
        stats.max_overlap = stats.max_overlap.max(s.max_overlap);
        if s.max_fraction > stats.max_overlap_fraction {
            stats.max_overlap_fraction = s.max_fraction;
            stats.worst_pair = (s.worst, None);
        }
    }
}
