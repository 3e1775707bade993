//! The one place the fields meet an engine: its [`GrainView`] as a
//! [`Snapshot`] of plain data (grains in memory order, grain–grain and
//! grain–wall contacts from the view's contact lists).

use crate::dim::Dim;
use crate::io::contact_records::{dot, scale, sub, ContactRecord, Snapshot, WallRecord};
use crate::view::GrainView;
use rustc_hash::FxHashMap;

/// The grains of `view` and their contacts now.
pub fn snapshot<D: Dim>(view: &GrainView<D>) -> Snapshot {
    let p = &view.grains;
    let mut s = Snapshot {
        dim: D::D,
        time: view.time,
        step: view.step,
        id: p.id.to_vec(),
        pos: p.pos.iter().map(|&x| D::to_xyz(x)).collect(),
        vel: p.vel.iter().map(|&v| D::to_xyz(v)).collect(),
        mass: p.mass.to_vec(),
        radius: p.radius.to_vec(),
        lo: D::to_xyz(view.domain.lo),
        hi: D::to_xyz(view.domain.hi),
        periodic: view.domain.periodic,
        ..Snapshot::default()
    };
    let index: FxHashMap<u64, usize> = s.id.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let pairs = view.pair_contacts();
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
    let walls = view.wall_contacts();
    for k in 0..walls.ids.len() {
        let Some(&i) = index.get(&walls.ids[k]) else {
            continue;
        };
        let w = walls.wall[k];
        s.walls.push(WallRecord {
            id: walls.ids[k],
            index: i,
            wall: w,
            wall_name: view.walls[w].name.clone(),
            point: D::to_xyz(walls.point[k]),
            normal: D::to_xyz(walls.normal[k]),
            force: D::to_xyz(walls.force[k]),
            overlap: walls.overlap[k],
        });
    }
    s
}
