//! Walls from triangle meshes (STL): the triangles in the wall's reference
//! frame, grouped into flat patches, with a grid to find those near a grain.
//!
//! A grain meets the mesh by the nearest feature of each triangle it
//! reaches (face, edge or corner: [`closest::closest_on_triangle`]), and
//! the contacts are then thinned so that one smooth surface pushes once:
//!
//! 1. Triangles sharing an edge and lying in one plane (normals within
//!    1e-5 rad) form a *patch*; a patch pushes with its nearest point only,
//!    measured from the patch's one plane, so a grain rolling across the
//!    inner edges of a flat patch feels one contact whose force does not
//!    jump there (and its tangential spring, kept per patch, rides along).
//! 2. A face contact always counts; an edge or corner contact is dropped
//!    when that edge or corner lies on a patch whose contact already
//!    counted, nearest first: at a convex ridge the two faces' shared edge
//!    pushes once, while in a concave corner each face pushes with its own
//!    face contact, as two plane walls would.
//!
//! Meshes are two-sided, as polygons are; the winding is not used.

mod candidates;
mod closest;
mod grid;
mod outline;
mod placed;
mod ribbon;

pub use candidates::MeshCandidates;
pub use outline::CREASE_DEG;

use super::geom::Touch;
use closest::{closest_on_triangle, Region};
use glam::{DQuat, DVec3};
use grid::TriGrid;
use std::collections::HashMap;

/// Normals of one patch agree to this (1 − cos of 1e-5 rad): single
/// precision STL vertices tilt a flat face's triangles by about 1e-7.
const COPLANAR: f64 = 5e-11;

/// Where a mesh read from a file is put: scaled about the origin, turned
/// about x, then y, then z (degrees, about the origin), then shifted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPlacement {
    pub scale: f64,
    pub rotate_deg: [f64; 3],
    pub translate: [f64; 3],
}

impl Default for MeshPlacement {
    fn default() -> Self {
        Self {
            scale: 1.0,
            rotate_deg: [0.0; 3],
            translate: [0.0; 3],
        }
    }
}

impl MeshPlacement {
    fn check(&self) -> Result<(), String> {
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(format!(
                "scale must be positive and finite, got {}",
                self.scale
            ));
        }
        let all = self.rotate_deg.iter().chain(&self.translate);
        if let Some(x) = all.into_iter().find(|x| !x.is_finite()) {
            return Err(format!("rotate_deg and translate must be finite, got {x}"));
        }
        Ok(())
    }

    /// The placed position of a file's vertex.
    pub fn apply(&self, v: [f64; 3]) -> DVec3 {
        let [rx, ry, rz] = self.rotate_deg.map(f64::to_radians);
        let turn =
            DQuat::from_rotation_z(rz) * DQuat::from_rotation_y(ry) * DQuat::from_rotation_x(rx);
        let x = DVec3::from_array(v) * self.scale;
        let x = if self.rotate_deg == [0.0; 3] {
            x
        } else {
            turn * x
        };
        x + DVec3::from_array(self.translate)
    }
}

/// A triangle mesh in a wall's reference frame.
#[derive(Clone, PartialEq)]
pub struct Mesh {
    /// The file it came from, for messages.
    source: String,
    vertices: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
    /// Each triangle's unit normal (its plane turns most far triangles
    /// down before the nearest-point search).
    normals: Vec<DVec3>,
    boxes: Vec<(DVec3, DVec3)>,
    /// Each triangle's patch.
    patch: Vec<u32>,
    /// Each patch's plane: a point and the unit normal.
    planes: Vec<(DVec3, DVec3)>,
    /// Vertex v's patches are `vertex_patches[vp_start[v]..vp_start[v + 1]]`.
    vp_start: Vec<u32>,
    vertex_patches: Vec<u32>,
    grid: TriGrid,
    lo: DVec3,
    hi: DVec3,
    centroid: DVec3,
    /// The point torques on the mesh are taken about (reference frame).
    load_point: DVec3,
    /// A hash of the vertices' bits and the triangles: a checkpoint's
    /// fingerprint holds it (through `Debug`), so that a run is not resumed
    /// over a mesh file changed since.
    digest: u64,
}

impl std::fmt::Debug for Mesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Mesh({}: {} triangles, {} patches, digest {:016x})",
            self.source,
            self.tris.len(),
            self.planes.len(),
            self.digest
        )
    }
}

/// A contact of a grain with a mesh: the patch that pushes and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MeshTouch {
    pub patch: u32,
    pub touch: Touch,
}

/// One triangle's nearest feature within reach of a grain.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    patch: u32,
    dist: f64,
    /// 0 face, 1 edge, 2 corner: at equal distance a face wins.
    rank: u8,
    /// The feature's vertices (an edge's two, a corner's one twice).
    ends: [u32; 2],
    /// The triangle it came from.
    tri: u32,
    touch: Touch,
}

/// Scratch memory of a wall pass's mesh contacts (one per block of grains,
/// so a contact allocates nothing).
#[derive(Debug, Default)]
pub struct MeshScratch {
    candidates: Vec<Candidate>,
    touches: Vec<MeshTouch>,
    /// Patches already met at their face: nothing of theirs is nearer.
    done: Vec<u32>,
    /// The triangles the last lookup tested (for the tests' counts).
    #[cfg(test)]
    tested: usize,
}

impl Mesh {
    /// A mesh from `triangles` (vertices as read) placed by `place`;
    /// `source` names the file in messages. Refuses a non-finite vertex and
    /// a degenerate triangle (zero area, or sides in line to 1e-12), naming
    /// the triangle by its index in the file.
    pub fn new(
        source: &str,
        triangles: &[[[f64; 3]; 3]],
        place: &MeshPlacement,
    ) -> Result<Self, String> {
        place.check()?;
        if triangles.is_empty() {
            return Err("the mesh has no triangles".into());
        }
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut vertices = Vec::new();
        let mut tris = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for (j, v) in tri.iter().enumerate() {
                if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                    return Err(format!("triangle {t}: vertex {j} is not finite ({x})"));
                }
            }
            let [a, b, c] = tri.map(|v| place.apply(v));
            let area2 = (b - a).cross(c - a).length();
            let longest = (b - a).length().max((c - a).length()).max((c - b).length());
            if area2.is_nan() || area2 <= 1e-12 * longest * longest {
                return Err(format!(
                    "triangle {t} is degenerate (zero area: its corners {:?}, {:?}, {:?} \
                     are in line or coincide)",
                    tri[0], tri[1], tri[2]
                ));
            }
            tris.push([a, b, c].map(|x| {
                // -0 and +0 are one vertex.
                let key = (x + DVec3::ZERO).to_array().map(f64::to_bits);
                *index.entry(key).or_insert_with(|| {
                    vertices.push(x);
                    (vertices.len() - 1) as u32
                })
            }));
        }
        Ok(Self::from_indexed(source, vertices, tris))
    }

    fn from_indexed(source: &str, vertices: Vec<DVec3>, tris: Vec<[u32; 3]>) -> Self {
        let (vertices, tris) = spatial_order(vertices, tris);
        let corner = |t: &[u32; 3]| t.map(|i| vertices[i as usize]);
        let normals: Vec<DVec3> = tris
            .iter()
            .map(|t| {
                let [a, b, c] = corner(t);
                (b - a).cross(c - a).normalize()
            })
            .collect();
        let boxes: Vec<(DVec3, DVec3)> = tris
            .iter()
            .map(|t| {
                let [a, b, c] = corner(t);
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let (patch, planes) = patches(&vertices, &tris, &normals);
        let (vp_start, vertex_patches) = vertex_patch_lists(vertices.len(), &tris, &patch);
        let lo = boxes.iter().fold(DVec3::INFINITY, |l, b| l.min(b.0));
        let hi = boxes.iter().fold(DVec3::NEG_INFINITY, |h, b| h.max(b.1));
        let (mut area, mut moment) = (0.0, DVec3::ZERO);
        for t in &tris {
            let [a, b, c] = corner(t);
            let w = (b - a).cross(c - a).length();
            area += w;
            moment += (a + b + c) * (w / 3.0);
        }
        let digest = {
            use std::hash::{Hash, Hasher};
            let mut h = rustc_hash::FxHasher::default();
            for v in &vertices {
                v.to_array().map(f64::to_bits).hash(&mut h);
            }
            tris.hash(&mut h);
            h.finish()
        };
        let grid = TriGrid::new(&boxes, &patch, lo, hi);
        Self {
            source: source.to_string(),
            vertices,
            tris,
            normals,
            boxes,
            patch,
            planes,
            vp_start,
            vertex_patches,
            grid,
            lo,
            hi,
            centroid: moment / area,
            load_point: moment / area,
            digest,
        }
    }

    /// The same mesh with torques taken about `point` (reference frame;
    /// it moves with the wall) instead of the centroid.
    pub fn with_load_point(mut self, point: DVec3) -> Result<Self, String> {
        if !point.is_finite() {
            return Err(format!("load_point must be finite, got {point}"));
        }
        self.load_point = point;
        Ok(self)
    }

    /// The point torques on the mesh are taken about (reference frame).
    pub fn load_point(&self) -> DVec3 {
        self.load_point
    }

    /// The file the mesh came from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The number of triangles.
    pub fn triangles(&self) -> usize {
        self.tris.len()
    }

    /// The number of flat patches.
    pub fn patches(&self) -> usize {
        self.planes.len()
    }

    /// The area-weighted centroid of the surface (reference frame).
    pub fn centroid(&self) -> DVec3 {
        self.centroid
    }

    /// The bounding box of the vertices (reference frame).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }

    /// The triangles' corners, for drawing and tests.
    pub fn corners(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.tris
            .iter()
            .map(|t| t.map(|i| self.vertices[i as usize]))
    }

    /// Whether vertex `v` lies on patch `p`.
    #[inline]
    fn on_patch(&self, v: u32, p: u32) -> bool {
        let v = v as usize;
        let list = &self.vertex_patches[self.vp_start[v] as usize..self.vp_start[v + 1] as usize];
        list.contains(&p)
    }

    /// The contacts of a sphere (centre `p`, radius `r`, reference frame)
    /// with the mesh, thinned as the module's documentation says, in patch
    /// order, into `scratch` (read them with [`MeshScratch::touches`]).
    pub(crate) fn touches(&self, p: DVec3, r: f64, scratch: &mut MeshScratch) {
        let MeshScratch {
            candidates,
            touches,
            done,
            ..
        } = scratch;
        #[cfg(test)]
        let mut tested = 0;
        candidates.clear();
        touches.clear();
        done.clear();
        let reach = DVec3::splat(r * (1.0 + 1e-9));
        // A patch met at its face is met at its nearest point (every point
        // of it is in that plane): its other triangles are passed over. So
        // the middle cell's triangles whose box holds the grain's foot on
        // their patch's plane are read first: one of them is most often
        // that face.
        let mut foot = (u32::MAX, DVec3::ZERO);
        let slack = DVec3::splat(1e-9 * r);
        let leads = |patch: u32, (bl, bh): (DVec3, DVec3)| {
            if foot.0 != patch {
                let (point, n) = self.planes[patch as usize];
                foot = (patch, p - n * (p - point).dot(n));
            }
            foot.1.cmpge(bl - slack).all() && foot.1.cmple(bh + slack).all()
        };
        self.grid
            .visit((p - reach, p + reach), done, leads, |t, done| {
                #[cfg(test)]
                {
                    tested += 1;
                }
                if let Some(c) = self.candidate(t, p, r) {
                    if c.rank == 0 {
                        done.push(c.patch);
                    }
                    candidates.push(c);
                }
            });
        #[cfg(test)]
        {
            scratch.tested = tested;
        }
        self.thin(scratch);
    }

    /// The contacts of the triangles' nearest features in `scratch`'s
    /// candidates, thinned to one per patch and then shadowed edges and
    /// corners dropped, into its touches.
    fn thin(&self, scratch: &mut MeshScratch) {
        let MeshScratch {
            candidates,
            touches,
            ..
        } = scratch;
        if candidates.is_empty() {
            return;
        }
        let order = |a: &Candidate, b: &Candidate| {
            a.dist
                .total_cmp(&b.dist)
                .then(a.rank.cmp(&b.rank))
                .then(a.patch.cmp(&b.patch))
                .then(a.ends.cmp(&b.ends))
        };
        // Each patch's contact: its face when one triangle is met at its
        // face (whatever an edge of it gave, nearer by rounding or by the
        // patch's slight bend), else its nearest edge or corner; the
        // triangle's number settles ties, so that the order the triangles
        // were read in never matters.
        candidates.sort_unstable_by(|a, b| {
            a.patch
                .cmp(&b.patch)
                .then((a.rank > 0).cmp(&(b.rank > 0)))
                .then(order(a, b))
                .then(a.tri.cmp(&b.tri))
        });
        candidates.dedup_by_key(|c| c.patch);
        // Then the patches nearest first.
        candidates.sort_unstable_by(order);
        for c in candidates.iter() {
            let shadowed = c.rank > 0
                && touches.iter().any(|a| {
                    self.on_patch(c.ends[0], a.patch) && self.on_patch(c.ends[1], a.patch)
                });
            if !shadowed {
                touches.push(MeshTouch {
                    patch: c.patch,
                    touch: c.touch,
                });
            }
        }
        touches.sort_unstable_by_key(|t| t.patch);
    }

    /// Triangle `t`'s nearest feature to `p` if within `r`.
    #[inline]
    fn candidate(&self, t: usize, p: DVec3, r: f64) -> Option<Candidate> {
        let corners = self.tris[t].map(|i| self.vertices[i as usize]);
        self.candidate_of(t, (corners, self.normals[t], self.patch[t]), p, r)
    }

    /// [`Mesh::candidate`] given triangle `t`'s corners, normal and patch
    /// (from the mesh, or a copy of them kept near the grain).
    #[inline(always)]
    fn candidate_of(
        &self,
        t: usize,
        ([a, b, c], normal, patch): ([DVec3; 3], DVec3, u32),
        p: DVec3,
        r: f64,
    ) -> Option<Candidate> {
        // Every point of the triangle is at least this far from p.
        if (p - a).dot(normal).abs() >= r {
            return None;
        }
        let (q, region) = closest_on_triangle(p, a, b, c);
        let (point, n) = self.planes[patch as usize];
        let (touch, rank, ends) = match region {
            Region::Face => {
                // From the patch's one plane, so that every triangle of it
                // gives the same distance and normal.
                let s = (p - point).dot(n);
                if s.abs() >= r {
                    return None;
                }
                let normal = if s < 0.0 { -n } else { n };
                let touch = Touch {
                    overlap: r - s.abs(),
                    normal,
                    point: p - n * s,
                };
                (touch, 0, [u32::MAX; 2])
            }
            Region::Edge(k) => {
                let ids = self.tris[t];
                let (i, j) = (ids[k as usize], ids[(k as usize + 1) % 3]);
                let touch = super::geom::touch_at(p, q, r, n)?;
                (touch, 1, [i.min(j), i.max(j)])
            }
            Region::Corner(k) => {
                let touch = super::geom::touch_at(p, q, r, n)?;
                (touch, 2, [self.tris[t][k as usize]; 2])
            }
        };
        Some(Candidate {
            patch,
            dist: r - touch.overlap,
            rank,
            ends,
            tri: t as u32,
            touch,
        })
    }
}

impl MeshScratch {
    /// The contacts the last [`Mesh::touches`] found, in patch order.
    pub(crate) fn touches(&self) -> &[MeshTouch] {
        &self.touches
    }
}

/// Groups triangles into flat patches: neighbours across an edge whose
/// normals agree to [`COPLANAR`] (either way round: the winding may flip).
/// Patches are numbered by their first triangle; each one's plane is that
/// of its largest triangle.
fn patches(
    vertices: &[DVec3],
    tris: &[[u32; 3]],
    normals: &[DVec3],
) -> (Vec<u32>, Vec<(DVec3, DVec3)>) {
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    let mut first_on_edge: HashMap<(u32, u32), u32> = HashMap::new();
    for (t, ids) in tris.iter().enumerate() {
        for k in 0..3 {
            let (i, j) = (ids[k], ids[(k + 1) % 3]);
            let edge = (i.min(j), i.max(j));
            let Some(&u) = first_on_edge.get(&edge) else {
                first_on_edge.insert(edge, t as u32);
                continue;
            };
            if normals[t].dot(normals[u as usize]).abs() >= 1.0 - COPLANAR {
                let (a, b) = (root(&mut parent, t as u32), root(&mut parent, u));
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut number: HashMap<u32, u32> = HashMap::new();
    let mut patch = Vec::with_capacity(tris.len());
    let mut largest: Vec<(f64, usize)> = Vec::new();
    for (t, ids) in tris.iter().enumerate() {
        let rt = root(&mut parent, t as u32);
        let next = number.len() as u32;
        let p = *number.entry(rt).or_insert(next);
        if p as usize == largest.len() {
            largest.push((-1.0, t));
        }
        let [a, b, c] = ids.map(|i| vertices[i as usize]);
        let area = (b - a).cross(c - a).length();
        if area > largest[p as usize].0 {
            largest[p as usize] = (area, t);
        }
        patch.push(p);
    }
    let planes = largest
        .iter()
        .map(|&(_, t)| (vertices[tris[t][0] as usize], normals[t]))
        .collect();
    (patch, planes)
}

/// The triangles in Morton order of their centroids, and the vertices in
/// order of first use: triangles near each other in space are then near in
/// memory, as are the grains a wall pass meets one after the other (they
/// are sorted by cell), so a lookup finds its triangles in the cache.
fn spatial_order(vertices: Vec<DVec3>, mut tris: Vec<[u32; 3]>) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let centre = |t: &[u32; 3]| t.iter().map(|&i| vertices[i as usize]).sum::<DVec3>() / 3.0;
    let lo = vertices.iter().fold(DVec3::INFINITY, |l, v| l.min(*v));
    let hi = vertices.iter().fold(DVec3::NEG_INFINITY, |h, v| h.max(*v));
    let span = (hi - lo).max(DVec3::splat(1e-300));
    // 10 bits per axis, interleaved.
    let spread = |x: u64| {
        let mut x = x & 0x3ff;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    let key = |t: &[u32; 3]| {
        let f = ((centre(t) - lo) / span * 1023.0)
            .to_array()
            .map(|x| x as u64);
        spread(f[0]) | spread(f[1]) << 1 | spread(f[2]) << 2
    };
    tris.sort_by_cached_key(key);
    let mut new = vec![u32::MAX; vertices.len()];
    let mut out = Vec::with_capacity(vertices.len());
    for t in &mut tris {
        for i in t.iter_mut() {
            if new[*i as usize] == u32::MAX {
                new[*i as usize] = out.len() as u32;
                out.push(vertices[*i as usize]);
            }
            *i = new[*i as usize];
        }
    }
    (out, tris)
}

/// Each vertex's patches, sorted, as one list with offsets.
fn vertex_patch_lists(n: usize, tris: &[[u32; 3]], patch: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (ids, &p) in tris.iter().zip(patch) {
        for &v in ids {
            lists[v as usize].push(p);
        }
    }
    let mut start = Vec::with_capacity(n + 1);
    let mut all = Vec::new();
    for mut l in lists {
        l.sort_unstable();
        l.dedup();
        start.push(all.len() as u32);
        all.extend(l);
    }
    start.push(all.len() as u32);
    (start, all)
}

#[cfg(test)]
mod tests;
