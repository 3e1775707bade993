//! The CUDA engine against the CPU mirror, bit for bit (feature `cuda`;
//! skipped, with a message, where no CUDA device or driver is present).

use grains::gpu::cuda::{Cuda, Options};
use grains::gpu::mirror::Mirror;
use grains::scenario::{build_md, load_file};
use grains::D3;
use std::path::PathBuf;

fn chute() -> Mirror {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-chute.toml");
    let (md, _) = build_md::<D3>(&load_file(&path, &[]).unwrap()).unwrap();
    Mirror::from_md(&md).unwrap()
}

/// The chute over 300 steps in two stretches, without fused multiply-add:
/// the rebuild decided on the device (and, as a variant, by the host after
/// every step), list buffers too small to start with: the mirror's bits.
#[test]
fn gpu_engine_same_bits_as_the_mirror_on_the_chute() {
    let mut mirror = chute();
    let start = mirror.clone();
    for n in [1, 299] {
        mirror.advance(n).unwrap();
    }
    assert!(mirror.builds >= 2, "{} builds", mirror.builds);
    let mut tight = start.clone();
    tight.capacity = [0, 0];
    let sync = Options {
        sync_each_step: true,
        ..Options::default()
    };
    for (what, m, options) in [
        ("device decides", start.clone(), Options::default()),
        ("host decides", start.clone(), sync),
        ("full buffers", tight, Options::default()),
    ] {
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
        let (grains, lists) = gpu.host().unwrap().differences(&mirror);
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
