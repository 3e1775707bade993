//! `grains bench chute|bed3d --device gpu|mirror`: the GPU pipeline timed
//! on the CUDA engine (feature `cuda`) or on its CPU mirror, in
//! particle-steps per second; `--verify` runs the mirror too and compares
//! every grain's bits (with `--fma`: a second GPU run), docs/gpu.md.

use clap::Args;
use grains::gpu::mirror::{CellOrder, Mirror};
use grains::scenario::{build_md, Loaded};
use grains::{Error, Result, D3};
use serde_json::json;
use std::time::Instant;

/// The options of `grains bench` for the GPU pipeline (flattened into
/// `crate::bench::BenchArgs`).
#[derive(Args)]
pub struct GpuArgs {
    /// cpu, gpu (the CUDA engine, feature cuda) or mirror (the GPU
    /// pipeline as CPU loops) [default: cpu]; chute and bed3d only.
    #[arg(long, value_parser = ["cpu", "gpu", "mirror"])]
    pub device: Option<String>,
    /// With --device gpu: also run the mirror and compare every grain's
    /// bits with the GPU's.
    #[arg(long)]
    pub verify: bool,
    /// With --device gpu: the kernels with fused multiply-add (not the
    /// mirror's bits; --verify then checks that two runs agree).
    #[arg(long)]
    pub fma: bool,
    /// With --device gpu: the host reads the step words after every step
    /// and launches the rebuild only when one is due, instead of gated
    /// launches with no look at the device until the end.
    #[arg(long)]
    pub sync_each_step: bool,
    /// With --device gpu: launch the steps of a stretch by sixteen as one
    /// CUDA graph (not with --sync-each-step).
    #[arg(long)]
    pub graph: bool,
    /// With --device gpu|mirror: store the grains in the CPU engine's cell
    /// order instead of Morton order (the same bits either way).
    #[arg(long)]
    pub cpu_order: bool,
    /// With --device gpu|mirror: re-sort every this many list builds
    /// instead of the engine's 20 (to exercise the re-sort in a short run).
    #[arg(long)]
    pub sort_every: Option<u32>,
}

/// Wall seconds, device memory (used, total), whether the bits matched
/// the mirror's (when checked).
type Timed = (f64, Option<(usize, usize)>, Option<bool>);

/// Times `workload` (chute or bed3d, built as `loaded`) on the device or
/// mirror `args.device` for `steps` steps; `json`: one JSON line.
pub fn run(workload: &str, json: bool, args: &GpuArgs, loaded: &Loaded, steps: u64) -> Result<()> {
    let device = args.device.as_deref().unwrap_or("cpu");
    if !matches!(workload, "chute" | "bed3d") {
        return Err(Error::input(format!(
            "--device {device}: the GPU pipeline runs chute and bed3d, not {}",
            workload
        )));
    }
    if device == "gpu" && !cfg!(feature = "cuda") {
        return Err(Error::input(grains::gpu::NO_FEATURE));
    }
    if device == "mirror" && (args.fma || args.graph || args.sync_each_step || args.verify) {
        return Err(Error::input(
            "--verify, --fma, --graph and --sync-each-step go with --device gpu",
        ));
    }
    let setup = Instant::now();
    let (md, _) = build_md::<D3>(loaded)?;
    let order = if args.cpu_order {
        CellOrder::Cpu
    } else {
        CellOrder::Morton
    };
    let mut mirror = Mirror::from_md_in(&md, order)?;
    if let Some(every) = args.sort_every {
        mirror.params.sort_every = every;
    }
    let mobile = md.particles.n_mobile();
    drop(md);
    let (wall, memory, verified) = if device == "mirror" {
        let mut m = mirror;
        let start = Instant::now();
        m.advance(steps)?;
        (start.elapsed().as_secs_f64(), None, None)
    } else {
        gpu(mirror, steps, args)?
    };
    let setup = setup.elapsed().as_secs_f64() - wall;
    let rate = steps as f64 * mobile.max(1) as f64 / wall;
    let ns = 1e9 / rate;
    if json {
        println!(
            "{}",
            json!({
                "workload": workload, "device": device, "particles": mobile,
                "steps": steps, "wall_seconds": wall, "ns_per_particle_step": ns,
                "particle_steps_per_second": rate, "setup_seconds": setup,
                "device_memory_bytes": memory.map(|m: (usize, usize)| m.0),
                "device_memory_total_bytes": memory.map(|m: (usize, usize)| m.1),
                "same_bits_as_mirror": verified.filter(|_| !args.fma),
                "same_bits_on_rerun": verified.filter(|_| args.fma),
                "fma": args.fma, "sync_each_step": args.sync_each_step, "graph": args.graph,
                "cell_order": if args.cpu_order { "cpu" } else { "morton" },
                "sort_every": args.sort_every,
            })
        );
    } else {
        let mem = memory.map_or(String::new(), |(used, total)| {
            format!(
                ", device memory {:.1} of {:.1} GiB",
                used as f64 / 1073741824.0,
                total as f64 / 1073741824.0
            )
        });
        let check = match (verified, args.fma) {
            (Some(true), false) => ", same bits as the mirror",
            (Some(false), false) => ", BITS DIFFER from the mirror",
            (Some(true), true) => ", FMA: the same bits on a second run",
            (Some(false), true) => ", FMA: BITS DIFFER on a second run",
            (None, _) => "",
        };
        println!(
            "{}: {mobile} mobile particles, {steps} steps, device {device}: {wall:.3} s, {ns:.3} ns per particle-step ({rate:.3e} particle-steps/s){mem}{check}",
            workload
        );
    }
    if verified == Some(false) {
        return Err(Error::input(if args.fma {
            "--verify --fma: two GPU runs differ"
        } else {
            "--verify: the GPU's bits differ from the mirror's"
        }));
    }
    Ok(())
}

/// Steps on the GPU: wall seconds, device memory (used, total), and with
/// `--verify` whether the mirror (with `--fma`: a second GPU run) gives the
/// same bits.
#[cfg(feature = "cuda")]
fn gpu(mirror: Mirror, steps: u64, args: &GpuArgs) -> Result<Timed> {
    use grains::gpu::cuda::{Cuda, Options};
    let options = Options {
        fma: args.fma,
        sync_each_step: args.sync_each_step,
        graph: args.graph,
    };
    let reference = args.verify.then(|| mirror.clone());
    let mut engine = Cuda::with(mirror, options)?;
    // One step first: the driver's JIT and first launches are not timed.
    engine.advance(1)?;
    let start = Instant::now();
    engine.advance(steps)?;
    let wall = start.elapsed().as_secs_f64();
    let memory = engine.memory()?;
    let verified = match reference {
        None => None,
        Some(m) => {
            let first = engine.host()?;
            let other = if args.fma {
                drop(engine);
                let mut again = Cuda::with(m, options)?;
                again.advance(1)?;
                again.advance(steps)?;
                again.host()?
            } else {
                let mut m = m;
                m.advance(1)?;
                m.advance(steps)?;
                m
            };
            let (grains, list) = first.differences(&other);
            if grains > 0 || list {
                eprintln!("grains: {grains} grains differ; lists or springs differ: {list}");
            }
            Some(grains == 0 && !list)
        }
    };
    Ok((wall, Some(memory), verified))
}

#[cfg(not(feature = "cuda"))]
fn gpu(_: Mirror, _: u64, _: &GpuArgs) -> Result<Timed> {
    Err(Error::input(grains::gpu::NO_FEATURE))
}
