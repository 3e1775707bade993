//! The plain data that coarse-graining reads: grains (position, velocity,
//! mass, radius) and contact records, with no reference to an engine.
//!
//! Vectors are 3-vectors in both dimensions (z = 0 in 2D), so the writers
//! and the fields need no dimension parameter.

/// One grain–grain contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactRecord {
    /// The two grains' ids.
    pub ids: [u64; 2],
    /// Their indices in the [`Snapshot`]'s arrays.
    pub index: [usize; 2],
    /// The contact point: on the line of centres, in the middle of the
    /// overlap (`x_j + n (r_j − δ/2)`).
    pub point: [f64; 3],
    /// The branch vector `x_i − x_j` between the centres (minimum image).
    pub branch: [f64; 3],
    /// Unit normal from the second grain to the first.
    pub normal: [f64; 3],
    /// Normal part of the force on the first grain.
    pub force_n: [f64; 3],
    /// Tangential part of the force on the first grain.
    pub force_t: [f64; 3],
    /// Overlap r_i + r_j − |x_i − x_j|.
    pub overlap: f64,
}

impl ContactRecord {
    /// The whole force on the first grain.
    pub fn force(&self) -> [f64; 3] {
        add(self.force_n, self.force_t)
    }
}

/// One grain–wall contact.
#[derive(Clone, Debug, PartialEq)]
pub struct WallRecord {
    /// The grain's id and its index in the [`Snapshot`]'s arrays.
    pub id: u64,
    pub index: usize,
    /// The wall's index among the engine's walls, and its name.
    pub wall: usize,
    pub wall_name: String,
    /// The contact point on the wall.
    pub point: [f64; 3],
    /// Unit normal from the wall towards the grain.
    pub normal: [f64; 3],
    /// The force the wall puts on the grain.
    pub force: [f64; 3],
    pub overlap: f64,
}

/// The grains and contacts of one instant.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Snapshot {
    /// 2 (disks) or 3 (spheres).
    pub dim: usize,
    pub time: f64,
    pub step: u64,
    pub id: Vec<u64>,
    pub pos: Vec<[f64; 3]>,
    pub vel: Vec<[f64; 3]>,
    pub mass: Vec<f64>,
    pub radius: Vec<f64>,
    pub contacts: Vec<ContactRecord>,
    pub walls: Vec<WallRecord>,
    /// The box: lower and upper corners, and which axes are periodic.
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub periodic: [bool; 3],
}

impl Snapshot {
    /// The volume of grain `i` (the area of a disk in 2D).
    pub fn grain_volume(&self, i: usize) -> f64 {
        let r = self.radius[i];
        match self.dim {
            2 => std::f64::consts::PI * r * r,
            _ => 4.0 / 3.0 * std::f64::consts::PI * r * r * r,
        }
    }

    /// `d` reduced to its minimum image along the periodic axes.
    pub fn minimum_image(&self, mut d: [f64; 3]) -> [f64; 3] {
        for (a, x) in d.iter_mut().enumerate().take(self.dim) {
            if self.periodic[a] {
                let l = self.hi[a] - self.lo[a];
                *x -= l * (*x / l).round();
            }
        }
        d
    }

    /// The mean grain diameter d0.
    pub fn mean_diameter(&self) -> f64 {
        match self.radius.len() {
            0 => 0.0,
            n => 2.0 * self.radius.iter().sum::<f64>() / n as f64,
        }
    }

    /// Σ over contacts (grain pairs and walls) of f ⊗ b, with b the branch
    /// vector from the second grain to the first (from the contact point to
    /// the grain for a wall): the contact virial, `[α][β] = Σ f_α b_β`.
    pub fn contact_virial(&self) -> [[f64; 3]; 3] {
        let mut w = [[0.0; 3]; 3];
        for c in &self.contacts {
            add_outer(&mut w, c.force(), c.branch, 1.0);
        }
        for c in &self.walls {
            let b = sub(self.pos[c.index], c.point);
            add_outer(&mut w, c.force, b, 1.0);
        }
        w
    }
}

pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `t += s a ⊗ b`.
pub fn add_outer(t: &mut [[f64; 3]; 3], a: [f64; 3], b: [f64; 3], s: f64) {
    for (row, &x) in t.iter_mut().zip(&a) {
        for (e, &y) in row.iter_mut().zip(&b) {
            *e += s * x * y;
        }
    }
}
