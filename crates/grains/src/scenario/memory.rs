//! What a run needs in memory, to refuse up front one that cannot fit.
//!
//! The figures are peak resident bytes per grain or particle, measured with
//! 10^6 grains (MD) and 10^7 particles (DSMC) on one thread, everything
//! included (the set-up's records, the state, the neighbour list and its
//! springs, the cell lists), rounded up by a few percent:
//!
//! ```text
//! grains bench bed3d --particles 1000000 --steps 5 --integrator verlet   282 B
//! grains bench bed3d --particles 1000000 --steps 5 --integrator gear5    474 B
//! a 2D bed of 10^6 disks (grains run, 5 steps), Verlet / Gear-5     277 / 369 B
//! grains bench gas2d --particles 10000000 --steps 3                  44.1 B
//! grains bench gas3d --particles 10000000 --steps 3                  66.7 B
//! ```
//!
//! The DSMC figures include the re-sorts of the 30 warm-up steps,
//! whose ring and side list (`dsmc::sort::Aside`) span a few layers of
//! cells: about 6 B per particle in 3D at 10^7, under 1 B in 2D.
//!
//! Gear-5 keeps eight more vectors per grain (four derivatives each of
//! position and spin), which is the difference between the two integrators.

use crate::error::{Error, Result};
use crate::integrate::Integrator;

/// Peak bytes per MD grain in `dims` dimensions with `integrator`.
pub fn md_bytes_per_grain(dims: usize, integrator: Integrator) -> u64 {
    match (dims, integrator) {
        (2, Integrator::Verlet) => 290,
        (2, Integrator::Gear5) => 385,
        (_, Integrator::Verlet) => 295,
        (_, Integrator::Gear5) => 495,
    }
}

/// Peak bytes per DSMC particle in `dims` dimensions.
pub fn dsmc_bytes_per_particle(dims: usize) -> u64 {
    if dims == 2 {
        45
    } else {
        70
    }
}

/// Refuses `count` items of `bytes_each` when they cannot fit in the memory
/// available now; `key` names what the user set.
pub fn check(key: &str, count: usize, bytes_each: u64) -> Result<()> {
    let need = (count as u64).saturating_mul(bytes_each);
    match available_memory() {
        Some(avail) if need > avail => Err(Error::input(format!(
            "{key} = {count} needs about {:.1} GiB (about {bytes_each} bytes each), \
             but only {:.1} GiB of memory is available",
            need as f64 / 1073741824.0,
            avail as f64 / 1073741824.0
        ))),
        _ => Ok(()),
    }
}

/// MemAvailable from /proc/meminfo (Linux); `None` elsewhere.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gear-5's history is 8 vectors a grain more than Verlet keeps: 8 × 24
    /// bytes in 3D, 4 × 16 + 4 × 8 in 2D; the figures differ by about that.
    #[test]
    fn gear_costs_its_history() {
        let g3 =
            md_bytes_per_grain(3, Integrator::Gear5) - md_bytes_per_grain(3, Integrator::Verlet);
        let g2 =
            md_bytes_per_grain(2, Integrator::Gear5) - md_bytes_per_grain(2, Integrator::Verlet);
        assert!((g3 as f64 - 192.0).abs() < 0.1 * 192.0, "{g3}");
        assert!((g2 as f64 - 96.0).abs() < 0.1 * 96.0, "{g2}");
    }

    /// An impossible count is refused with the key and the figures; a small
    /// one passes.
    #[test]
    fn impossible_counts_are_refused_by_name() {
        assert!(check("particles.count", 1000, 500).is_ok());
        if available_memory().is_some() {
            let e = check("particles.count", usize::MAX / 2, 500).unwrap_err();
            let msg = e.to_string();
            assert!(
                msg.contains("particles.count") && msg.contains("GiB"),
                "{msg}"
            );
        }
    }
}
