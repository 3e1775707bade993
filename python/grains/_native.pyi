"""Type stubs of grains' native module (re-exported by `grains`)."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
#: Overrides: {"contact.mu": 0.3} or ["contact.mu=0.3", ...] (as --set).
Overrides = Union[Mapping[str, Any], Sequence[str], str]

class InputError(ValueError):
    """Bad input: a scenario key or value, an array of the wrong shape, a
    file that does not parse. The message names the key or the file."""

class UnstableError(RuntimeError):
    """The simulation became unstable (non-finite state, overlap beyond the
    limit); the message says why and suggests a time step."""

class Scenario:
    """A scenario: the TOML text of a file (or string) and the overrides set
    on it, checked at once as `grains run --set` checks them."""

    @staticmethod
    def load(path: PathLike) -> "Scenario":
        """Reads a scenario file; relative paths in it are taken from its
        directory. OSError when unreadable, InputError when invalid."""
    @staticmethod
    def from_toml(text: str, base_dir: Optional[PathLike] = None) -> "Scenario":
        """A scenario from TOML text; relative paths from `base_dir`
        (default: the current directory)."""
    def set(self, key: str, value: Any) -> "Scenario":
        """Sets a dotted key as --set does (`set("contact.mu", 0.3)`,
        `set("walls.0.motion.frequency", 60)`); InputError naming the key
        when the result breaks the schema (the scenario is then unchanged).
        Returns the scenario, so calls chain."""
    def to_toml(self) -> str:
        """The scenario with its overrides as TOML (every key, defaults too)."""
    @property
    def name(self) -> str: ...
    @property
    def origin(self) -> str:
        """The file it came from, or "scenario text"."""
    @property
    def overrides(self) -> List[str]:
        """The overrides applied so far, as KEY=VALUE strings."""

class Simulation:
    """A running simulation of one scenario (MD or DSMC, 2D or 3D).

    Arrays are fresh copies in ascending id order; assign to `positions` or
    `velocities` to change the state (the engine restarts from it as a
    scenario starts: neighbour list rebuilt, springs of pairs still
    touching kept, forces evaluated, integrator history set up).
    """

    def __init__(self, scenario: Union[Scenario, PathLike], threads: Optional[int] = None) -> None:
        """Builds the engine exactly as `grains run` builds it, at step 0.
        `threads`: worker threads (default: the scenario's run.threads,
        else one per core); results do not depend on it. Scenarios with
        [hopper] or run.events raise InputError: run them with grains.run."""
    @staticmethod
    def resume(path: PathLike, threads: Optional[int] = None) -> "Simulation":
        """Continues from a checkpoint file (save_checkpoint, or
        `grains run --checkpoint-every`; a run directory means its newest
        valid checkpoint) bit for bit."""
    @staticmethod
    def from_checkpoint(
        path: PathLike,
        set: Optional[Overrides] = None,
        threads: Optional[int] = None,
        allow_changed_inputs: bool = False,
    ) -> "Simulation":
        """Continues from a checkpoint under its scenario changed by `set`
        (as `grains resume DIR --set`): law, materials, gravity, walls'
        motions, run and outputs may change; grains, box, walls' shapes,
        integrator and skin may not (InputError names the key). Changed
        input files raise InputError unless `allow_changed_inputs`."""
    def run(
        self, steps: Optional[int] = None, time: Optional[float] = None, progress: bool = False
    ) -> None:
        """Advances `steps` steps, or `time` seconds (rounded to steps), or
        with neither to the end of the scenario's run. Releases the GIL;
        Ctrl-C raises KeyboardInterrupt within about a second with the
        engine at a complete step. UnstableError when the state blows up.
        `progress=True` draws a progress bar on sys.stderr (steps done,
        simulated time, time left), redrawn in place about five times a
        second and ended with a newline; off by default."""
    @property
    def step(self) -> int: ...
    @property
    def time(self) -> float:
        """Simulated time (s)."""
    @property
    def dt(self) -> float:
        """Time step (s)."""
    @property
    def dimension(self) -> int:
        """2 or 3."""
    @property
    def method(self) -> str:
        """"md" or "dsmc"."""
    @property
    def name(self) -> str:
        """The scenario's name."""
    def __len__(self) -> int:
        """Number of grains (particles)."""
    @property
    def ids(self) -> npt.NDArray[np.int64]:
        """Grain ids, shape (n,), ascending (DSMC: places in the store)."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Positions (m), shape (n, dim), a copy in id order."""
    @positions.setter
    def positions(self, value: npt.ArrayLike) -> None: ...
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """Velocities (m/s), shape (n, dim), a copy in id order."""
    @velocities.setter
    def velocities(self, value: npt.ArrayLike) -> None: ...
    @property
    def angular_velocities(self) -> npt.NDArray[np.float64]:
        """Angular velocities (rad/s): shape (n,) in 2D, (n, 3) in 3D."""
    @property
    def orientations(self) -> npt.NDArray[np.float64]:
        """Rigid bodies' unit quaternions (w, x, y, z), principal frame to
        space, shape (bodies, 4) in bodies.csv's order; (0, 4) without clumps."""
    @property
    def angular_momenta(self) -> npt.NDArray[np.float64]:
        """Rigid bodies' angular momenta about their centres (kg m^2/s,
        space frame), shape (bodies, 3); (0, 3) without clumps."""
    @property
    def diameters(self) -> npt.NDArray[np.float64]:
        """Diameters (m), shape (n,)."""
    @property
    def masses(self) -> npt.NDArray[np.float64]:
        """Masses (kg), shape (n,)."""
    @property
    def frozen(self) -> npt.NDArray[np.bool_]:
        """Whether each grain is frozen in place, shape (n,)."""
    @property
    def kinetic_energy(self) -> float:
        """Translational kinetic energy of the mobile grains (J)."""
    @property
    def rotational_energy(self) -> float:
        """Rotational kinetic energy of the mobile grains (J)."""
    @property
    def granular_temperature(self) -> float:
        """Mean fluctuation kinetic energy per grain and degree of freedom (J)."""
    def contacts(self) -> Dict[str, npt.NDArray[Any]]:
        """Grain-grain contacts now: ids (m, 2) int64, overlap (m,) m,
        normal (m, dim) from the second grain to the first, force (m, dim)
        on the first grain in N. MD only (InputError for DSMC)."""
    def fields(self, window: int = -1) -> Optional[Dict[str, Any]]:
        """The coarse-grained fields of [measure.fields] averaged over a
        window (default the last; the open one if it has samples), sampled
        during run() at the steps `grains run` samples them, so equal to
        its fields/fields_0000k.csv. None before the first sample; not in
        save_checkpoint's file. G is the grid's shape (cells along axes in
        x, y, z order; () for the single box), d the dimension: axes
        (names), one coordinate array (m) per grid axis named by it,
        point_volume (sum(density) * point_volume is the mass), samples,
        times; float64 arrays density G, packing_fraction G, velocity
        G + (d,), temperature G, kinetic_stress, contact_stress, stress
        G + (d, d) (positive in compression), coordination G, fabric
        G + (d, d). InputError without [measure.fields] (or for DSMC),
        IndexError for a window not there."""
    def summary(self) -> Dict[str, Any]:
        """The run so far with the keys of summary.json that describe the
        engine (the runner's measurement scalars are absent)."""
    @property
    def thermo(self) -> Any:
        """Thermo rows (start, every output interval, end of each run) with
        the columns of thermo.csv: a pandas DataFrame when pandas is
        installed, else a dict of numpy columns."""
    def save_checkpoint(self, path: PathLike) -> str:
        """Writes a checkpoint; Simulation.resume continues from it bit for bit."""

def run(
    scenario: Union[Scenario, PathLike, None] = None,
    out: Optional[PathLike] = None,
    set: Optional[Overrides] = None,
    steps: Optional[int] = None,
    threads: Optional[int] = None,
    quiet: bool = True,
    checkpoint_every: Optional[str] = None,
    overwrite: bool = False,
) -> Dict[str, Any]:
    """Runs a scenario exactly as `grains run` does (engine, files,
    summary.json) and returns the summary. None runs the built-in default;
    `out` defaults to runs/<name> (runs/<name>-2, ... when that holds a
    run); an `out` that holds another run raises InputError unless
    `overwrite`. Ctrl-C stops the run with a checkpoint and raises
    KeyboardInterrupt."""

def sweep(
    scenario: Union[Scenario, PathLike],
    vary: Mapping[str, Sequence[Any]],
    set: Optional[Overrides] = None,
    out: Optional[PathLike] = None,
    steps: Optional[int] = None,
    jobs: int = 1,
    threads: Optional[int] = None,
    quiet: bool = True,
    overwrite: bool = False,
) -> List[Dict[str, Any]]:
    """Runs the grid of variants as `grains sweep` does (each in
    out/<key=value_...>, default runs/<name>-sweep; a variant's directory
    that holds a run raises InputError unless `overwrite`). Returns per
    variant: values, dir, summary (None if it failed), error (None if it
    ran)."""
