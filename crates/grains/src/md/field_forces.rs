//! Forces that act on one grain at a time: contacts with walls and gravity.
//! Grains are independent here, so the loop runs in parallel chunks; each
//! grain's sum is formed in wall order, whatever the threads.

use super::wall_springs::{ChunkSprings, WallSprings};
use super::MdStats;
use crate::boundary::Wall;
use crate::contact::ContactLaw;
use crate::dim::Dim;
use crate::particles::Particles;
use rayon::prelude::*;

/// Grains per parallel chunk.
const CHUNK: usize = 2048;
/// Fewest chunks handed to one parallel job (as many grains as the pair
/// loop's smallest job).
const MIN_CHUNKS_PER_JOB: usize = 2;

pub struct FieldInput<'a, D: Dim> {
    pub law: &'a ContactLaw,
    pub walls: &'a [Wall<D>],
    pub gravity: D::V,
    pub time: f64,
    pub dt: f64,
    pub update: bool,
}

#[derive(Clone, Copy, Debug, Default)]
struct ChunkStats {
    contacts: usize,
    max_overlap: f64,
    max_fraction: f64,
    worst: u64,
}

/// Adds wall contacts and gravity to every owned, non-frozen grain, and
/// updates the wall contacts' springs.
pub fn field_forces<D: Dim>(
    input: &FieldInput<D>,
    p: &mut Particles<D>,
    wall_springs: &mut WallSprings<D>,
    stats: &mut MdStats,
) {
    let nw = input.walls.len();
    let n = p.n_owned();
    let has_gravity = input.gravity != D::zero();
    if nw == 0 && !has_gravity {
        return;
    }
    let (pos, vel, omega, radius, mass, frozen, id) = (
        &p.pos, &p.vel, &p.omega, &p.radius, &p.mass, &p.frozen, &p.id,
    );
    let law = input.law;
    let springs_in = &*wall_springs;
    let chunks: Vec<(ChunkStats, ChunkSprings<D>)> = p.force[..n]
        .par_chunks_mut(CHUNK)
        .zip(p.torque[..n].par_chunks_mut(CHUNK))
        // A small system stays on one thread rather than wake another.
        .with_min_len(MIN_CHUNKS_PER_JOB)
        .enumerate()
        .map(|(c, (force, torque))| {
            let mut s = ChunkStats::default();
            let first = c * CHUNK;
            let mut springs = springs_in.cursor(first..first + force.len());
            let mut kept = ChunkSprings::default();
            for (k, (f, t)) in force.iter_mut().zip(torque.iter_mut()).enumerate() {
                let i = first + k;
                if frozen[i] {
                    continue;
                }
                let (ri, mi) = (radius[i], mass[i]);
                for (w, wall) in input.walls.iter().enumerate() {
                    // An open contact keeps no spring.
                    let Some(contact) = wall.contact(pos[i], ri, input.time) else {
                        continue;
                    };
                    let mut spring = springs.get(i, w);
                    let mut v_rel = vel[i] - contact.velocity;
                    if law.rotation {
                        v_rel -= D::ang_cross(omega[i] * ri, contact.normal);
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
                    *f += out.force * fi;
                    if law.rotation {
                        *t -= D::torque(contact.normal, out.tangential) * (ri * fi);
                    }
                    s.contacts += 1;
                    s.max_overlap = s.max_overlap.max(contact.overlap);
                    let frac = contact.overlap / ri;
                    if frac > s.max_fraction {
                        s.max_fraction = frac;
                        s.worst = id[i];
                    }
                }
                if has_gravity {
                    *f += input.gravity * mi;
                }
            }
            (s, kept)
        })
        .collect();
    let mut chunk_stats = Vec::with_capacity(chunks.len());
    wall_springs.assemble(chunks.into_iter().map(|(s, kept)| {
        chunk_stats.push(s);
        kept
    }));
    for s in &chunk_stats {
        stats.contacts += s.contacts;
        stats.max_overlap = stats.max_overlap.max(s.max_overlap);
        if s.max_fraction > stats.max_overlap_fraction {
            stats.max_overlap_fraction = s.max_fraction;
            stats.worst_pair = (s.worst, None);
        }
    }
}
