//! A clump's [`Shape`] from its spheres as written: the union's mass
//! properties, its principal axes, and the spheres moved into that frame.
//!
//! 3D clumps and 2D clumps under `MassModel::Sphere` are unions of balls
//! (a disk weighs what its sphere weighs, as single grains do); 2D clumps
//! under `MassModel::Disk` are unions of disks of unit thickness, their
//! mass the density times the area. The inertia tensor about the centre of
//! mass is ρ (tr S · 1 − S) with S = ∫(x − x̄)(x − x̄)ᵀ over the union; its
//! eigenvectors (Jacobi rotations; about z only in 2D) are the body axes.

use super::mass::{union_2d, union_3d, Ball, Moments};
use super::{Shape, SubSphere};
use crate::dim::Dim;
use crate::particles::MassModel;
use glam::{DMat3, DQuat, DVec3};

/// Two spheres touch, and so join a clump, when their centres are at most
/// this fraction beyond the sum of their radii apart (rounding in the
/// written numbers).
pub const TOUCH: f64 = 1e-9;

/// What `grains check` reports of a shape besides the [`Shape`] itself.
#[derive(Clone, Debug, PartialEq)]
pub struct Props {
    /// Volume (3D, and 2D under the sphere mass model) or area (m³ or m²).
    pub measure: f64,
    /// Centre of mass in the input frame (m).
    pub com: DVec3,
    /// Inertia tensor about the centre of mass, input frame (kg m²).
    pub inertia: DMat3,
    /// The principal axes in the input frame, as columns (right-handed),
    /// in the order of the shape's principal moments (ascending in 3D).
    pub axes: DMat3,
    /// The rotation from the principal frame to the input frame.
    pub to_input: DQuat,
    /// Largest distance of a sub-sphere's surface from the centre of mass.
    pub bounding_radius: f64,
    /// True when the mass properties are closed forms, false when a piece
    /// was integrated by quadrature.
    pub exact: bool,
    /// The last change of a refined quadrature, relative (0 when exact).
    pub last_change: f64,
}

/// The index of a sphere not joined to the first through touching or
/// overlapping spheres, if any.
pub fn detached(balls: &[Ball]) -> Option<usize> {
    let mut joined = vec![false; balls.len()];
    let mut todo = vec![0];
    if let Some(j) = joined.first_mut() {
        *j = true;
    }
    while let Some(i) = todo.pop() {
        for (j, b) in balls.iter().enumerate() {
            let reach = (balls[i].1 + b.1) * (1.0 + TOUCH);
            if !joined[j] && (balls[i].0 - b.0).length() <= reach {
                joined[j] = true;
                todo.push(j);
            }
        }
    }
    joined.iter().position(|&j| !j)
}

/// The shape of a clump of `balls` (centres in the input frame, z = 0 in
/// 2D) of material density `density`; `model` is the grains' mass model,
/// which only 2D reads.
pub fn clump<D: Dim>(
    name: &str,
    balls: &[Ball],
    density: f64,
    model: MassModel,
) -> (Shape<D>, Props) {
    let flat = D::D == 2 && model == MassModel::Disk;
    let union = if flat {
        union_2d(balls)
    } else {
        union_3d(balls)
    };
    let m: Moments = union.moments;
    let com = m.centroid();
    let s = m.central();
    let inertia =
        (DMat3::from_diagonal(DVec3::splat(s.x_axis.x + s.y_axis.y + s.z_axis.z)) - s) * density;
    let axes = if D::D == 2 {
        // In the plane: the body x axis along the largest spread.
        let angle = 0.5 * (2.0 * s.y_axis.x).atan2(s.x_axis.x - s.y_axis.y);
        DMat3::from_rotation_z(angle)
    } else {
        principal_axes(inertia)
    };
    let body = axes.transpose() * inertia * axes;
    let spheres: Vec<SubSphere<D>> = balls
        .iter()
        .map(|&(c, r)| {
            let y = axes.transpose() * (c - com);
            SubSphere {
                center: D::from_xyz(y.to_array()),
                radius: r,
            }
        })
        .collect();
    let bounding_radius = spheres
        .iter()
        .map(|s| D::norm(s.center) + s.radius)
        .fold(0.0, f64::max);
    let shape = Shape {
        name: name.to_string(),
        spheres,
        mass: density * m.m0,
        inertia: [body.x_axis.x, body.y_axis.y, body.z_axis.z],
    };
    let props = Props {
        measure: m.m0,
        com,
        inertia,
        axes,
        to_input: DQuat::from_mat3(&axes).normalize(),
        bounding_radius,
        exact: union.exact,
        last_change: union.last_change,
    };
    (shape, props)
}

/// The eigenvectors of a symmetric 3×3 matrix as the columns of a
/// rotation (determinant +1), ordered by ascending eigenvalue: cyclic
/// Jacobi rotations, each zeroing one off-diagonal entry, until the
/// off-diagonal part is below 1e-15 of the matrix (Golub & Van Loan,
/// "Matrix Computations", §8.5).
pub fn principal_axes(m: DMat3) -> DMat3 {
    let mut a = m.to_cols_array_2d();
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let norm = a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    for _sweep in 0..50 {
        let off = (a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2)).sqrt();
        if off <= 1e-15 * norm {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane.
            for row in a.iter_mut() {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
            let (rp, rq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * rp[k] - s * rq[k];
                a[q][k] = s * rp[k] + c * rq[k];
            }
            for row in v.iter_mut() {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
        }
    }
    // a is symmetric (the array is columns, the same as rows); v's rows
    // hold the eigenvectors' components, its columns the eigenvectors.
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let col = |k: usize| DVec3::new(v[0][k], v[1][k], v[2][k]);
    let (x, y) = (col(order[0]), col(order[1]));
    DMat3::from_cols(x, y, x.cross(y))
}

/// Quaternion (w, x, y, z) as glam's.
pub fn quat(q: [f64; 4]) -> DQuat {
    DQuat::from_xyzw(q[1], q[2], q[3], q[0])
}

/// glam's quaternion as (w, x, y, z).
pub fn wxyz(q: DQuat) -> [f64; 4] {
    [q.w, q.x, q.y, q.z]
}

/// The centre of a sub-sphere in space: the body's position plus its
/// body-frame offset turned by the orientation.
pub fn placed<D: Dim>(pos: D::V, orientation: DQuat, offset: D::V) -> D::V {
    pos + D::from_xyz((orientation * DVec3::from_array(D::to_xyz(offset))).to_array())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D3;

    #[test]
    fn jacobi_finds_the_axes_of_a_turned_diagonal() {
        let turn = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::ZYX, 0.3, -1.1, 0.7));
        let m = turn * DMat3::from_diagonal(DVec3::new(3.0, 1.0, 2.0)) * turn.transpose();
        let r = principal_axes(m);
        let d = r.transpose() * m * r;
        assert!((d.x_axis.x - 1.0).abs() < 1e-13 && (d.y_axis.y - 2.0).abs() < 1e-13);
        assert!((d.z_axis.z - 3.0).abs() < 1e-13 && d.y_axis.x.abs() < 1e-13);
        assert!((r.determinant() - 1.0).abs() < 1e-13);
    }

    #[test]
    fn a_chain_with_a_gap_is_detached() {
        let b = |x: f64| (DVec3::new(x, 0.0, 0.0), 0.5);
        assert_eq!(detached(&[b(0.0), b(1.0), b(2.0)]), None);
        assert_eq!(detached(&[b(0.0), b(1.0), b(2.1)]), Some(2));
        let (s, _) = clump::<D3>("one", &[b(0.0)], 1.0, MassModel::Sphere);
        assert_eq!(s.spheres.len(), 1);
    }
}
