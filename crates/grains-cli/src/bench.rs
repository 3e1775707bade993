//! `grains bench`: time a reference workload and report ns per particle-step.
//!
//! `chute` and `vib2d` are the LAMMPS workloads of `bench/` (scenario files
//! `scenarios/bench-*.toml` reading the same data files); `chute-clumps`
//! is the chute's flowing grains as rigid three-sphere rods
//! ([`crate::bench_clumps`], timed per sub-sphere-step); `chute-psd` is
//! the chute's box with a 5:1 lognormal mix placed at random; `bed3d` is a
//! synthetic dense bed of N spheres built without a data file, its set-up
//! reported pass by pass on stderr. Only the stepping loop is timed, as
//! LAMMPS's "Loop time" is; the set-up is timed apart (`setup_seconds`).
//!
//! `gas2d` and `gas3d` time the DSMC engine on the elastic hard-sphere gas
//! that mirrors SPARTA's `bench/sparta/in.hs3d` (10 particles per cell, cell
//! = λ/2, ω τ = 0.30, Maxwellian start; see `grains::dsmc::workload`): 30
//! untimed warm-up steps (`--warmup`), then the timed ones. The set-up (placement in
//! cell order) is timed apart and reported line by line on stderr.

use crate::bench_gpu::GpuArgs;
use clap::Args;
use grains::comm::Comm;
use grains::integrate::Integrator;
use grains::md::decomp::{Balance, DecomposedMd};
use grains::md::phase_times::PhaseTimes;
use grains::md::Md;
use grains::scenario::{build_md, build_md_reporting, load_file, load_str, Loaded};
use grains::{Dim, Error, Result, D2, D3};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct BenchArgs {
    /// chute, chute-hertz, chute-clumps, chute-psd, vib2d, bed3d, gas2d or gas3d.
    pub(crate) workload: String,
    /// Steps to time [default: chute, chute-hertz and chute-clumps 1000, vib2d 10000, bed3d 1000, gas 300].
    #[arg(long)]
    pub(crate) steps: Option<u64>,
    /// Untimed steps of the gas workloads before the timed ones [default:
    /// 30, as SPARTA's input].
    #[arg(long)]
    warmup: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// gear5 or verlet [default: verlet, as LAMMPS's nve/sphere].
    #[arg(long, value_parser = ["gear5", "verlet"])]
    integrator: Option<String>,
    /// Grains in the synthetic workloads [default: bed3d 20000, gas 1000000].
    #[arg(long)]
    pub(crate) particles: Option<usize>,
    /// One JSON line instead of text.
    #[arg(long)]
    pub(crate) json: bool,
    /// Scenario overrides KEY=VALUE of the MD workloads (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) sets: Vec<String>,
    #[command(flatten)]
    pub(crate) gpu: GpuArgs,
}

/// Finds `scenarios/<file>` from the working directory or the source tree.
fn scenario_path(file: &str) -> Result<PathBuf> {
    crate::repo_file::repo_file("scenarios", file, "")
}

/// A dense 3D bed: spheres of diameter 1 (±10%) on a cubic lattice of pitch
/// 1.0 in a box periodic in x and y, on a floor, under gravity, with the
/// benchmarks' LAMMPS contact law.
fn bed3d_scenario(n: usize) -> String {
    let side = ((n as f64 / 10.0).sqrt().ceil() as usize).max(4);
    let layers = n.div_ceil(side * side);
    let height = layers as f64 * 1.2 + 10.0;
    format!(
        r#"name = "bench-bed3d"
dimension = "3d"
gravity = [0.0, 0.0, -1.0]
[domain]
lo = [0.0, 0.0, 0.0]
hi = [{side}.0, {side}.0, {height}]
periodic = [true, true, false]
[particles]
placement = "lattice"
count = {n}
d0 = 1.0
width = 0.2
density = 1.9098593
spacing = 1.0
region = {{ lo = [0.0, 0.0, 0.0], hi = [{side}.0, {side}.0, {height}] }}
[contact]
preset = "lammps-hooke-history"
[[walls]]
name = "floor"
shape = {{ type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[run]
integrator = "verlet"
dt = 1.0e-4
duration = 1.0
skin = 0.1
[output]
frames = false
picture = false
"#,
        side = (side as f64 * 1.1).ceil() as usize,
    )
}

fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|k| k.parse::<u64>().ok())
            })
        })
        .map_or(0, |kb| kb * 1024)
}

/// Wall and CPU seconds of `steps` steps, and the time of each phase.
/// What the report says of a timed engine: its mobile grains, integrator,
/// steps on one thread, the setup's seconds and [`time_steps`]'s figures.
type Timed = (usize, Integrator, u64, f64, (f64, f64, PhaseTimes));

/// A built engine's [`time_steps`] with the rest of [`Timed`]; the setup
/// counted from `setup_start`.
fn timed_run<D: Dim>(md: &mut Md<D>, steps: u64, setup_start: Instant) -> Result<Timed> {
    let setup = setup_start.elapsed().as_secs_f64();
    let w = time_steps(md, steps)?;
    let narrow = md.governor.steps_wide_narrow().1;
    Ok((
        md.particles.n_mobile(),
        md.settings.integrator,
        narrow,
        setup,
        w,
    ))
}

fn time_steps<D: Dim>(md: &mut Md<D>, steps: u64) -> Result<(f64, f64, PhaseTimes)> {
    md.timing.reset();
    let (start, cpu0) = (Instant::now(), cpu_seconds());
    md.run(steps)?;
    let (wall, cpu) = (start.elapsed().as_secs_f64(), cpu_seconds() - cpu0);
    Ok((wall, cpu, md.timing))
}

/// The phases' nanoseconds per particle-step, in the words of the text
/// output.
fn phase_line(phases: &serde_json::Value) -> String {
    let names = [
        ("contacts", "contacts"),
        ("fields", "walls and gravity"),
        ("integrate", "integration"),
        ("neighbors", "neighbour lists"),
        ("other", "other"),
    ];
    let parts: Vec<String> = names
        .iter()
        .map(|(key, words)| format!("{words} {:.1}", phases[key].as_f64().unwrap_or(0.0)))
        .collect();
    format!("  ns per particle-step: {}", parts.join(", "))
}

/// The scenario of an MD workload and its default step count.
fn md_workload(args: &BenchArgs) -> Result<(Loaded, u64)> {
    let mut sets = Vec::new();
    if let Some(i) = &args.integrator {
        sets.push(format!("run.integrator={i}"));
    }
    sets.extend(args.sets.iter().cloned());
    let (loaded, default_steps) = match args.workload.as_str() {
        "chute" | "chute-clumps" => (load_file(&scenario_path("bench-chute.toml")?, &sets)?, 1000),
        "chute-hertz" => (
            load_file(&scenario_path("bench-chute-hertz.toml")?, &sets)?,
            1000,
        ),
        "chute-psd" => (
            load_file(&scenario_path("bench-chute-psd.toml")?, &sets)?,
            1000,
        ),
        "vib2d" => (
            load_file(&scenario_path("bench-vib2d.toml")?, &sets)?,
            10_000,
        ),
        "bed3d" => {
            let n = args.particles.unwrap_or(20_000);
            if n == 0 {
                return Err(Error::input("--particles must be at least 1"));
            }
            (
                load_str(&bed3d_scenario(n), "bed3d", PathBuf::from("."), &sets)?,
                1000,
            )
        }
        other => {
            return Err(Error::input(format!(
            "unknown workload `{other}`: choose chute, chute-hertz, chute-clumps, chute-psd, vib2d, bed3d, gas2d or gas3d"
        )))
        }
    };
    Ok((loaded, default_steps))
}

pub fn run(args: BenchArgs) -> Result<()> {
    crate::set_threads(args.threads)?;
    if let Some(dim) = args.workload.strip_prefix("gas") {
        if !args.sets.is_empty() {
            return Err(Error::input(
                "--set applies to the MD workloads only (not gas2d, gas3d)",
            ));
        }
        return match dim {
            "2d" => gas::<grains::D2>(&args),
            "3d" => gas::<grains::D3>(&args),
            _ => Err(Error::input(format!(
                "unknown workload `{}`: choose chute, chute-hertz, chute-clumps, chute-psd, vib2d, bed3d, gas2d or gas3d",
                args.workload
            ))),
        };
    }
    if args.warmup.is_some() {
        return Err(Error::input(
            "--warmup applies to the gas workloads only (gas2d, gas3d)",
        ));
    }
    let (loaded, default_steps) = md_workload(&args)?;
    let steps = args.steps.unwrap_or(default_steps);
    let clumps = args.workload == "chute-clumps";
    match args.gpu.device.as_deref() {
        Some("gpu") | Some("mirror") if clumps => {
            return Err(Error::input(
                "--device: chute-clumps runs on the CPU engine only (the GPU engine has no rigid clumps)",
            ))
        }
        Some("gpu") | Some("mirror") => {
            return crate::bench_gpu::run(&args.workload, args.json, &args.gpu, &loaded, steps)
        }
        _ if args.gpu.verify
            || args.gpu.fma
            || args.gpu.graph
            || args.gpu.sync_each_step
            || args.gpu.cpu_order
            || args.gpu.sort_every.is_some() =>
        {
            return Err(Error::input(
                "--verify, --fma, --graph, --sync-each-step, --cpu-order and --sort-every go with \
                 --device gpu (the last two also with --device mirror)",
            ))
        }
        _ => {}
    }
    // A large bed takes seconds to build: one line per pass (bed3d only,
    // whose size is the user's).
    let verbose = args.workload == "bed3d";
    let mut report = |line: &str| {
        if verbose {
            eprintln!("grains: {line}")
        }
    };
    let setup_start = Instant::now();
    let mut bodies = None;
    let (particles, integrator, narrow, setup, (wall, cpu, timing)) = if clumps {
        let (mut md, count) = crate::bench_clumps::build(&loaded)?;
        let timed = timed_run(&mut md, steps, setup_start)?;
        bodies = Some(crate::bench_clumps::Report::of(&md, count));
        timed
    } else if loaded.scenario.dimension.axes() == 2 {
        let (mut md, _) = build_md_reporting::<D2>(&loaded, &mut report)?;
        timed_run(&mut md, steps, setup_start)?
    } else {
        let (mut md, _) = build_md_reporting::<D3>(&loaded, &mut report)?;
        timed_run(&mut md, steps, setup_start)?
    };
    let threads = rayon::current_num_threads();
    let dims = loaded.scenario.dimension.axes();
    let updates = steps as f64 * particles.max(1) as f64;
    let ns = 1e9 * wall / updates;
    let phases = timing.to_json(wall, 1e9 / updates);
    let rss = peak_rss_bytes();
    if args.json {
        let mut out = json!({
            "workload": args.workload, "particles": particles, "steps": steps, "threads": threads,
            "integrator": integrator.name(), "wall_seconds": wall, "ns_per_particle_step": ns,
            "cpu_seconds": cpu, "peak_rss_bytes": rss, "phase_ns_per_particle_step": phases,
            "estimate_bytes_per_particle": grains::scenario::memory::md_bytes_per_grain(dims, integrator),
            "steps_on_one_thread": narrow, "setup_seconds": setup,
        });
        if let (Some(b), Some(map)) = (&bodies, out.as_object_mut()) {
            b.write(map);
        }
        println!("{out}");
    } else {
        println!(
            "{}: {particles} mobile particles, {steps} steps, {threads} thread(s) ({narrow} steps on one), {}: {wall:.3} s, {ns:.1} ns per particle-step, peak RSS {:.1} MiB, set-up {setup:.2} s",
            args.workload,
            integrator.name(),
            rss as f64 / 1048576.0
        );
        println!("{}", phase_line(&phases));
        if let Some(b) = &bodies {
            println!("{}", b.line());
        }
    }
    Ok(())
}

/// `grains bench` as one rank of `mpirun`: an MD workload decomposed over
/// the ranks ([`grains::md::decomp`]). Every rank builds the whole
/// workload and keeps its box; the timed loop runs between two barriers,
/// so the time is the slowest rank's. Rank 0 reports.
pub fn run_ranks(args: BenchArgs, comm: &dyn Comm) -> Result<()> {
    crate::set_threads(args.threads)?;
    if args.workload.starts_with("gas") {
        return Err(Error::input(format!(
            "`grains bench {}` runs on one process; time a distributed DSMC run with bench/mpi_scaling.sh",
            args.workload
        )));
    }
    if args.workload == "chute-clumps" {
        return Err(Error::input(
            "`grains bench chute-clumps` runs on one process (rigid clumps are refused under mpirun)",
        ));
    }
    let (loaded, default_steps) = md_workload(&args)?;
    let steps = args.steps.unwrap_or(default_steps);
    /// What the timed loop of the ranks measured.
    struct Timed {
        particles: usize,
        integrator: &'static str,
        wall: f64,
        ghosts: u64,
        builds: u64,
        work: f64,
        cpu: f64,
        balance: Balance,
    }
    fn go<D: Dim>(loaded: &Loaded, steps: u64, comm: &dyn Comm) -> Result<Timed> {
        let (md, _) = build_md::<D>(loaded)?;
        let integrator = md.settings.integrator.name();
        let particles = md.particles.n_mobile();
        let mut dec = DecomposedMd::with_spec(md, comm, &loaded.scenario.parallel)?;
        comm.barrier();
        let (start, cpu0) = (Instant::now(), cpu_seconds());
        grains::parallel::on_pool(|| dec.advance(steps))?;
        let mut cpu = [cpu_seconds() - cpu0];
        comm.barrier();
        let wall = start.elapsed().as_secs_f64();
        comm.max_f64(&mut cpu);
        let mut ghosts = [dec.n_ghosts() as u64];
        comm.sum_u64(&mut ghosts);
        // The busiest rank's work: the loop without its messages and waits.
        let mut work = [wall - dec.comm_seconds];
        comm.max_f64(&mut work);
        Ok(Timed {
            particles,
            integrator,
            wall,
            ghosts: ghosts[0],
            builds: dec.neighbor_builds(),
            work: work[0],
            cpu: cpu[0],
            balance: dec.balance.clone(),
        })
    }
    let Timed {
        particles,
        integrator,
        wall,
        ghosts,
        builds,
        work,
        cpu,
        balance,
    } = if loaded.scenario.dimension.axes() == 2 {
        go::<D2>(&loaded, steps, comm)?
    } else {
        go::<D3>(&loaded, steps, comm)?
    };
    if comm.rank() != 0 {
        return Ok(());
    }
    let (ranks, threads) = (comm.size(), rayon::current_num_threads());
    let ns = 1e9 * wall / (steps as f64 * particles.max(1) as f64);
    let rss = peak_rss_bytes();
    if args.json {
        let mut out = json!({
            "workload": args.workload, "particles": particles, "steps": steps, "threads": threads,
            "ranks": ranks, "ghosts": ghosts, "neighbor_builds": builds,
            "max_rank_work_seconds": work, "max_rank_cpu_seconds": cpu,
            "integrator": integrator, "wall_seconds": wall, "ns_per_particle_step": ns,
            "peak_rss_bytes_rank0": rss,
        });
        if let Some(map) = out.as_object_mut() {
            balance.write(map);
        }
        println!("{out}");
    } else {
        println!(
            "{}: {particles} mobile particles, {steps} steps, {ranks} ranks × {threads} thread(s), {integrator}: {wall:.3} s, {ns:.1} ns per particle-step, {ghosts} ghosts, busiest rank's work {work:.3} s, imbalance {:.3} (max {:.3}, {} rebalances), peak RSS of rank 0 {:.1} MiB",
            args.workload,
            balance.last,
            balance.max,
            balance.rebalances,
            rss as f64 / 1048576.0
        );
    }
    Ok(())
}

/// The DSMC hard-sphere gas workloads.
fn gas<D: grains::dsmc::GasDim>(args: &BenchArgs) -> Result<()> {
    let n = args.particles.unwrap_or(1_000_000);
    if n == 0 {
        return Err(Error::input("--particles must be at least 1"));
    }
    let steps = args.steps.unwrap_or(300);
    let bytes = grains::scenario::memory::dsmc_bytes_per_particle(D::D);
    grains::scenario::memory::check("--particles", n, bytes)?;
    // The set-up of a large gas takes seconds: one line per pass.
    let setup_start = Instant::now();
    let mut gas = grains::dsmc::workload::hard_sphere_gas_reporting::<D>(n, 12345, &mut |line| {
        eprintln!("grains: {line}")
    });
    let setup = setup_start.elapsed().as_secs_f64();
    gas.run(args.warmup.unwrap_or(30));
    let before = gas.totals;
    let cpu0 = cpu_seconds();
    let start = Instant::now();
    gas.run(steps);
    let wall = start.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    let particles = gas.store.len();
    let updates = (steps as f64 * particles as f64).max(1.0);
    let ns = 1e9 * wall / updates;
    let collisions = (gas.totals.collisions - before.collisions) as f64 / updates;
    let candidates = (gas.totals.candidates - before.candidates) as f64 / updates;
    let threads = rayon::current_num_threads();
    let rss = peak_rss_bytes();
    if args.json {
        println!(
            "{}",
            json!({
                "workload": args.workload, "particles": particles, "steps": steps, "threads": threads,
                "wall_seconds": wall, "ns_per_particle_step": ns, "peak_rss_bytes": rss,
                "collisions_per_particle_step": collisions,
                "candidates_per_particle_step": candidates,
                "cells": gas.grid.cells(),
                "cpu_seconds": cpu, "cpu_ns_per_particle_step": 1e9 * cpu / updates,
                "setup_seconds": setup, "estimate_bytes_per_particle": bytes,
                "bytes_per_particle": rss as f64 / particles as f64,
            })
        );
    } else {
        println!(
            "{}: {particles} particles, {} cells, {steps} steps, {threads} thread(s): {wall:.3} s, {ns:.1} ns per particle-step (CPU {:.1} ns), {collisions:.4} collisions and {candidates:.4} candidates per particle-step, peak RSS {:.1} MiB ({:.1} B per particle), set-up {setup:.2} s",
            args.workload,
            gas.grid.cells(),
            1e9 * cpu / updates,
            rss as f64 / 1048576.0,
            rss as f64 / particles as f64
        );
    }
    Ok(())
}

/// User plus system CPU time of this process (s), from /proc/self/stat; 0
/// where unavailable. On a shared machine it shows what wall time hides.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            let ut: f64 = f.get(11)?.parse().ok()?;
            let st: f64 = f.get(12)?.parse().ok()?;
            Some((ut + st) / 100.0)
        })
        .unwrap_or(0.0)
}
