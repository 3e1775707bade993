//! The `grains` command line: a thin layer over the library's scenario
//! runner. Exit codes: 0 success, 2 bad input, 3 simulation unstable,
//! 1 anything else.

mod bench;
mod progress;
mod sweep;

use clap::{Parser, Subcommand};
use grains::runner::{self, RunOptions};
use grains::scenario::{self, Loaded};
use grains::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
    Run {
        /// Scenario file (TOML). Omit for the built-in default.
        scenario: Option<PathBuf>,
        /// Output directory [default: runs/<scenario name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scenario key, e.g. --set contact.mu=0.3 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Run this many steps instead of the scenario's length (no relaxation).
        #[arg(long)]
        steps: Option<u64>,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Print nothing but errors.
        #[arg(long)]
        quiet: bool,
    },
    /// Validate a scenario and print the resolved parameters, without running.
    Check {
        scenario: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
    /// Time a reference workload: chute, vib2d or bed3d.
    Bench(bench::BenchArgs),
    /// Run a grid of scenario variants; collect summaries in sweep.csv and plot one.
    Sweep(sweep::SweepArgs),
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

fn execute(cli: Cli) -> grains::Result<()> {
    match cli.command {
        Command::Run {
            scenario,
            out,
            sets,
            steps,
            threads,
            quiet,
        } => {
            let loaded = load(scenario.as_deref(), &sets)?;
            let from_file = Some(loaded.scenario.run.threads).filter(|&n| n > 0);
            set_threads(threads.or(from_file))?;
            let out_dir =
                out.unwrap_or_else(|| Path::new("runs").join(safe_dir_name(&loaded.scenario.name)));
            if steps == Some(0) {
                return Err(Error::input("--steps must be at least 1"));
            }
            let opts = RunOptions {
                out_dir: out_dir.clone(),
                steps,
            };
            let mut progress = progress::for_terminal(quiet);
            if !quiet {
                eprintln!("grains: running {} -> {}", loaded.origin, out_dir.display());
            }
            let summary = runner::run(&loaded, &opts, progress.as_mut())?;
            if !quiet {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&summary).unwrap_or_default()
                );
                eprintln!("grains: wrote {}", out_dir.display());
            }
            Ok(())
        }
        Command::Check { scenario, sets } => {
            let loaded = scenario::load_file(&scenario, &sets)?;
            let resolved = runner::check(&loaded)?;
            println!(
                "{}",
                serde_json::to_string_pretty(&resolved).unwrap_or_default()
            );
            Ok(())
        }
        Command::Bench(args) => bench::run(args),
        Command::Sweep(args) => sweep::run(args),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match execute(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("grains: error: {e}");
            ExitCode::from(match e {
                Error::Input(_) => 2,
                // A missing or unreadable input file, or an output directory
                // that cannot be written, is bad input too.
                Error::Io { ref source, .. }
                    if matches!(
                        source.kind(),
                        std::io::ErrorKind::NotFound
                            | std::io::ErrorKind::PermissionDenied
                            | std::io::ErrorKind::InvalidData
                            | std::io::ErrorKind::IsADirectory
                            | std::io::ErrorKind::NotADirectory
                    ) =>
                {
                    2
                }
                Error::Unstable(_) => 3,
                Error::Io { .. } => 1,
            })
        }
    }
}
