//! The benchmark gas (mirrors SPARTA's `bench/sparta/in.hs3d`): elastic hard
//! spheres (disks in 2D) in a periodic box, 10 particles per cell on
//! average, cell edge = λ/2 (λ = 1/(√2 n σ_cross) the mean free path), a
//! time step with ω τ = 0.30 (0.15 collision events per particle per step,
//! mean flight 0.6 cells per step), Maxwellian start. Units: cell edge 1,
//! m = 1, T/m = 1. No dense-gas correction (SPARTA has none; ν ≈ 0.006 in
//! 3D, 0.0025 in 2D).

use super::collide::GasDim;
use super::dense::DenseGas;
use super::engine::{collision_frequency, maxwellian, Dsmc, DsmcSettings};
use super::placement::{gas_in_cell_order, GasDraw, GasVelocity};
use super::rng::Stream;
use super::sort::CellGrid;
use super::store::{Particle, Store};
use crate::domain::Domain;

/// Particles per cell of the workload.
pub const PER_CELL: f64 = 10.0;
/// ω τ of the workload.
pub const OMEGA_DT: f64 = 0.30;

/// The hard-sphere benchmark gas with about `n` particles (rounded to fill
/// whole cells) and elastic collisions.
pub fn hard_sphere_gas<D: GasDim>(n: usize, seed: u64) -> Dsmc<D> {
    hard_sphere_gas_reporting(n, seed, &mut |_| {})
}

/// [`hard_sphere_gas`], telling `report` how its set-up goes (one line per
/// pass of [`gas_in_cell_order`]).
pub fn hard_sphere_gas_reporting<D: GasDim>(
    n: usize,
    seed: u64,
    report: &mut dyn FnMut(&str),
) -> Dsmc<D> {
    let cells = (n as f64 / PER_CELL).max(1.0);
    // Cells per axis: 3D like SPARTA's 50 × 50 × 40 (x = y ≥ z), 2D square.
    let mut nc = [1usize; 3];
    if D::D == 2 {
        let s = cells.sqrt().round().max(1.0) as usize;
        nc[0] = s;
        nc[1] = ((cells / s as f64).round() as usize).max(1);
    } else {
        let s = cells.cbrt().round().max(1.0) as usize;
        nc[0] = s;
        nc[1] = s;
        nc[2] = ((cells / (s * s) as f64).round() as usize).max(1);
    }
    let total_cells: usize = nc[..D::D].iter().product();
    let count = (PER_CELL as usize) * total_cells;
    let density = PER_CELL; // per unit cell volume
                            // λ = 1/(√2 n σ_cross) = 2 (two cell edges).
    let cross = 1.0 / (std::f64::consts::SQRT_2 * density * 2.0);
    let diameter = if D::D == 2 {
        cross / 2.0
    } else {
        (cross / std::f64::consts::PI).sqrt()
    };
    let omega = collision_frequency(D::D, density, diameter, 1.0, 1.0);
    let dt = OMEGA_DT / omega;
    let mut hi = D::zero();
    for (a, &k) in nc.iter().enumerate().take(D::D) {
        D::set(&mut hi, a, k as f64);
    }
    let domain = Domain::new(D::zero(), hi, [true; 3]);
    let settings = DsmcSettings {
        dt,
        restitution: 1.0,
        wall_restitution: 1.0,
        dense: DenseGas::None,
        rcp: 0.64,
        seed,
        cell: 1.0,
        vmax_floor: 0.0,
    };
    // Uniform in the box (x = 0 + u k, the same bits as u k), Maxwellian
    // with √(T/m) = 1.
    let draw = GasDraw::<D> {
        seed,
        purpose: 1,
        lo: D::zero(),
        hi,
        velocity: GasVelocity::Maxwellian { thermal_speed: 1.0 },
    };
    let grid = CellGrid::for_domain(&domain, settings.cell);
    let placed = gas_in_cell_order(&draw, count, &grid, report)
        .expect("the workload's count is far below the limit");
    let store = Store::new(placed.particles, diameter, 1.0);
    Dsmc::with_speed_sum(
        store,
        domain,
        D::zero(),
        Vec::new(),
        settings,
        placed.speed_sum,
    )
}

/// A homogeneous gas in a periodic cube (square in 2D) for tests and
/// studies.
#[derive(Clone, Copy, Debug)]
pub struct PeriodicGas {
    pub count: usize,
    /// Box edge.
    pub length: f64,
    pub diameter: f64,
    /// √(T/m) of the initial Maxwellian (m = 1).
    pub thermal_speed: f64,
    pub cell: f64,
    pub dt: f64,
    pub restitution: f64,
    pub dense: DenseGas,
    pub seed: u64,
}

impl PeriodicGas {
    /// Builds the engine: uniform positions, Maxwellian velocities with the
    /// mean removed (zero total momentum).
    pub fn build<D: GasDim>(&self) -> Dsmc<D> {
        let mut rng = Stream::for_purpose(self.seed, 2);
        let mut p: Vec<Particle<D>> = (0..self.count)
            .map(|_| {
                let mut x = D::zero();
                for a in 0..D::D {
                    D::set(&mut x, a, rng.uniform() * self.length);
                }
                Particle {
                    x,
                    v: maxwellian::<D>(&mut rng, self.thermal_speed),
                }
            })
            .collect();
        let mean = p.iter().fold(D::zero(), |a, q| a + q.v) / self.count.max(1) as f64;
        for q in &mut p {
            q.v -= mean;
        }
        let mut hi = D::zero();
        for a in 0..D::D {
            D::set(&mut hi, a, self.length);
        }
        Dsmc::new(
            Store::new(p, self.diameter, 1.0),
            Domain::new(D::zero(), hi, [true; 3]),
            D::zero(),
            Vec::new(),
            DsmcSettings {
                dt: self.dt,
                restitution: self.restitution,
                wall_restitution: 1.0,
                dense: self.dense,
                rcp: super::dense::default_rcp(D::D),
                seed: self.seed,
                cell: self.cell,
                vmax_floor: 0.0,
            },
        )
    }
}
