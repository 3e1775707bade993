//! Runs a scenario over several ranks (`mpirun -np N grains run ...`).
//!
//! MD scenarios go to [`super::distributed_md`]. DSMC: each rank steps its
//! slab ([`crate::dsmc::decomp`]) inside [`DistGas`], the decomposed engine
//! the serial run's loop drives ([`super::dsmc`]); at every sampling and
//! output step the ranks gather the whole state on rank 0, into an engine
//! of the same run, and rank 0 measures and writes it with the serial
//! code. The files are therefore the serial
//! run's, byte for byte (summary.json adds `ranks`, `imbalance`,
//! `rebalances`). The gather costs O(N) on rank 0 per sample: for very
//! large runs choose `output.every` and `dsmc.profile_bins` with that in
//! mind.
//!
//! Frames in pieces (`output.frames_layout = "pieces"`): each rank writes
//! its own particles as a piece (ids: serial store positions + 1, as in a
//! gathered frame), rank 0 the `.pvtp`.
//!
//! MD checkpoints and resume: see [`super::distributed_md`]. Not supported
//! yet for DSMC, with a clear error: checkpoints and resume under mpirun
//! (run or resume those on one process). A stop signal ends the run
//! without a checkpoint.

use super::checkpointing::{self, Found};
use super::choose::{choose, Runs};
use super::dsmc::{build, gas_outputs, head, run_loop, GasStart};
use super::engine::GasView;
use super::options::{prepare_fresh, Progress, RunOptions};
use crate::comm::Comm;
use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::dsmc::contract::gas_frame as frame;
use crate::dsmc::decomp::Decomposed;
use crate::dsmc::engine::Dsmc;
use crate::dsmc::Method;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::output::Pieces;
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};

/// Runs `loaded` on the ranks of `comm` (all of them call this). Returns the
/// summary on rank 0 and `Value::Null` elsewhere.
pub fn run(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let md = loaded.scenario.method != Method::Dsmc;
    refuse_device(loaded)?;
    if opts.checkpoint_every.is_some() && !md {
        return Err(Error::input(
            "--checkpoint-every is not supported for a DSMC run on several ranks yet; \
             run it on one process to checkpoint it",
        ));
    }
    // Not on rayon's pool here (unlike `super::run`): ranks that are
    // threads of one process would each hold a pool worker while waiting
    // for the others. The command line puts its single rank on the pool.
    struct Ranks<'a>(
        &'a Loaded,
        &'a RunOptions,
        &'a mut dyn Progress,
        &'a dyn Comm,
    );
    impl Runs for Ranks<'_> {
        type Out = Result<Value>;
        fn md<D: Dim>(self) -> Result<Value> {
            super::distributed_md::run::<D>(self.0, self.1, self.2, self.3)
        }
        fn gas<D: GasDim>(self) -> Result<Value> {
            run_dim::<D>(self.0, self.1, self.2, self.3)
        }
    }
    choose(&loaded.scenario, Ranks(loaded, opts, progress, comm))
}

/// The GPU pipeline runs on one process, never decomposed over ranks.
fn refuse_device(loaded: &Loaded) -> Result<()> {
    if loaded.scenario.run.device.is_cpu() {
        return Ok(());
    }
    Err(Error::input(
        "run.device = \"gpu\" (or \"mirror\") runs on one process: run it without mpirun",
    ))
}

/// Continues a checkpoint (of a serial or a distributed MD run) on the
/// ranks of `comm`; all of them call this with the same checkpoint. Outputs
/// go to the checkpoint's directory, as with [`checkpointing::resume`].
pub fn resume(
    found: Found,
    steps: Option<u64>,
    opts: RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    refuse_device(found.loaded())?;
    let opts = checkpointing::resume_options(&found, opts)?;
    struct Ranks<'a>(
        &'a Found,
        Option<u64>,
        &'a RunOptions,
        &'a mut dyn Progress,
        &'a dyn Comm,
    );
    impl Runs for Ranks<'_> {
        type Out = Result<Value>;
        fn md<D: Dim>(self) -> Result<Value> {
            let Ranks(found, steps, opts, progress, comm) = self;
            super::distributed_md::resume::<D>(found, steps, opts, progress, comm)
        }
        fn gas<D: GasDim>(self) -> Result<Value> {
            Err(Error::input(format!(
                "checkpoint {}: resuming a DSMC run on several ranks is not supported yet; \
                 resume it without mpirun",
                self.0.path.display()
            )))
        }
    }
    choose(
        &found.loaded().scenario,
        Ranks(&found, steps, &opts, progress, comm),
    )
}

fn run_dim<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let root = comm.rank() == 0;
    if root {
        prepare_fresh(opts)?;
    }
    // Every rank builds the same engine; rank 0 keeps a second one to
    // gather the whole state into.
    let (full, plan) = build::<D>(loaded)?;
    let mirror = match root {
        true => Some(build::<D>(loaded)?.0),
        false => None,
    };
    let summary = head(loaded, &full, &plan);
    let dec = Decomposed::new(full, comm).map_err(Error::input)?;
    let mut outputs = match root {
        true => Some(gas_outputs(&opts.out_dir, &loaded.scenario.output)?),
        false => None,
    };
    if let Some(out) = outputs.as_mut() {
        out.set_ranks(comm.size());
    }
    let engine = DistGas {
        dec,
        comm,
        mirror,
        fresh: None,
        pieces: Pieces::new(&loaded.scenario.output, &opts.out_dir, comm),
    };
    let start = GasStart {
        engine,
        every: plan.output_every,
        plan: match opts.steps {
            Some(n) => (0, n),
            None => (plan.relax_steps, plan.measure_steps),
        },
        outputs,
        restored: None,
        summary,
    };
    run_loop(loaded, opts, start, progress)
}

/// The decomposed DSMC engine of one rank: its slab of the gas, and on
/// rank 0 the mirror, an engine of the same run into which the ranks
/// gather the whole gas where a hook reads it.
struct DistGas<'c, D: GasDim> {
    dec: Decomposed<'c, D>,
    comm: &'c dyn Comm,
    mirror: Option<Dsmc<D>>,
    /// The step at which the mirror last received the gas.
    fresh: Option<u64>,
    pieces: Pieces,
}

impl<D: GasDim> DistGas<'_, D> {
    /// This rank's particles, with their serial store positions as ids (as
    /// when gathered).
    fn piece(&self) -> Frame {
        let mut f = frame(&self.dec.sim);
        f.id = self.dec.keys().iter().map(|k| k + 1).collect();
        f
    }
}

impl<D: GasDim> Engine for DistGas<'_, D> {
    fn dim(&self) -> usize {
        D::D
    }
    fn step_count(&self) -> u64 {
        self.dec.sim.step
    }
    fn sim_time(&self) -> f64 {
        self.dec.sim.time
    }
    fn time_step(&self) -> f64 {
        self.dec.sim.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        self.dec.run(n);
        Ok(())
    }
    fn frame(&self) -> Result<Frame> {
        Ok(self.piece())
    }
    fn export(&self) -> Result<Vec<u8>> {
        Err(Error::input(
            "checkpoints of a DSMC run on several ranks are not supported yet; \
             run it on one process to checkpoint it",
        ))
    }
    fn import(&mut self, _: &[u8], origin: &str) -> Result<()> {
        Err(Error::input(format!(
            "checkpoint {origin}: resuming a DSMC run on several ranks is not supported yet"
        )))
    }
    fn writes(&self) -> bool {
        self.comm.rank() == 0
    }
    fn any_rank(&mut self, flag: bool) -> bool {
        let mut n = [u64::from(flag)];
        self.comm.sum_u64(&mut n);
        n[0] > 0
    }
}

impl<D: GasDim> GasView for DistGas<'_, D> {
    type D = D;
    fn whole(&mut self) -> Option<&mut Dsmc<D>> {
        if self.fresh != Some(self.dec.sim.step) {
            self.dec.gather(self.mirror.as_mut());
            self.fresh = Some(self.dec.sim.step);
        }
        self.mirror.as_mut()
    }
    fn write_piece(&self) -> Result<()> {
        self.pieces.write(|| self.piece())
    }
    fn tallies_read(&mut self) {
        self.dec.reset_collisions();
    }
    fn summarize(&mut self, summary: &mut Map<String, Value>) {
        summary.insert("ranks".into(), json!(self.comm.size()));
        summary.insert("imbalance".into(), json!(self.dec.imbalance));
        summary.insert("rebalances".into(), json!(self.dec.rebalances));
    }
}
