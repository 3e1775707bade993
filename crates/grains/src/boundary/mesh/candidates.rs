//! Each grain's candidate triangles of a mesh, kept between neighbour-list rebuilds.
//!
//! The grid is searched once per grain with a margin; a grain then tests
//! only its own short list while it stays within that margin of where the
//! list was made (the Verlet list's idea, for triangles).
//!
//! Which triangles a grain is tested against never changes its contacts:
//! [`Mesh::touches`] keeps, of whatever triangles it reads, each patch's
//! face (measured from the patch's one plane, so the same from any of its
//! triangles) or else its nearest edge or corner with the triangle number
//! settling ties, so any set of triangles that holds every one within
//! reach gives the same contacts, bit for bit. A triangle within r of the
//! grain's centre p is within r + |p − c| of the centre c the list was
//! made at, so a list of the triangles within r₀ + margin of c serves
//! while |p − c| + (r − r₀) ≤ margin; past that, the grain's lookup goes
//! through the grid as without a list.
//!
//! The nearest triangle's corners and normal are kept with the list
//! because on a large mesh a lookup's cost is reading triangles (corners,
//! normals and indices on separate cache lines), and a grain resting on a
//! flat patch most often needs that one triangle only (its face answers
//! for the patch, whose other triangles are then passed over by number).

use super::{closest::closest_on_triangle, Mesh, MeshScratch};
use glam::DVec3;
use rayon::prelude::*;

/// Grains per parallel piece of a build.
const CHUNK: usize = 4096;

/// The candidate triangles of every grain of a pass, for one mesh wall.
#[derive(Clone, Debug, Default)]
pub struct MeshCandidates {
    grains: Vec<Entry>,
    /// (triangle, patch), each grain's nearest first.
    items: Vec<(u32, u32)>,
    /// The corners and normal of each non-empty list's first triangle, in
    /// grain order.
    leads: Vec<[DVec3; 4]>,
    margin: f64,
}

/// A grain's list: where it was made, and where its parts lie.
#[derive(Clone, Copy, Debug)]
struct Entry {
    /// The reference-frame centre and radius the list was made for (a NaN
    /// radius: no list).
    centre: DVec3,
    radius: f64,
    /// `items[start..start + len]`; `leads[lead]` when `len > 0`.
    start: u32,
    len: u32,
    lead: u32,
}

/// A grain's list as [`Mesh::touches_among`] reads it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GrainList<'a> {
    items: &'a [(u32, u32)],
    lead: Option<&'a [DVec3; 4]>,
}

impl MeshCandidates {
    /// The lists of grains at reference-frame centres `local(i)` with radii
    /// `radius[i]`, each holding every triangle within its radius plus
    /// `margin`; grains for which `skip(i)` holds get none.
    pub(crate) fn build(
        mesh: &Mesh,
        local: impl Fn(usize) -> DVec3 + Sync,
        radius: &[f64],
        skip: impl Fn(usize) -> bool + Sync,
        margin: f64,
    ) -> Self {
        let n = radius.len();
        let pieces: Vec<Self> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .with_min_len(crate::parallel::min_len(1))
            .map(|c| {
                let range = c * CHUNK..((c + 1) * CHUNK).min(n);
                let mut piece = Self {
                    grains: Vec::with_capacity(range.len()),
                    ..Self::default()
                };
                let mut found = Vec::new();
                for i in range {
                    let mut e = Entry {
                        centre: DVec3::ZERO,
                        radius: f64::NAN,
                        start: piece.items.len() as u32,
                        len: 0,
                        lead: piece.leads.len() as u32,
                    };
                    if !skip(i) {
                        (e.centre, e.radius) = (local(i), radius[i]);
                        mesh.near_triangles(e.centre, e.radius + margin, &mut found);
                        e.len = found.len() as u32;
                        piece
                            .items
                            .extend(found.iter().map(|&(_, t, patch)| (t, patch)));
                        if let Some(&(_, t, _)) = found.first() {
                            let [a, b, c] =
                                mesh.tris[t as usize].map(|v| mesh.vertices[v as usize]);
                            piece.leads.push([a, b, c, mesh.normals[t as usize]]);
                        }
                    }
                    piece.grains.push(e);
                }
                piece
            })
            .collect();
        let mut out = Self {
            grains: Vec::with_capacity(n),
            items: Vec::with_capacity(pieces.iter().map(|p| p.items.len()).sum()),
            leads: Vec::with_capacity(pieces.iter().map(|p| p.leads.len()).sum()),
            margin,
        };
        for piece in pieces {
            let (items, leads) = (out.items.len() as u32, out.leads.len() as u32);
            out.grains.extend(piece.grains.iter().map(|e| Entry {
                start: e.start + items,
                lead: e.lead + leads,
                ..*e
            }));
            out.items.extend(piece.items);
            out.leads.extend(piece.leads);
        }
        out
    }

    /// Grain `i`'s list, when it serves a grain at `p` of radius `r`.
    #[inline]
    pub(crate) fn list(&self, i: usize, p: DVec3, r: f64) -> Option<GrainList<'_>> {
        let e = self.grains.get(i)?;
        // False for a NaN radius (no list) too.
        if (p - e.centre).length() + (r - e.radius) <= self.margin {
            let start = e.start as usize;
            Some(GrainList {
                items: &self.items[start..start + e.len as usize],
                lead: self.leads.get(e.lead as usize).filter(|_| e.len > 0),
            })
        } else {
            None
        }
    }

    /// The number of grains with a list, and of triangles in all lists.
    pub fn counts(&self) -> (usize, usize) {
        let with = self.grains.iter().filter(|e| !e.radius.is_nan()).count();
        (with, self.items.len())
    }
}

impl Mesh {
    /// Every triangle within `reach` of `p` (with a margin of 1e-9 for
    /// rounding), as (distance, triangle, patch), nearest first, into
    /// `out`.
    pub(crate) fn near_triangles(&self, p: DVec3, reach: f64, out: &mut Vec<(f64, u32, u32)>) {
        out.clear();
        // Far enough over the rounding of the distances here and of the
        // contact tests, which turn down whatever is r or farther.
        let reach = reach + 1e-9 * (reach + p.abs().max_element());
        let b = DVec3::splat(reach);
        if (self.lo - p).max_element() >= reach || (p - self.hi).max_element() >= reach {
            return;
        }
        self.grid.visit(
            (p - b, p + b),
            &mut Vec::new(),
            |_, _| false,
            |t, _| {
                let [a, b, c] = self.tris[t].map(|i| self.vertices[i as usize]);
                let (q, _) = closest_on_triangle(p, a, b, c);
                let d = (p - q).length();
                if d < reach {
                    out.push((d, t as u32, self.patch[t]));
                }
            },
        );
        // The grid may report a triangle twice.
        out.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        out.dedup_by_key(|x| x.1);
    }

    /// [`Mesh::touches`] reading only the triangles of a grain's `list`,
    /// which must hold every triangle within `r` of `p`.
    pub(crate) fn touches_among(
        &self,
        p: DVec3,
        r: f64,
        list: GrainList,
        scratch: &mut MeshScratch,
    ) {
        scratch.candidates.clear();
        scratch.touches.clear();
        scratch.done.clear();
        #[cfg(test)]
        {
            scratch.tested = 0;
        }
        for (k, &(t, patch)) in list.items.iter().enumerate() {
            if scratch.done.contains(&patch) {
                continue;
            }
            #[cfg(test)]
            {
                scratch.tested += 1;
            }
            let found = match list.lead {
                Some(&[a, b, c, normal]) if k == 0 => {
                    self.candidate_of(t as usize, ([a, b, c], normal, patch), p, r)
                }
                _ => self.candidate(t as usize, p, r),
            };
            if let Some(c) = found {
                if c.rank == 0 {
                    scratch.done.push(c.patch);
                }
                scratch.candidates.push(c);
            }
        }
        self.thin(scratch);
    }
}
