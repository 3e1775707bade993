//! The one place the fields meet the engine: an MD state as a
//! [`Snapshot`] of plain data (grains in memory order, grain–grain contacts
//! from [`Md::contact_list`], wall contacts from [`Md::wall_contact_list`]).

use crate::dim::Dim;
use crate::io::contact_records::{dot, scale, sub, ContactRecord, Snapshot, WallRecord};
use crate::md::Md;
use rustc_hash::FxHashMap;

/// The owned grains and the contacts of `md` now.
pub fn snapshot<D: Dim>(md: &Md<D>) -> Snapshot {
    let p = &md.particles;
    let n = p.n_owned();
    let mut s = Snapshot {
        dim: D::D,
        time: md.time,
        step: md.step,
        id: p.id[..n].to_vec(),
        pos: p.pos[..n].iter().map(|&x| D::to_xyz(x)).collect(),
        vel: p.vel[..n].iter().map(|&v| D::to_xyz(v)).collect(),
        mass: p.mass[..n].to_vec(),
        radius: p.radius[..n].to_vec(),
        lo: D::to_xyz(md.domain.lo),
        hi: D::to_xyz(md.domain.hi),
        periodic: md.domain.periodic,
        ..Snapshot::default()
    };
    let index: FxHashMap<u64, usize> = s.id.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let pairs = md.contact_list();
    for k in 0..pairs.ids.len() {
        let [a, b] = pairs.ids[k];
        let (Some(&i), Some(&j)) = (index.get(&a), index.get(&b)) else {
            continue;
        };
        let normal = D::to_xyz(pairs.normal[k]);
        let f = D::to_xyz(pairs.force[k]);
        let force_n = scale(normal, dot(f, normal));
        let overlap = pairs.overlap[k];
        let branch = s.minimum_image(sub(s.pos[i], s.pos[j]));
        let reach = s.radius[j] - 0.5 * overlap;
        let point = [0, 1, 2].map(|c| s.pos[j][c] + normal[c] * reach);
        s.contacts.push(ContactRecord {
            ids: [a, b],
            index: [i, j],
            point,
            branch,
            normal,
            force_n,
            force_t: sub(f, force_n),
            overlap,
        });
    }
    let walls = md.wall_contact_list();
    for k in 0..walls.ids.len() {
        let Some(&i) = index.get(&walls.ids[k]) else {
            continue;
        };
        let w = walls.wall[k];
        s.walls.push(WallRecord {
            id: walls.ids[k],
            index: i,
            wall: w,
            wall_name: md.walls[w].name.clone(),
            point: D::to_xyz(walls.point[k]),
            normal: D::to_xyz(walls.normal[k]),
            force: D::to_xyz(walls.force[k]),
            overlap: walls.overlap[k],
        });
    }
    s
}
