//! Displacement field: where each grain went between two moments (seed 002
//! Figs. 2–3 draw these as arrows). Positions are unwrapped across periodic
//! boundaries by accumulating minimum-image increments at every sample, so
//! samples must be taken often enough that no grain moves half a box between
//! two of them.

use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::view::GrainView;
use std::collections::HashMap;

/// Start position, unwrapped current position, last wrapped position.
type Track = ([f64; 3], [f64; 3], [f64; 3]);

#[derive(Clone, Debug, Default)]
pub struct DisplacementField {
    /// id → track.
    tracks: HashMap<u64, Track>,
    /// Ids in first-seen order, for stable output.
    order: Vec<u64>,
    /// The time the tracking began (`None` when resumed from a checkpoint
    /// written before it was kept).
    pub t0: Option<f64>,
}

/// One grain's start and end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Displacement {
    pub id: u64,
    pub start: [f64; 3],
    pub end: [f64; 3],
}

impl DisplacementField {
    /// Starts tracking every mobile grain from its present position.
    pub fn begin<D: Dim>(view: &GrainView<D>) -> Self {
        let p = &view.grains;
        let mut field = Self {
            t0: Some(view.time),
            ..Self::default()
        };
        for i in 0..p.len() {
            if !p.frozen[i] {
                let x = D::to_xyz(p.pos[i]);
                field.tracks.insert(p.id[i], (x, x, x));
                field.order.push(p.id[i]);
            }
        }
        field
    }

    /// Follows the grains since the last sample.
    pub fn sample<D: Dim>(&mut self, view: &GrainView<D>) {
        let p = &view.grains;
        for i in 0..p.len() {
            if let Some((_, unwrapped, last)) = self.tracks.get_mut(&p.id[i]) {
                let now = p.pos[i];
                let step = view.domain.minimum_image(now - D::from_xyz(*last));
                let s = D::to_xyz(step);
                for a in 0..3 {
                    unwrapped[a] += s[a];
                }
                *last = D::to_xyz(now);
            }
        }
    }

    pub fn displacements(&self) -> Vec<Displacement> {
        self.order
            .iter()
            .map(|id| {
                let (start, end, _) = self.tracks[id];
                Displacement {
                    id: *id,
                    start,
                    end,
                }
            })
            .collect()
    }
}

/// Checkpoint state (see `runner::checkpointing`).
impl DisplacementField {
    pub fn save(&self, e: &mut Enc) {
        e.len(self.order.len());
        for id in &self.order {
            e.u64(*id);
            let (a, b, c) = &self.tracks[id];
            for x in a.iter().chain(b).chain(c) {
                e.f64(*x);
            }
        }
    }

    pub fn load(d: &mut Dec) -> DecResult<Self> {
        let n = d.len(8 + 9 * 8, "displacement tracks")?;
        let mut f = Self::default();
        for _ in 0..n {
            let id = d.u64("displacement id")?;
            let mut x = [[0.0; 3]; 3];
            for v in x.iter_mut().flatten() {
                *v = d.f64("displacement track")?;
            }
            if f.tracks.insert(id, (x[0], x[1], x[2])).is_some() {
                return Err(format!("displacement: grain {id} twice"));
            }
            f.order.push(id);
        }
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use crate::domain::Domain;
    use crate::view::{ContactList, ContactLists, Grains, MeshLoad, MeshLoads, WallContactList};
    use glam::DVec2;

    struct NoLoads;
    impl MeshLoads for NoLoads {
        fn mesh_loads(&self) -> Vec<MeshLoad> {
            Vec::new()
        }
    }
    impl ContactLists<D2> for NoLoads {
        fn pair_contacts(&self) -> ContactList<D2> {
            ContactList::default()
        }
        fn wall_contacts(&self) -> WallContactList<D2> {
            WallContactList::default()
        }
    }

    /// A view built from plain arrays, as an engine other than `Md` gives
    /// one: a disk at x = 0.95 of a periodic unit box is next seen at
    /// x = 0.05. Between two samples it moved less than half the box, so by
    /// the minimum image it went +0.1 across the side, not −0.9 back: its
    /// unwrapped end is 0.95 + 0.1 = 1.05 (to the rounding of 0.05 − 0.95).
    #[test]
    fn displacement_follows_a_grain_across_a_periodic_side() {
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::ONE, [true, true, false]);
        let sample = |field: Option<DisplacementField>, x: f64, time: f64| {
            let v = GrainView::<D2> {
                step: 0,
                time,
                dt: 1e-3,
                domain: &domain,
                gravity: DVec2::ZERO,
                walls: &[],
                grains: Grains {
                    id: &[1],
                    kind: &[1],
                    pos: &[DVec2::new(x, 0.5)],
                    vel: &[DVec2::ZERO],
                    omega: &[0.0],
                    force: &[DVec2::ZERO],
                    radius: &[0.01],
                    mass: &[1.0],
                    frozen: &[false],
                },
                contacts: 0,
                loads: &NoLoads,
                lists: &NoLoads,
            };
            match field {
                None => DisplacementField::begin(&v),
                Some(mut f) => {
                    f.sample(&v);
                    f
                }
            }
        };
        let field = sample(None, 0.95, 0.0);
        let field = sample(Some(field), 0.05, 1.0);
        let d = field.displacements();
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].start, [0.95, 0.5, 0.0]);
        assert!((d[0].end[0] - 1.05).abs() < 1e-12, "{:?}", d[0].end);
        assert_eq!(d[0].end[1], 0.5);
        assert_eq!(field.t0, Some(0.0));
    }
}
