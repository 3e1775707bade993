//! Criterion benchmarks of the two hot kernels, on the vib2d and chute
//! workloads of `bench/` (the LAMMPS twins), so that regressions show:
//! - `forces/*`: one full force evaluation (pair contacts, walls, gravity);
//! - `neighbors/*`: one Verlet-list build from the same positions.
//!
//! Run with `cargo bench -p grains --bench kernels`.

use criterion::{criterion_group, criterion_main, Criterion};
use grains::neighbors::NeighborList;
use grains::scenario::{build_md, load_file};
use grains::{Dim, D2, D3};
use std::path::Path;

fn scenario(name: &str) -> grains::scenario::Loaded {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios")
        .join(name);
    load_file(&path, &[]).expect("bench scenario loads")
}

fn bench_workload<D: Dim>(c: &mut Criterion, label: &str, file: &str) {
    let loaded = scenario(file);
    let (mut md, _) = build_md::<D>(&loaded).expect("bench scenario builds");
    // Let contacts form so springs and deferred shares are exercised.
    md.run(20).expect("stable");
    c.bench_function(&format!("forces/{label}"), |b| {
        b.iter(|| md.compute_forces(true))
    });
    let p = &md.particles;
    let mut list = NeighborList::<D>::new(md.settings.skin);
    c.bench_function(&format!("neighbors/{label}"), |b| {
        b.iter(|| {
            list.build(&p.pos, &p.radius, &p.frozen, &md.domain)
                .expect("valid positions")
        })
    });
}

fn kernels(c: &mut Criterion) {
    bench_workload::<D2>(c, "vib2d", "bench-vib2d.toml");
    bench_workload::<D3>(c, "chute", "bench-chute.toml");
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = kernels
}
criterion_main!(benches);
