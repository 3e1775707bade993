//! Drawing helpers shared by the measurement pictures: walls at a given time
//! on a particle picture, faint backgrounds, per-grain colours.

use crate::boundary::{Shape, Wall};
use crate::dim::Dim;
use crate::io::picture::Image;
use crate::io::{render_particles, Frame, PictureOptions};

/// World (horizontal, vertical) pair of a vector: (x, y) in 2D, (x, z) in 3D.
pub fn hv<D: Dim>(v: D::V) -> [f64; 2] {
    [D::get(v, 0), D::get(v, D::vertical())]
}

/// Same for an xyz array.
pub fn hv3(x: [f64; 3], dim: usize) -> [f64; 2] {
    [x[0], if dim == 3 { x[2] } else { x[1] }]
}

/// Draws the walls as they stand at time `t`: segments and planes as lines,
/// obstacles as filled disks. Cylinders and polygons are not drawn.
pub fn draw_walls<D: Dim>(img: &mut Image, walls: &[Wall<D>], t: f64, colour: [u8; 3], width: f64) {
    let view = img.view;
    let px = |v: D::V| view.to_pixel(hv::<D>(v));
    for w in walls.iter().filter(|w| w.is_active(t)) {
        match &w.shape {
            Shape::Segment { a, b } => {
                let (pa, pb) = (px(w.motion.place(*a, t)), px(w.motion.place(*b, t)));
                img.draw_segment(pa, pb, width, colour);
            }
            Shape::Plane { point, normal } => {
                // The line in the picture plane perpendicular to the normal,
                // sampled so that a modulated vibration shows its shape.
                let n = hv::<D>(*normal);
                let dir = [-n[1], n[0]];
                let span = 2.0 * (img.width.max(img.height) as f64) / view.scale;
                let k = 64;
                let mut last: Option<[f64; 2]> = None;
                for i in 0..=k {
                    let s = span * (i as f64 / k as f64 - 0.5);
                    let mut q = *point;
                    D::set(&mut q, 0, D::get(*point, 0) + s * dir[0]);
                    let up = D::vertical();
                    D::set(&mut q, up, D::get(*point, up) + s * dir[1]);
                    let p = px(w.motion.place(q, t));
                    if let Some(l) = last {
                        img.draw_segment(l, p, width, colour);
                    }
                    last = Some(p);
                }
            }
            Shape::Obstacle { center, diameter } => {
                let c = px(w.motion.place(*center, t));
                img.fill_disk(c, 0.5 * diameter * view.scale, colour, true);
            }
            _ => {}
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
        pos: pick(&frame.pos),
        vel: pick(&frame.vel),
        omega: pick(&frame.omega),
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

/// A colour per grain id, for telling trajectories apart.
pub fn id_colour(id: u64) -> [u8; 3] {
    let h = (id.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) as f64 / (1u64 << 24) as f64;
    // A hue wheel kept away from very light colours.
    let f = |o: f64| {
        let x = ((h + o).fract() * 6.0 - 3.0).abs() - 1.0;
        (40.0 + 170.0 * x.clamp(0.0, 1.0)) as u8
    };
    [f(0.0), f(1.0 / 3.0), f(2.0 / 3.0)]
}
