//! What a flow scenario adds: `run.events` and the `[hopper]` silo.
//!
//! Events settle the grains, then remove a wall, tilt gravity or sink
//! grains; the hopper is a silo built from a few numbers.

use serde::{Deserialize, Serialize};

/// Events during a run. Settling ends when the kinetic energy per mobile
/// grain falls below `settle_energy` m g d0 (m the mean grain mass), but not
/// before `settle_min` seconds; then `remove_wall` disappears, or gravity
/// starts to turn at `tilt_rate` (the box tilts) until the grains flow.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EventsSpec {
    /// Threshold of the kinetic energy per grain, in units of m g d0; default 1e-3.
    #[serde(default = "default_settle_energy")]
    pub settle_energy: f64,
    /// Earliest end of settling (s); default 0.
    #[serde(default)]
    pub settle_min: f64,
    /// Name of the wall removed once settled.
    #[serde(default)]
    pub remove_wall: Option<String>,
    /// Tilting rate of gravity (degrees per second) once settled; the box is
    /// tilted so that the pile leans towards +x.
    #[serde(default)]
    pub tilt_rate: Option<f64>,
    /// The pile has failed when the kinetic energy per grain exceeds this
    /// (units of m g d0) while tilting; default 1e-2.
    #[serde(default = "default_fail_energy")]
    pub fail_energy: f64,
    /// Grains below this height (m) are taken out of the run: frozen and
    /// parked below it (they fell out of the box).
    #[serde(default)]
    pub sink: Option<f64>,
}

fn default_settle_energy() -> f64 {
    1e-3
}
fn default_fail_energy() -> f64 {
    1e-2
}

/// A flat-bottomed silo built from planes (sides) and segments/polygons
/// (the floor with a centred outlet). 2D: a slot of width `outlet`; 3D: a
/// square orifice of side `outlet`. Grains that leave through the outlet and
/// fall below `sink` are put back at the top (recycled), so discharge is
/// steady; or, with `recycle = false`, an outlet takes them out.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HopperSpec {
    /// Outlet width D (m): the gap between the floor's edges.
    pub outlet: f64,
    /// Height of the floor (m); default 0.
    #[serde(default)]
    pub floor: f64,
    /// Grains below this height (m) are recycled; default floor − 10 d0.
    #[serde(default)]
    pub sink: Option<f64>,
    /// Height band (m) where recycled grains are put back, [low, high].
    pub refill: Vec<f64>,
    /// Discharge before the flow rate is measured (s); default 0.
    #[serde(default)]
    pub transient: f64,
    /// Whether grains below `sink` go back to the top (default true). With
    /// false an `[[outlets]]` entry must take them out of the run.
    #[serde(default = "super::yes")]
    pub recycle: bool,
    /// A wall named "gate" closing the orifice (default false), for
    /// `run.events.remove_wall = "gate"` to open once the fill has settled.
    #[serde(default)]
    pub gate: bool,
}
