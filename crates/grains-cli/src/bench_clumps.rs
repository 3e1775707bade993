//! `grains bench chute-clumps`: the chute with its flowing grains as rigid
//! three-sphere rods.
//!
//! The frozen base of `bench-chute.toml` (the spheres of type 2 of
//! `bench/data.chute_flow`) stays; its flowing spheres are replaced by the
//! rods of `bench/chute-clumps.bodies` (made by `bench/make_chute_clumps.py`,
//! which writes the same bodies for LAMMPS's `bench/in.chute-clumps`): three
//! spheres of d = 1 at spacing 0.5 along the body's x axis, orientations
//! uniform on rotations, each rod with the velocity of the sphere it replaced.
//! The law, time step and skin are the chute's. A rod's mass and moments are
//! those `fix rigid/small` sums from its three atoms of mass 1 (overlaps
//! counted per sphere, each sphere's own 2/5 m r²), so that both codes move
//! the same bodies.

use grains::md::Md;
use grains::rigid::{BodySpec, Shape, SubSphere};
use grains::scenario::{build_md, Loaded};
use grains::{Dim, Error, Result, D3};
use std::path::{Path, PathBuf};

/// Spacing of a rod's spheres along its axis, in diameters.
const SPACING: f64 = 0.5;

/// The rod: three spheres of d = 1 (mass 1 each, as the chute's density
/// 1.9098593 gives a sphere of d = 1) along x. About its centre, as LAMMPS
/// sums point masses and the spheres' own moments: I_x = 3 · 2/5 · m r²,
/// I_y = I_z = I_x + 2 m s².
fn rod() -> Shape<D3> {
    let (m, r) = (1.0, 0.5);
    let own = 0.4 * m * r * r;
    let ends = 2.0 * m * SPACING * SPACING;
    Shape {
        name: "rod".into(),
        spheres: [-SPACING, 0.0, SPACING]
            .iter()
            .map(|&x| SubSphere {
                center: D3::from_xyz([x, 0.0, 0.0]),
                radius: r,
            })
            .collect(),
        mass: 3.0 * m,
        inertia: [3.0 * own, 3.0 * own + ends, 3.0 * own + ends],
    }
}

/// Finds `bench/<file>` from the working directory or the source tree.
fn bench_path(file: &str) -> Result<PathBuf> {
    crate::repo_file::repo_file(
        "bench",
        file,
        " (or make it with `python3 bench/make_chute_clumps.py`)",
    )
}

/// The bodies of a file of lines `x y z qw qx qy qz vx vy vz` (`#` starts
/// a comment).
fn read_bodies(path: &Path) -> Result<Vec<BodySpec<D3>>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::input(format!("{}: {e}", path.display())))?;
    let mut bodies = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| Error::input(format!("{} line {}: {e}", path.display(), n + 1)))?;
        let [x, y, z, qw, qx, qy, qz, vx, vy, vz] = v[..] else {
            return Err(Error::input(format!(
                "{} line {}: {} numbers, expected 10 (x y z qw qx qy qz vx vy vz)",
                path.display(),
                n + 1,
                v.len()
            )));
        };
        bodies.push(BodySpec {
            shape: 0,
            kind: 0,
            pos: D3::from_xyz([x, y, z]),
            orientation: [qw, qx, qy, qz],
            vel: D3::from_xyz([vx, vy, vz]),
            omega: D3::ang_from_xyz([0.0; 3]),
        });
    }
    Ok(bodies)
}

/// The clump chute's engine: the chute's base and the rods; the number of
/// bodies.
pub(crate) fn build(loaded: &Loaded) -> Result<(Md<D3>, usize)> {
    let (mut md, _) = build_md::<D3>(loaded)?;
    let n = md.particles.n_owned();
    let flowing: Vec<u64> = (0..n)
        .filter(|&i| !md.particles.frozen[i])
        .map(|i| md.particles.id[i])
        .collect();
    md.remove_grains(&flowing)?;
    let bodies = read_bodies(&bench_path("chute-clumps.bodies")?)?;
    let count = bodies.len();
    md.add_bodies(vec![rod()], bodies)?;
    Ok((md, count))
}

/// What the bench reports of the bodies after the timed steps, to set
/// beside LAMMPS's `ke/rigid`, `erotate/rigid` and `vcm(rods,x)`.
pub(crate) struct Report {
    bodies: usize,
    translational: f64,
    rotational: f64,
    mean_vx: f64,
}

impl Report {
    /// The bodies of `md` now.
    pub(crate) fn of(md: &Md<D3>, count: usize) -> Report {
        let (translational, rotational, mean_vx) = md.bodies().map_or((0.0, 0.0, 0.0), |b| {
            let n = b.bodies.len().max(1) as f64;
            let vx: f64 = b.bodies.iter().map(|body| body.vel.x).sum();
            (b.translational_energy(), b.rotational_energy(), vx / n)
        });
        Report {
            bodies: count,
            translational,
            rotational,
            mean_vx,
        }
    }

    /// Its keys in the bench's JSON line.
    pub(crate) fn write(&self, map: &mut serde_json::Map<String, serde_json::Value>) {
        map.insert("bodies".into(), self.bodies.into());
        map.insert("body_kinetic_energy".into(), self.translational.into());
        map.insert("body_rotational_energy".into(), self.rotational.into());
        map.insert("body_mean_vx".into(), self.mean_vx.into());
    }

    /// Its line of the text output.
    pub(crate) fn line(&self) -> String {
        format!(
            "  {} rods (the particles above are their sub-spheres); after the steps: ½MV² {:.12e}, ½L·ω {:.12e}, mean vx {:.12e}",
            self.bodies, self.translational, self.rotational, self.mean_vx
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rod's moments against the parallel-axis theorem by hand: the
    /// spheres' own 3 · 0.1 = 0.3, the end spheres' 2 · 0.25 = 0.5.
    #[test]
    fn rod_moments_are_lammps_sums() {
        let s = rod();
        assert_eq!(s.mass, 3.0);
        assert!((s.inertia[0] - 0.3).abs() < 1e-15);
        assert!((s.inertia[1] - 0.8).abs() < 1e-15);
        assert!((s.inertia[2] - 0.8).abs() < 1e-15);
    }
}
