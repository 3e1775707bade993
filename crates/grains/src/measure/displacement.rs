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
