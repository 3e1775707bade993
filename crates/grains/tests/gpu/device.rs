//! The CUDA engine against the CPU mirror, bit for bit (feature `cuda`;
//! skipped, with a message, where no CUDA device or driver is present).

use grains::gpu::cuda::Cuda;
use grains::gpu::mirror::Mirror;
use grains::scenario::{build_md, load_file};
use grains::D3;
use std::path::PathBuf;

#[test]
fn gpu_engine_same_bits_as_the_mirror_on_the_chute() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/bench-chute.toml");
    let (md, _) = build_md::<D3>(&load_file(&path, &[]).unwrap()).unwrap();
    let mut mirror = Mirror::from_md(&md).unwrap();
    let mut gpu = match Cuda::new(mirror.clone()) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("skipped: no CUDA device ({e})");
            return;
        }
    };
    for n in [1, 299] {
        gpu.advance(n).unwrap();
        mirror.advance(n).unwrap();
    }
    let (grains, lists) = gpu.host().unwrap().differences(&mirror);
    assert_eq!(
        (grains, lists),
        (0, false),
        "grains differing, lists differing"
    );
    assert!(mirror.builds >= 2, "{} builds", mirror.builds);
}
