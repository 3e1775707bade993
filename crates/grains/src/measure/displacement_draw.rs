//! displacement.png: where a few tracer grains went over the measurement,
//! drawn so that it can be read.
//!
//! Every grain's displacement is in displacement.csv; the picture shows
//! [`TRACERS`] of them, chosen evenly in id order (the same ones on any
//! thread count), each in its own colour: a dot where it started and an
//! arrow to where it is at the end, drawn over the final state. The
//! displacement is unwrapped across periodic boundaries, so the arrow ends
//! on the grain and starts one displacement back; a periodic axis wraps the
//! arrow into the box in pieces (it leaves one side and comes in at the
//! other) instead of pointing out of the picture. A band under it gives
//! the time span, a scale bar and what the marks mean.

use super::displacement::Displacement;
use super::draw::{draw_walls, faint};
use crate::boundary::Wall;
use crate::dim::Dim;
use crate::io::{Frame, Image, View};
use crate::render::legend::{draw_band_labelled, id_colour, Legend, BAND_ROWS};
use crate::render::text::sig3;
use std::collections::HashMap;

/// How many grains the picture follows.
pub const TRACERS: usize = 30;

/// Up to `n` of `rows`, evenly spaced in id order.
pub fn tracers(rows: &[Displacement], n: usize) -> Vec<Displacement> {
    let mut sorted = rows.to_vec();
    sorted.sort_by_key(|r| r.id);
    let k = n.min(sorted.len());
    (0..k).map(|j| sorted[j * sorted.len() / k]).collect()
}

/// The pieces of the segment `a`–`b` (world plane coordinates) inside the
/// box `lo`–`hi` along the periodic axes (`periodic`), each a periodic copy
/// of part of it; a non-periodic axis is not cut. Pieces in order along
/// the segment, as (from, to, whether it ends at `b`).
pub fn wrapped_pieces(
    a: [f64; 2],
    b: [f64; 2],
    lo: [f64; 2],
    hi: [f64; 2],
    periodic: [bool; 2],
) -> Vec<([f64; 2], [f64; 2], bool)> {
    // Parameters along the segment where it crosses a periodic face.
    let mut cuts = vec![0.0, 1.0];
    for ax in 0..2 {
        let len = hi[ax] - lo[ax];
        let d = b[ax] - a[ax];
        if !periodic[ax] || len.is_nan() || len <= 0.0 || d == 0.0 {
            continue;
        }
        let (x0, x1) = (a[ax].min(b[ax]), a[ax].max(b[ax]));
        let first = ((x0 - lo[ax]) / len).ceil() as i64;
        let last = ((x1 - lo[ax]) / len).floor() as i64;
        for k in first..=last {
            let t = (lo[ax] + k as f64 * len - a[ax]) / d;
            if t > 0.0 && t < 1.0 {
                cuts.push(t);
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    cuts.windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            // Each piece lies in one periodic copy of the box: the one of
            // its middle, shifted back into the box.
            let mid = at(0.5 * (w[0] + w[1]));
            let mut shift = [0.0; 2];
            for ax in 0..2 {
                let len = hi[ax] - lo[ax];
                if periodic[ax] && len > 0.0 {
                    shift[ax] = ((mid[ax] - lo[ax]) / len).floor() * len;
                }
            }
            let (p, q) = (at(w[0]), at(w[1]));
            (
                [p[0] - shift[0], p[1] - shift[1]],
                [q[0] - shift[0], q[1] - shift[1]],
                w[1] == 1.0,
            )
        })
        .collect()
}

/// The picture of `rows` (every grain's displacement from time `t0` to the
/// frame `last`), over `last` drawn faintly with `walls`.
pub fn picture<D: Dim>(
    rows: &[Displacement],
    t0: Option<f64>,
    last: &Frame,
    walls: &[Wall<D>],
) -> Image {
    let v = last.vertical();
    let mut world = faint(last);
    draw_walls(&mut world, walls, last.time, [60, 60, 60], 1.5);
    let text_scale = if world.width >= 700 { 2 } else { 1 };
    let mut img = with_band(&world, BAND_ROWS * text_scale);
    let view = img.view;
    let px = |w: [f64; 2]| view.to_pixel(w);
    let lo = [last.box_lo[0], last.box_lo[v]];
    let hi = [last.box_hi[0], last.box_hi[v]];
    let periodic = [last.periodic[0], last.periodic[v]];
    let now: HashMap<u64, [f64; 3]> = last
        .id
        .iter()
        .copied()
        .zip(last.pos.iter().copied())
        .collect();
    let line = 1.0 + text_scale as f64;
    let mut pieces = Vec::new();
    let mut shown = 0;
    for r in tracers(rows, TRACERS) {
        // A grain that left the box is not in the picture.
        let Some(end) = now.get(&r.id) else { continue };
        let end = [end[0], end[v]];
        let start = [
            end[0] - (r.end[0] - r.start[0]),
            end[1] - (r.end[v] - r.start[v]),
        ];
        pieces.push((
            id_colour(r.id),
            wrapped_pieces(start, end, lo, hi, periodic),
        ));
        shown += 1;
    }
    for (colour, parts) in &pieces {
        for (k, &(a, b, last_piece)) in parts.iter().enumerate() {
            let (pa, pb) = (px(a), px(b));
            img.draw_segment(pa, pb, line, *colour);
            if k == 0 {
                img.fill_disk(pa, 2.0 * line, *colour, true);
            }
            if last_piece {
                arrow_head(&mut img, pa, pb, 5.0 * line, line, *colour);
            }
        }
    }
    let t1 = last.time;
    let (long, short) = match t0 {
        Some(t0) => (
            format!("t = {} to {} s", sig3(t0), sig3(t1)),
            format!("{}-{} s", sig3(t0), sig3(t1)),
        ),
        None => (
            format!("until t = {} s", sig3(t1)),
            format!("-{} s", sig3(t1)),
        ),
    };
    let note = format!("{shown} of {} grains, dot = start", rows.len());
    let top = world.height;
    draw_band_labelled(
        &mut img,
        top,
        text_scale,
        [&long, &short],
        &Legend::Note(&note),
    );
    img
}

/// `world` with `rows` white rows added under it for the band, the world
/// drawn where it was.
fn with_band(world: &Image, rows: u32) -> Image {
    let view = View {
        origin: [
            world.view.origin[0],
            world.view.origin[1] - rows as f64 / world.view.scale,
        ],
        scale: world.view.scale,
        height: world.view.height + rows,
    };
    let mut img = Image::new(world.width, world.height + rows, view);
    img.rgb[..world.rgb.len()].copy_from_slice(&world.rgb);
    img
}

/// A head at pixel `tip` for a shaft coming from `from`, `size` pixels long.
fn arrow_head(img: &mut Image, from: [f64; 2], tip: [f64; 2], size: f64, w: f64, c: [u8; 3]) {
    let (dx, dy) = (tip[0] - from[0], tip[1] - from[1]);
    let len = (dx * dx + dy * dy).sqrt();
    if len.is_nan() || len <= 0.5 {
        return;
    }
    let (ux, uy) = (dx / len, dy / len);
    let (cos, sin) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
    for sign in [1.0, -1.0] {
        let (hx, hy) = (-(ux * cos - sign * uy * sin), -(sign * ux * sin + uy * cos));
        img.draw_segment(tip, [tip[0] + size * hx, tip[1] + size * hy], w, c);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(id: u64) -> Displacement {
        Displacement {
            id,
            start: [0.0; 3],
            end: [0.0; 3],
        }
    }

    /// Thirty of two hundred, spread over the ids whatever their order.
    #[test]
    fn tracers_are_spread_evenly_by_id() {
        let rows: Vec<Displacement> = (0..200).rev().map(d).collect();
        let t = tracers(&rows, 30);
        assert_eq!(t.len(), 30);
        assert_eq!(t[0].id, 0);
        assert_eq!(t[1].id, 6);
        assert_eq!(t[29].id, 193);
        assert_eq!(tracers(&rows[..5], 30).len(), 5);
    }

    /// A step of 1.5 box widths to the right, ending at x = 0.25 of a unit
    /// box, is three pieces: the first from the start's copy to the right
    /// face, one across the box, the last from the left face to the end.
    #[test]
    fn a_long_periodic_step_wraps_into_the_box() {
        let p = wrapped_pieces(
            [-1.25, 0.5],
            [0.25, 0.5],
            [0.0, 0.0],
            [1.0, 1.0],
            [true, false],
        );
        assert_eq!(p.len(), 3, "{p:?}");
        let close =
            |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12;
        assert!(
            close(p[0].0, [0.75, 0.5]) && close(p[0].1, [1.0, 0.5]),
            "{p:?}"
        );
        assert!(
            close(p[1].0, [0.0, 0.5]) && close(p[1].1, [1.0, 0.5]),
            "{p:?}"
        );
        assert!(
            close(p[2].0, [0.0, 0.5]) && close(p[2].1, [0.25, 0.5]),
            "{p:?}"
        );
        assert!(p[2].2 && !p[0].2 && !p[1].2);
        for (a, b, _) in &p {
            assert!((0.0..=1.0).contains(&a[0]) && (0.0..=1.0).contains(&b[0]));
        }
        // Along a wall-bounded axis nothing is cut.
        let q = wrapped_pieces(
            [0.5, -2.0],
            [0.5, 0.5],
            [0.0, 0.0],
            [1.0, 1.0],
            [true, false],
        );
        assert_eq!(q.len(), 1);
    }
}
