//! The `grains` command line: a thin layer over the library's scenario
//! runner. Exit codes: 0 success, 2 bad input, 3 simulation unstable,
//! 1 anything else.

mod bench;
mod bench_clumps;
mod bench_gpu;
mod cg;
mod launch;
mod movie;
mod progress;
mod repo_file;
mod sweep;
mod view;

use clap::{Args, Parser, Subcommand};
use grains::comm::Comm;
use grains::runner::checkpointing::{self, Every};
use grains::runner::{self, RunOptions};
use grains::scenario::{self, Loaded};
use grains::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "grains",
    version,
    about = "Granular dynamics: soft-sphere MD (DEM) in 2D and 3D"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario (without one: the seed's convection experiment).
    Run(RunArgs),
    /// Continue an interrupted run from its newest valid checkpoint,
    /// appending to its outputs.
    Resume(ResumeArgs),
    /// Validate a scenario and print the resolved parameters, without running.
    Check {
        scenario: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
    /// Time a reference workload: chute, chute-hertz, chute-psd, vib2d, bed3d, gas2d or gas3d.
    Bench(bench::BenchArgs),
    /// Run a grid of scenario variants; collect summaries in sweep.csv and plot one.
    Sweep(sweep::SweepArgs),
    /// Draw a run's frames into movie.gif (and movie.mp4 with ffmpeg).
    Movie(movie::MovieArgs),
    /// Play a run in the browser: serves a page on 127.0.0.1 (prints its address).
    View(view::ViewArgs),
    /// Recompute a run's fields from its frames and contacts (another kernel, width or grid).
    Cg(cg::CgArgs),
}

#[derive(Args)]
struct RunArgs {
    /// Scenario file (TOML). Omit for the built-in default.
    scenario: Option<PathBuf>,
    /// Output directory [default: runs/<scenario name>, or runs/<scenario
    /// name>-2, -3, … when that one holds an earlier run].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the run in the --out directory: its frames, tables, pictures
    /// and checkpoints are removed first (without it, a directory that holds
    /// another run is refused).
    #[arg(long)]
    overwrite: bool,
    /// Override a scenario key, e.g. --set contact.mu=0.3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Run this many steps instead of the scenario's length (no relaxation).
    #[arg(long)]
    steps: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Write a checkpoint every T simulated seconds (e.g. 0.01) or N
    /// steps (e.g. 500steps); the newest two are kept.
    #[arg(long, value_name = "T")]
    checkpoint_every: Option<String>,
    /// Start from this checkpoint's state (a checkpoint file, or a run
    /// directory's newest valid one) instead of step 0: the scenario may
    /// change the law, gravity, walls' motions, the run and its outputs,
    /// not the grains, box or walls' shapes.
    #[arg(long, value_name = "CHECKPOINT")]
    from: Option<PathBuf>,
    /// With --from: use input files (particles.file, meshes) that changed
    /// since the checkpoint's run read them.
    #[arg(long)]
    allow_changed_inputs: bool,
    /// Print nothing but errors.
    #[arg(long)]
    quiet: bool,
}

#[derive(Args)]
struct ResumeArgs {
    /// The run's output directory (or one checkpoint file in it).
    run_dir: PathBuf,
    /// Run this many more steps instead of to the scenario's end (with
    /// --set or --out: this many measured steps of the new run).
    #[arg(long)]
    steps: Option<u64>,
    /// Continue under a changed scenario (repeatable), e.g. --set
    /// contact.mu=0.1: a restart, which writes a new run into --out.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Write the continued run into this new directory (a restart) instead
    /// of appending to the checkpoint's own run.
    #[arg(long)]
    out: Option<PathBuf>,
    /// With --out: replace the run that directory holds.
    #[arg(long)]
    overwrite: bool,
    /// Use input files (particles.file, meshes) that changed since the run
    /// read them; without it such a file is refused by name.
    #[arg(long)]
    allow_changed_inputs: bool,
    /// Change the checkpoint interval (default: the run's).
    #[arg(long, value_name = "T")]
    checkpoint_every: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long)]
    quiet: bool,
}

fn load(path: Option<&Path>, sets: &[String]) -> grains::Result<Loaded> {
    match path {
        Some(p) => scenario::load_file(p, sets),
        None => scenario::load_default(sets),
    }
}

/// The scenario name as one harmless path component (no separators, no
/// leading dots), so the default output directory stays under `runs/`.
fn safe_dir_name(name: &str) -> String {
    let cleaned: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let cleaned = cleaned.trim_start_matches('.');
    if cleaned.is_empty() {
        "run".to_string()
    } else {
        cleaned.to_string()
    }
}

pub(crate) fn set_threads(threads: Option<usize>) -> grains::Result<()> {
    if let Some(n) = threads {
        if n == 0 {
            return Err(Error::input("--threads must be at least 1"));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::input(format!("--threads {n}: {e}")))?;
    }
    Ok(())
}

/// Asks the run to stop at its next check (at most 256 steps on) on SIGINT or
/// SIGTERM; a second signal ends the process at once.
fn stop_flag() -> grains::Result<Arc<AtomicBool>> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(sig, 130, Arc::clone(&flag))
            .and_then(|_| signal_hook::flag::register(sig, Arc::clone(&flag)))
            .map_err(|e| Error::input(format!("cannot install the signal handler: {e}")))?;
    }
    Ok(flag)
}

/// Prints a run's summary, or the interruption message; true when the run
/// was interrupted.
fn report(summary: &serde_json::Value, quiet: bool) -> bool {
    if summary.get("interrupted").and_then(|v| v.as_bool()) == Some(true) {
        let msg = summary["message"].as_str().unwrap_or("interrupted");
        eprintln!("grains: {msg}");
        return true;
    }
    if !quiet {
        println!(
            "{}",
            serde_json::to_string_pretty(summary).unwrap_or_default()
        );
    }
    false
}

fn execute(cli: Cli, ranks: &launch::Ranks) -> grains::Result<ExitCode> {
    if let Some(comm) = ranks.several() {
        return match cli.command {
            Command::Run(args) => run_distributed(&args, comm),
            Command::Resume(args) => resume_distributed(&args, comm),
            Command::Bench(args) => bench::run_ranks(args, comm).map(|_| ExitCode::SUCCESS),
            _ => Err(Error::input(format!(
                "only `grains run`, `grains resume` and `grains bench` run on several MPI ranks ({} here); start other commands without mpirun",
                comm.size()
            ))),
        };
    }
    match cli.command {
        Command::Resume(args) => {
            let (found, mut opts) = resume_set_up(&args, None)?;
            opts.stop = Some(stop_flag()?);
            let mut progress = progress::for_terminal(args.quiet);
            let summary = checkpointing::resume(found, args.steps, opts, progress.as_mut())?;
            Ok(finish(&summary, args.quiet, written(&args)))
        }
        Command::Run(args) => {
            let (loaded, mut opts) = run_set_up(&args, None)?;
            opts.stop = Some(stop_flag()?);
            let mut progress = progress::for_terminal(args.quiet);
            let summary = match from_checkpoint(&args, &loaded, None)? {
                Some(found) => {
                    checkpointing::resume(found, args.steps, opts.clone(), progress.as_mut())?
                }
                None => runner::run(&loaded, &opts, progress.as_mut())?,
            };
            Ok(finish(&summary, args.quiet, &opts.out_dir))
        }
        Command::Check { scenario, sets } => {
            let loaded = scenario::load_file(&scenario, &sets)?;
            let resolved = runner::check(&loaded)?;
            println!(
                "{}",
                serde_json::to_string_pretty(&resolved).unwrap_or_default()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Bench(args) => bench::run(args).map(|_| ExitCode::SUCCESS),
        Command::Sweep(args) => sweep::run(args).map(|_| ExitCode::SUCCESS),
        Command::Movie(args) => movie::run(args).map(|_| ExitCode::SUCCESS),
        Command::View(args) => view::run(args).map(|_| ExitCode::SUCCESS),
        Command::Cg(args) => cg::run(args).map(|_| ExitCode::SUCCESS),
    }
}

/// Reports a run that returned `summary` (see [`report`]) and says where
/// it wrote unless quiet: exit code 130 when it was interrupted.
fn finish(summary: &serde_json::Value, quiet: bool, dir: &Path) -> ExitCode {
    if report(summary, quiet) {
        return ExitCode::from(130);
    }
    if !quiet {
        eprintln!("grains: wrote {}", dir.display());
    }
    ExitCode::SUCCESS
}

/// The checks `grains run` and `grains resume` share: at least one step
/// when `--steps` is given; the `--checkpoint-every` interval parsed.
fn checked_steps(steps: Option<u64>, every: Option<&str>) -> grains::Result<Option<Every>> {
    if steps == Some(0) {
        return Err(Error::input("--steps must be at least 1"));
    }
    every.map(Every::parse).transpose()
}

/// Whether this process says what it runs: unless quiet, a plain process
/// or rank 0 of `mpirun`.
fn talks(quiet: bool, comm: Option<&dyn Comm>) -> bool {
    !quiet && comm.is_none_or(|c| c.rank() == 0)
}

/// " on N ranks" under `mpirun`, nothing for a plain process.
fn on_ranks_note(comm: Option<&dyn Comm>) -> String {
    comm.map(|c| format!(" on {} ranks", c.size()))
        .unwrap_or_default()
}

/// What `grains run` runs, alike in a plain process (`comm` None) and on
/// each rank of `mpirun`: the scenario loaded with the overrides, the
/// thread pool sized (`--threads`, else the scenario's `run.threads`), and
/// the run options (output directory, steps, checkpoint interval; the
/// caller adds the stop flag where it has one). Rank 0 says what runs
/// where unless quiet.
fn run_set_up(args: &RunArgs, comm: Option<&dyn Comm>) -> grains::Result<(Loaded, RunOptions)> {
    if args.allow_changed_inputs && args.from.is_none() {
        return Err(Error::input(
            "--allow-changed-inputs acts on the files of a checkpoint: give --from (or use grains resume)",
        ));
    }
    let loaded = load(args.scenario.as_deref(), &args.sets)?;
    let from_file = Some(loaded.scenario.run.threads).filter(|&n| n > 0);
    set_threads(args.threads.or(from_file))?;
    // An unnamed output directory never holds an earlier run: the first
    // free one of runs/NAME, runs/NAME-2, … (rank 0 decides under mpirun).
    let out_dir = match &args.out {
        Some(dir) => dir.clone(),
        None => {
            let base = Path::new("runs").join(safe_dir_name(&loaded.scenario.name));
            match comm {
                Some(c) => rank0_path(c, &grains::run_dir::fresh(&base)),
                None => grains::run_dir::fresh(&base),
            }
        }
    };
    let every = checked_steps(args.steps, args.checkpoint_every.as_deref())?;
    if talks(args.quiet, comm) {
        eprintln!(
            "grains: running {}{} -> {}",
            loaded.origin,
            on_ranks_note(comm),
            out_dir.display()
        );
    }
    let opts = RunOptions {
        out_dir,
        steps: args.steps,
        checkpoint_every: every,
        overwrite: args.overwrite,
        ..RunOptions::default()
    };
    Ok((loaded, opts))
}

/// Rank 0's `path` on every rank.
fn rank0_path(comm: &dyn Comm, path: &Path) -> PathBuf {
    let mine = path.to_string_lossy().into_owned().into_bytes();
    let all = comm.all_gather_bytes(&mine);
    PathBuf::from(String::from_utf8_lossy(&all[0]).into_owned())
}

/// What `grains resume` starts from, alike in a plain process (`comm`
/// None) and on each rank of `mpirun`: the arguments checked, the newest
/// valid checkpoint found, the thread pool sized, and the run options (the
/// checkpoint interval; the caller adds the stop flag where it has one).
/// Says which checkpoints were skipped and which one resumes: a plain
/// process names the skipped ones even when quiet, under `mpirun` only a
/// talking rank 0 speaks.
fn resume_set_up(
    args: &ResumeArgs,
    comm: Option<&dyn Comm>,
) -> grains::Result<(checkpointing::Found, RunOptions)> {
    let every = checked_steps(args.steps, args.checkpoint_every.as_deref())?;
    if !args.sets.is_empty() && args.out.is_none() {
        return Err(Error::input(
            "--set changes the scenario: give --out for the changed run's files \
             (the checkpoint's own run stays as it is)",
        ));
    }
    if args.overwrite && args.out.is_none() {
        return Err(Error::input(
            "--overwrite replaces the run in --out; a plain resume appends to its own run",
        ));
    }
    let (found, skipped) = checkpointing::find(&args.run_dir)?;
    let talks = talks(args.quiet, comm);
    if talks || comm.is_none() {
        for s in &skipped {
            eprintln!("grains: skipped {s}");
        }
    }
    let found = checked_inputs(found, args.allow_changed_inputs, talks)?;
    let found = match &args.out {
        Some(_) => found.restart_with_sets(&args.sets)?,
        None => found,
    };
    set_threads(args.threads)?;
    if talks {
        eprintln!(
            "grains: resuming from {} (step {}){}{}",
            found.path.display(),
            found.step,
            on_ranks_note(comm),
            restart_note(&found, args.out.as_deref())
        );
    }
    let opts = RunOptions {
        checkpoint_every: every,
        out_dir: args.out.clone().unwrap_or_default(),
        overwrite: args.overwrite,
        ..RunOptions::default()
    };
    Ok((found, opts))
}

/// The checkpoint after the check of the files its scenario read (refused
/// by name when one changed, unless `allow_changed`, which says so).
fn checked_inputs(
    found: checkpointing::Found,
    allow_changed: bool,
    talks: bool,
) -> grains::Result<checkpointing::Found> {
    for note in found.check_inputs(allow_changed)? {
        if talks {
            eprintln!("grains: warning: {note} (--allow-changed-inputs)");
        }
    }
    Ok(found)
}

/// " as a new run in DIR, changing KEYS" for a restart, nothing otherwise.
fn restart_note(found: &checkpointing::Found, out: Option<&Path>) -> String {
    let Some(keys) = found.changed_keys() else {
        return String::new();
    };
    let mut note = String::new();
    if let Some(dir) = out {
        note.push_str(&format!(" as a new run in {}", dir.display()));
    }
    if !keys.is_empty() {
        note.push_str(&format!(", changing {}", keys.join(", ")));
    }
    note
}

/// `grains run --from CHECKPOINT`: that checkpoint's state under the
/// scenario `loaded` (checked against the checkpoint's), or None without
/// --from.
fn from_checkpoint(
    args: &RunArgs,
    loaded: &Loaded,
    comm: Option<&dyn Comm>,
) -> grains::Result<Option<checkpointing::Found>> {
    let Some(from) = &args.from else {
        return Ok(None);
    };
    let talks = talks(args.quiet, comm);
    let (found, skipped) = checkpointing::find(from)?;
    if talks {
        for s in &skipped {
            eprintln!("grains: skipped {s}");
        }
    }
    let found = checked_inputs(found, args.allow_changed_inputs, talks)?;
    let found = found.restart_with(loaded.clone(), &loaded.origin)?;
    if talks {
        eprintln!(
            "grains: starting from {} (step {}){}",
            found.path.display(),
            found.step,
            restart_note(&found, None)
        );
    }
    Ok(Some(found))
}

/// `grains resume` as one rank of `mpirun`: every rank reads the
/// checkpoint and keeps its part; rank 0 reports and writes.
fn resume_distributed(args: &ResumeArgs, comm: &dyn Comm) -> grains::Result<ExitCode> {
    let (found, opts) = resume_set_up(args, Some(comm))?;
    on_ranks(comm, args.quiet, written(args), |progress| {
        runner::distributed::resume(found, args.steps, opts, progress, comm)
    })
}

/// Runs `work` (a run or a resume as one rank of mpirun) on rayon's pool;
/// rank 0 draws the progress and reports the summary.
fn on_ranks(
    comm: &dyn Comm,
    quiet: bool,
    dir: &Path,
    work: impl FnOnce(&mut dyn runner::Progress) -> grains::Result<serde_json::Value> + Send,
) -> grains::Result<ExitCode> {
    let root = comm.rank() == 0;
    let mut progress = progress::for_terminal(quiet || !root);
    let summary = grains::parallel::on_pool(|| work(progress.as_mut()))?;
    if !root {
        return Ok(ExitCode::SUCCESS);
    }
    Ok(finish(&summary, quiet, dir))
}

/// The folder a resume writes into: its `--out` (a restart or a branch),
/// else the run it continues.
fn written(args: &ResumeArgs) -> &Path {
    args.out.as_deref().unwrap_or(&args.run_dir)
}

/// `grains run` as one rank of `mpirun`: rank 0 reports and writes.
fn run_distributed(args: &RunArgs, comm: &dyn Comm) -> grains::Result<ExitCode> {
    let (loaded, opts) = run_set_up(args, Some(comm))?;
    if let Some(found) = from_checkpoint(args, &loaded, Some(comm))? {
        let out = opts.out_dir.clone();
        return on_ranks(comm, args.quiet, &out, |progress| {
            runner::distributed::resume(found, args.steps, opts, progress, comm)
        });
    }
    on_ranks(comm, args.quiet, &opts.out_dir, |progress| {
        runner::distributed::run(&loaded, &opts, progress, comm)
    })
}

fn main() -> ExitCode {
    restore_sigpipe();
    let cli = Cli::parse();
    let ranks = launch::Ranks::detect();
    match execute(cli, &ranks) {
        Ok(code) => code,
        Err(e) => {
            // Every rank meets bad input alike: one message is enough.
            if !matches!(e, Error::Input(_)) || ranks.reports_input_errors() {
                eprintln!("grains: error: {e}");
            }
            let code = exit_code(&e);
            // Other errors (a file rank 0 cannot write) leave the other
            // ranks waiting: end them all.
            if !matches!(e, Error::Input(_)) {
                ranks.abort(code);
            }
            ExitCode::from(code)
        }
    }
}

/// Lets a closed pipe end the process quietly, as it ends `cat` or `grep`
/// (`grains run | head -2`), where Rust's runtime would make every later
/// print panic.
fn restore_sigpipe() {
    // SAFETY: resetting one signal to its default disposition at start-up,
    // before any thread exists, races with nothing.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The exit code of an error.
fn exit_code(e: &Error) -> u8 {
    match e {
        Error::Input(_) => 2,
        // A missing or unreadable input file, or an output directory
        // that cannot be written, is bad input too.
        Error::Io { source, .. }
            if matches!(
                source.kind(),
                std::io::ErrorKind::NotFound
                    | std::io::ErrorKind::PermissionDenied
                    | std::io::ErrorKind::InvalidData
                    | std::io::ErrorKind::AlreadyExists
                    | std::io::ErrorKind::IsADirectory
                    | std::io::ErrorKind::NotADirectory
            ) =>
        {
            2
        }
        Error::Unstable(_) => 3,
        Error::Io { .. } => 1,
    }
}
