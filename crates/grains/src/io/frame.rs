//! A neutral snapshot of the particles, independent of the engine's storage.

/// One snapshot of the system: everything the writers need, as plain arrays.
///
/// Vectors are always 3 components; in 2D the z component of positions and
/// velocities is 0 and the spin is the z component of `omega`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    pub step: u64,
    pub time: f64,
    /// 2 or 3.
    pub dim: usize,
    pub box_lo: [f64; 3],
    pub box_hi: [f64; 3],
    pub periodic: [bool; 3],
    pub id: Vec<u64>,
    pub kind: Vec<u32>,
    pub pos: Vec<[f64; 3]>,
    pub vel: Vec<[f64; 3]>,
    pub omega: Vec<[f64; 3]>,
    pub radius: Vec<f64>,
    /// Each grain's rigid body, numbered from 1 (0 for a free sphere), so
    /// that viewers group a clump's sub-spheres; `None` in a run without
    /// bodies, whose outputs then keep their columns.
    pub body: Option<Vec<u64>>,
    /// Each grain's orientation, its body's unit quaternion (w, x, y, z)
    /// from the body's principal frame to space (identity for a free
    /// sphere); `None` in a run without bodies.
    pub orientation: Option<Vec<[f64; 4]>>,
    /// Each grain's mass where the run saves it (`output.contacts`, for
    /// `grains cg`); empty otherwise.
    pub mass: Vec<f64>,
}

impl Frame {
    /// Number of particles (the length of `pos`).
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Panics with a clear message if the per-particle arrays disagree in
    /// length; writers call this so a programming error is caught early.
    pub(crate) fn check_lengths(&self) {
        let n = self.pos.len();
        let lens = [
            ("id", self.id.len()),
            ("kind", self.kind.len()),
            ("vel", self.vel.len()),
            ("omega", self.omega.len()),
            ("radius", self.radius.len()),
        ];
        for (name, len) in lens {
            assert_eq!(len, n, "Frame.{name} has {len} entries but pos has {n}");
        }
        if let Some(b) = &self.body {
            let len = b.len();
            assert_eq!(len, n, "Frame.body has {len} entries but pos has {n}");
        }
        if let Some(q) = &self.orientation {
            let len = q.len();
            assert_eq!(
                len, n,
                "Frame.orientation has {len} entries but pos has {n}"
            );
        }
        let m = self.mass.len();
        assert!(
            m == 0 || m == n,
            "Frame.mass has {m} entries but pos has {n}"
        );
    }

    /// Speed |v| of particle `i`.
    pub fn speed(&self, i: usize) -> f64 {
        let v = self.vel[i];
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    /// The vertical axis: y (1) in 2D, z (2) in 3D.
    pub fn vertical(&self) -> usize {
        if self.dim == 3 {
            2
        } else {
            1
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small 2D frame used by the writers' tests.
    pub(crate) fn sample_2d() -> Frame {
        Frame {
            step: 1200,
            time: 0.12,
            dim: 2,
            box_lo: [0.0, 0.0, -0.5],
            box_hi: [10.0, 20.0, 0.5],
            periodic: [true, false, false],
            id: vec![1, 2, 7],
            kind: vec![1, 1, 2],
            pos: vec![[1.0, 1.0, 0.0], [3.25, 1.5, 0.0], [7.0, 4.0, 0.0]],
            vel: vec![[0.5, -1.0, 0.0], [0.0, 0.0, 0.0], [1e-17, 2.0, 0.0]],
            omega: vec![[0.0, 0.0, 0.25], [0.0, 0.0, -3.0], [0.0, 0.0, 0.0]],
            radius: vec![0.5, 0.6, 0.45],
            body: None,
            orientation: None,
            mass: Vec::new(),
        }
    }

    #[test]
    fn speed_and_vertical() {
        let f = sample_2d();
        assert_eq!(f.len(), 3);
        assert!((f.speed(0) - 1.25f64.sqrt()).abs() < 1e-15);
        assert_eq!(f.vertical(), 1);
        f.check_lengths();
    }
}
