//! `grains cg RUN_DIR`: a run's coarse-grained fields computed again from
//! its saved frames and contacts with another kernel, width or grid
//! (docs/fields.md).

use clap::Args;
use grains::measure::fields::replay::{recompute, Recompute};
use std::path::PathBuf;

#[derive(Args)]
pub struct CgArgs {
    /// The run's output directory (fields.json, frames.pvd, contacts.pvd).
    run_dir: PathBuf,
    /// The kernel: gauss (gaussian) or lucy [default: the run's].
    #[arg(long)]
    kernel: Option<String>,
    /// The kernel's width w in units of d0 [default: the run's].
    #[arg(long)]
    width: Option<f64>,
    /// The grid: AXIS:CELLS,… (e.g. y:60 or x:20,z:40), or box [default: the run's].
    #[arg(long)]
    grid: Option<String>,
    /// Where to write fields/, fields.pvd and fields.json [default: RUN_DIR/cg].
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(args: CgArgs) -> grains::Result<()> {
    let out = args.out.unwrap_or_else(|| args.run_dir.join("cg"));
    let changes = Recompute {
        kernel: args.kernel,
        width: args.width,
        grid: args.grid,
    };
    let done = recompute(&args.run_dir, &out, &changes)?;
    println!(
        "grains: wrote {} ({} windows from {} frames{})",
        out.display(),
        done.windows,
        done.samples,
        match done.off_schedule {
            0 => String::new(),
            k => format!("; {k} not at the run's sample steps, so the windows are not the run's"),
        }
    );
    Ok(())
}
