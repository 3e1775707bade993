//! The CUDA engine against the CPU mirror, bit for bit (feature `cuda`;
//! skipped, with a message, where no CUDA device or driver is present).

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
        let mut gpu = match Cuda::with(m, options) {
            Ok(g) => g,
            Err(e) => {
                eprintln!("skipped: no CUDA device ({e})");
                return;
            }
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
/// the threads), whatever they are against the mirror's.
#[test]
fn gpu_engine_with_fma_repeats_its_bits() {
    let start = chute();
    let fma = Options {
        fma: true,
        ..Options::default()
    };
    let mut runs = Vec::new();
    for _ in 0..2 {
        let mut gpu = match Cuda::with(start.clone(), fma) {
            Ok(g) => g,
            Err(e) => {
                eprintln!("skipped: no CUDA device ({e})");
                return;
            }
        };
        gpu.advance(300).unwrap();
        runs.push(gpu.host().unwrap());
    }
    assert_eq!(runs[0].differences(&runs[1]), (0, false));
    let mut mirror = start;
    mirror.advance(300).unwrap();
    let (grains, _) = runs[0].differences(&mirror);
    eprintln!("with FMA, {grains} grains differ from the mirror after 300 steps");
}
