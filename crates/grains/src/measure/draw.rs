//! Drawing helpers shared by the measurement pictures: walls at a given time
//! on a particle picture, faint backgrounds (per-grain colours are
//! `crate::render::legend::id_colour`).

use crate::boundary::Wall;
use crate::dim::Dim;
use crate::io::picture::Image;
use crate::io::{render_particles, Frame, PictureOptions};
use crate::render::{wires_at, Wire};

/// World (horizontal, vertical) pair of a vector: (x, y) in 2D, (x, z) in 3D.
pub fn hv<D: Dim>(v: D::V) -> [f64; 2] {
    [D::get(v, 0), D::get(v, D::vertical())]
}

/// Same for an xyz array.
pub fn hv3(x: [f64; 3], dim: usize) -> [f64; 2] {
    [x[0], if dim == 3 { x[2] } else { x[1] }]
}

/// Draws the walls as they stand at time `t` (every shape: lines for planes,
/// segments, polygon outlines and cylinders, filled disks for obstacles),
/// cut to the part of the world the picture shows.
pub fn draw_walls<D: Dim>(img: &mut Image, walls: &[Wall<D>], t: f64, colour: [u8; 3], width: f64) {
    let view = img.view;
    let (h0, v0) = (view.origin[0], view.origin[1]);
    let (h1, v1) = (
        h0 + img.width as f64 / view.scale,
        v0 + img.height as f64 / view.scale,
    );
    // The depth axis (y in 3D) is not shown: any reach will do.
    let far = 1e3 * (h1 - h0).abs().max((v1 - v0).abs());
    let (lo, hi) = if D::D == 3 {
        ([h0, -far, v0], [h1, far, v1])
    } else {
        ([h0, v0, -0.5], [h1, v1, 0.5])
    };
    let px = |p: [f64; 3]| view.to_pixel(hv3(p, D::D));
    for w in wires_at(walls, t, lo, hi) {
        match w {
            Wire::Line { points } => {
                for pair in points.windows(2) {
                    img.draw_segment(px(pair[0]), px(pair[1]), width, colour);
                }
            }
            Wire::Ball { center, radius } => {
                img.fill_disk(px(center), radius * view.scale, colour, true);
            }
        }
    }
}

/// The frame without the grains that left the box (lost grains would
/// stretch the picture).
pub fn in_box(frame: &Frame) -> Frame {
    let v = frame.vertical();
    let keep: Vec<usize> = (0..frame.len())
        .filter(|&i| {
            let p = frame.pos[i];
            [0, v]
                .iter()
                .all(|&a| p[a] >= frame.box_lo[a] && p[a] <= frame.box_hi[a])
        })
        .collect();
    let pick = |x: &Vec<[f64; 3]>| keep.iter().map(|&i| x[i]).collect::<Vec<_>>();
    Frame {
        id: keep.iter().map(|&i| frame.id[i]).collect(),
        kind: keep.iter().map(|&i| frame.kind[i]).collect(),
        radius: keep.iter().map(|&i| frame.radius[i]).collect(),
        mass: match frame.mass.is_empty() {
            true => Vec::new(),
            false => keep.iter().map(|&i| frame.mass[i]).collect(),
        },
        pos: pick(&frame.pos),
        vel: pick(&frame.vel),
        omega: pick(&frame.omega),
        body: frame
            .body
            .as_ref()
            .map(|b| keep.iter().map(|&i| b[i]).collect()),
        orientation: frame
            .orientation
            .as_ref()
            .map(|q| keep.iter().map(|&i| q[i]).collect()),
        ..frame.clone()
    }
}

/// The particles of `frame` drawn in a light tint (a background for arrows,
/// trajectories, segments).
pub fn faint(frame: &Frame) -> Image {
    let mut f = in_box(frame);
    f.vel.iter_mut().for_each(|x| *x = [0.0; 3]);
    let mut img = render_particles(&f, &PictureOptions::default());
    for px in img.rgb.chunks_mut(3) {
        for c in px {
            *c = 255 - (255 - *c) / 4;
        }
    }
    img
}
