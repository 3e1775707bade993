//! Criterion benchmarks of movie frames of 10^5 grains: one frame painted
//! (grains, walls, band) and appended to a GIF, on one thread, the way
//! `grains movie` and `output.movie` draw each frame; and one frame's
//! packing for `grains view`'s reading side, the VTK text parse.
//! The target is at least 10 frames per second (under 100 ms a frame).
//!
//! Run with `cargo bench -p grains --bench render`.

use criterion::{criterion_group, criterion_main, Criterion};
use grains::io::{read_frame, vtp_string, Frame};
use grains::render::movie::GifWriter;
use grains::render::{Painter, StillOptions, Wire};

/// 10^5 grains of diameter 0.9 to 1 on a square lattice (2D: 400 × 250 in a
/// box 400 × 400; 3D: 50 × 50 × 40 in a box 50 × 50 × 60, shifted in x and
/// z), speeds varying.
fn grains(dim: usize) -> Frame {
    let (n, cols): (usize, [usize; 3]) = if dim == 2 {
        (100_000, [400, 250, 1])
    } else {
        (100_000, [50, 50, 40])
    };
    let mut f = Frame {
        dim,
        time: 1.25,
        box_lo: [0.0, 0.0, if dim == 2 { -0.5 } else { 0.0 }],
        box_hi: if dim == 2 {
            [400.0, 400.0, 0.5]
        } else {
            [50.0, 50.0, 60.0]
        },
        periodic: [true, false, false],
        ..Default::default()
    };
    for k in 0..n {
        let (i, j, l) = (
            k % cols[0],
            (k / cols[0]) % cols[1],
            k / (cols[0] * cols[1]),
        );
        // Shifted off the lattice by up to ±0.3 in the picture plane, as in
        // a real packing (an aligned lattice would leave straight holes
        // through every layer of a 3D picture).
        let jitter = |salt: u64| {
            let h = (k as u64 ^ salt).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 11;
            0.6 * (h as f64 / (1u64 << 53) as f64 - 0.5)
        };
        let p = if dim == 2 {
            [i as f64 + 0.5, j as f64 + 0.5, 0.0]
        } else {
            [
                i as f64 + 0.5 + jitter(1),
                j as f64 + 0.5,
                l as f64 + 0.5 + jitter(2),
            ]
        };
        f.pos.push(p);
        f.vel
            .push([(k as f64 * 0.37).sin(), (k as f64 * 0.11).cos(), 0.0]);
        f.omega.push([0.0; 3]);
        f.radius.push(0.45 + 0.05 * ((k % 7) as f64 / 6.0));
        f.id.push(k as u64 + 1);
        f.kind.push(1 + (k % 3) as u32);
    }
    f
}

fn render(c: &mut Criterion) {
    for dim in [2, 3] {
        let f = grains(dim);
        let floor = vec![Wire::Line {
            points: (0..=64)
                .map(|k| [f.box_hi[0] * k as f64 / 64.0, 0.0, 0.0])
                .collect(),
        }];
        for width in [640u32, 1000] {
            let opts = StillOptions {
                width,
                ..Default::default()
            };
            let painter = Painter::new(&[&f], &opts);
            let mut gif = GifWriter::new(Vec::new(), painter.width, painter.height(), 10).unwrap();
            c.bench_function(&format!("movie_frame/{dim}d_1e5/{width}px"), |b| {
                b.iter(|| {
                    let img = painter.paint(&f, &floor);
                    gif.push(&img).unwrap();
                })
            });
        }
    }
    // Reading one 10^5-grain frame back from its VTK text (what a movie
    // and the viewer's server do per frame before drawing or packing it).
    let dir = std::env::temp_dir().join(format!("grains-bench-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("frame.vtp");
    std::fs::write(&path, vtp_string(&grains(2))).unwrap();
    c.bench_function("read_vtp/2d_1e5", |b| b.iter(|| read_frame(&path).unwrap()));
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = render
}
criterion_main!(benches);
