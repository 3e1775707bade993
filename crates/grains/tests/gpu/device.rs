//! The CUDA engine against the CPU mirror, bit for bit (feature `cuda`).
//! Where no CUDA device or driver is present each test prints "skipped: no
//! CUDA device" and returns, unless `GRAINS_REQUIRE_GPU=1` says a device
//! was asked for: then it fails.

use grains::gpu::cuda::{Cuda, Options};
use grains::gpu::mirror::{CellOrder, Mirror};
use grains::scenario::{build_md, load_file};
use grains::D3;
use std::path::PathBuf;

/// The chute, re-sorted every second list build (into `order`).
fn chute_in(order: CellOrder) -> Mirror {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-chute.toml");
    let (md, _) = build_md::<D3>(&load_file(&path, &[]).unwrap()).unwrap();
    let mut m = Mirror::from_md_in(&md, order).unwrap();
    m.params.sort_every = 2;
    m
}

fn chute() -> Mirror {
    chute_in(CellOrder::Morton)
}

/// The pipeline on the device, or `None` (after a visible line) where no
/// device is found; with `GRAINS_REQUIRE_GPU=1` a missing device fails the
/// test instead. The line goes to the process's stderr itself, which the
/// test harness does not capture (`eprintln!` it does, and shows only for
/// a failing test), so a passing run says that it skipped.
fn on_device(m: Mirror, options: Options) -> Option<Cuda> {
    match Cuda::with(m, options) {
        Ok(g) => Some(g),
        Err(e) => {
            let required = std::env::var("GRAINS_REQUIRE_GPU").is_ok_and(|v| v == "1");
            assert!(!required, "GRAINS_REQUIRE_GPU=1 but no CUDA device: {e}");
            let line = format!("skipped: no CUDA device ({e})\n");
            let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
            None
        }
    }
}

/// The chute over 300 steps in two stretches, without fused multiply-add,
/// re-sorted into Morton order: the rebuild decided on the device (and, as
/// variants, by the host after every step, in graphs of 16 steps, with
/// list buffers too small to start with, in the CPU engine's cell order):
/// the mirror's bits.
#[test]
fn gpu_engine_same_bits_as_the_mirror_on_the_chute() {
    let mut mirror = chute();
    let start = mirror.clone();
    for n in [1, 299] {
        mirror.advance(n).unwrap();
    }
    assert!(mirror.builds >= 2, "{} builds", mirror.builds);
    let moved = mirror
        .rank
        .iter()
        .enumerate()
        .filter(|&(k, &r)| r as usize != k);
    assert!(moved.count() > 0, "no grain moved out of the CPU's order");
    let mut tight = start.clone();
    tight.capacity = [0, 0];
    let cpu_order = chute_in(CellOrder::Cpu);
    let mut cpu_mirror = cpu_order.clone();
    for n in [1, 299] {
        cpu_mirror.advance(n).unwrap();
    }
    let graph = Options {
        graph: true,
        ..Options::default()
    };
    let sync = Options {
        sync_each_step: true,
        ..Options::default()
    };
    for (what, m, options) in [
        ("device decides", start.clone(), Options::default()),
        ("host decides", start.clone(), sync),
        ("graph of steps", start.clone(), graph),
        ("full buffers", tight, Options::default()),
        ("CPU cell order", cpu_order.clone(), Options::default()),
    ] {
        let want = if what == "CPU cell order" {
            &cpu_mirror
        } else {
            &mirror
        };
        let Some(mut gpu) = on_device(m, options) else {
            return;
        };
        for n in [1, 299] {
            gpu.advance(n).unwrap();
        }
        let (grains, lists) = gpu.host().unwrap().differences(want);
        assert_eq!(
            (grains, lists),
            (0, false),
            "{what}: grains, lists differing"
        );
    }
}

/// With fused multiply-add: the same bits on two runs (no order left to
/// the threads), and within rounding's reach of the mirror.
///
/// The bound: FMA changes a result by about one ulp (1e-16 relative) per
/// contraction (docs/gpu.md), and a dense flow amplifies it chaotically;
/// the chute's Hooke contacts (kn = 2e5, m ≈ 1) last about 50 steps of
/// 1e-4 s, so 300 steps are about six contact times, and even a tenfold
/// growth per contact time leaves 1e-10 of a diameter (d = 1). A wrong
/// kernel, by contrast, moves a grain by about F dt²/m ≈ 1e-5 d in a
/// single step (F ≈ kn · 0.01 d). So every grain (matched by id) must lie
/// within 1e-6 d of the mirror's, and its velocity within 1e-6 d/dt.
#[test]
fn gpu_engine_with_fma_repeats_its_bits() {
    let start = chute();
    let fma = Options {
        fma: true,
        ..Options::default()
    };
    let mut runs = Vec::new();
    for _ in 0..2 {
        let Some(mut gpu) = on_device(start.clone(), fma) else {
            return;
        };
        gpu.advance(300).unwrap();
        runs.push(gpu.host().unwrap());
    }
    assert_eq!(runs[0].differences(&runs[1]), (0, false));
    let mut mirror = start;
    mirror.advance(300).unwrap();
    let (grains, _) = runs[0].differences(&mirror);
    eprintln!("with FMA, {grains} grains differ from the mirror after 300 steps");
    let dt = mirror.params.dt;
    let at: std::collections::HashMap<u64, usize> = mirror
        .id
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, k))
        .collect();
    let gpu = &runs[0];
    assert_eq!(gpu.len(), mirror.len(), "grains lost");
    let (mut worst_x, mut worst_v) = (0.0f64, 0.0f64);
    for (k, id) in gpu.id.iter().enumerate() {
        let j = at[id];
        let d = |s: &grains::gpu::grain_kernels::Soa3, t: &grains::gpu::grain_kernels::Soa3| {
            ((s.x[k] - t.x[j]).powi(2) + (s.y[k] - t.y[j]).powi(2) + (s.z[k] - t.z[j]).powi(2))
                .sqrt()
        };
        worst_x = worst_x.max(d(&gpu.pos, &mirror.pos));
        worst_v = worst_v.max(d(&gpu.vel, &mirror.vel) * dt);
    }
    eprintln!("with FMA, largest differences: position {worst_x:e}, velocity × dt {worst_v:e}");
    assert!(worst_x < 1e-6, "position off by {worst_x:e} diameters");
    assert!(worst_v < 1e-6, "velocity × dt off by {worst_v:e} diameters");
}
