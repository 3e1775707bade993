//! Pictures of a frame as PNG, in pure Rust: filled disks coloured by speed
//! with a viridis-like colour map on a white background, the box outline
//! (walls dark, periodic edges light), and optional displacement arrows.
//!
//! World coordinates in pictures are pairs (horizontal, vertical): (x, y) in
//! 2D, (x, z) in 3D, where particles are drawn from far (large y) to near.

use super::atomic::write_atomic;
use super::frame::Frame;
use crate::error::{Error, Result};
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct PictureOptions {
    /// Image width in pixels; the height follows the drawn rectangle's aspect.
    pub width: u32,
    /// Speed at the top of the colour scale; `None`: the frame's fastest particle.
    pub max_speed: Option<f64>,
    /// Smooth disk edges (coverage-weighted blending).
    pub antialias: bool,
}

impl Default for PictureOptions {
    fn default() -> Self {
        PictureOptions {
            width: 1000,
            max_speed: None,
            antialias: true,
        }
    }
}

/// The mapping from world (horizontal, vertical) to pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// World coordinates of the image's lower-left corner.
    pub origin: [f64; 2],
    /// Pixels per world unit.
    pub scale: f64,
    pub height: u32,
}

impl View {
    /// Pixel coordinates (x right, y down; pixel `i` spans `i..i+1`).
    pub fn to_pixel(&self, w: [f64; 2]) -> [f64; 2] {
        [
            (w[0] - self.origin[0]) * self.scale,
            self.height as f64 - (w[1] - self.origin[1]) * self.scale,
        ]
    }
}

/// An 8-bit RGB image together with the world-to-pixel mapping it was drawn with.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Row-major RGB, top row first.
    pub rgb: Vec<u8>,
    pub view: View,
}

const WALL: [u8; 3] = [60, 60, 60];
const PERIODIC_EDGE: [u8; 3] = [190, 190, 190];
const MAX_HEIGHT: u32 = 16384;

impl Image {
    /// A white image; `view` maps world coordinates onto it.
    pub fn new(width: u32, height: u32, view: View) -> Self {
        let (width, height) = (width.max(1), height.max(1));
        Image {
            width,
            height,
            rgb: vec![255; width as usize * height as usize * 3],
            view,
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let k = (y as usize * self.width as usize + x as usize) * 3;
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }

    /// Mixes `colour` into pixel (x, y) with weight `alpha` in [0, 1].
    fn blend(&mut self, x: i64, y: i64, colour: [u8; 3], alpha: f64) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 || alpha <= 0.0 {
            return;
        }
        let k = (y as usize * self.width as usize + x as usize) * 3;
        if alpha >= 1.0 {
            self.rgb[k..k + 3].copy_from_slice(&colour);
            return;
        }
        for (old, &new) in self.rgb[k..k + 3].iter_mut().zip(&colour) {
            let o = *old as f64;
            *old = (o + (new as f64 - o) * alpha).round() as u8;
        }
    }

    /// Fills a disk given in pixel coordinates; disks of 3 px radius or more
    /// get a darker rim so touching particles stay distinct.
    pub fn fill_disk(&mut self, centre: [f64; 2], radius: f64, colour: [u8; 3], antialias: bool) {
        if !(centre[0].is_finite() && centre[1].is_finite() && radius.is_finite()) {
            return;
        }
        let r = radius.max(0.5);
        let rim = (r >= 3.0).then(|| colour.map(|c| (c as f64 * 0.6) as u8));
        let rim_from = r - (0.08 * r).max(1.0);
        let outer2 = (r + 0.5) * (r + 0.5);
        let (x0, x1) = self.clip_x(centre[0] - r - 1.0, centre[0] + r + 1.0);
        let (y0, y1) = self.clip_y(centre[1] - r - 1.0, centre[1] + r + 1.0);
        for y in y0..y1 {
            let dy2 = (y as f64 + 0.5 - centre[1]).powi(2);
            for x in x0..x1 {
                let d2 = (x as f64 + 0.5 - centre[0]).powi(2) + dy2;
                if d2 >= outer2 {
                    continue;
                }
                let d = d2.sqrt();
                let cover = if antialias {
                    (r + 0.5 - d).clamp(0.0, 1.0)
                } else {
                    f64::from(u8::from(d <= r))
                };
                let col = match rim {
                    Some(rc) if d > rim_from => rc,
                    _ => colour,
                };
                self.blend(x, y, col, cover);
            }
        }
    }

    /// Draws an anti-aliased segment of `width` pixels between two pixel
    /// positions, with round caps. Each pixel is blended once.
    pub fn draw_segment(&mut self, a: [f64; 2], b: [f64; 2], width: f64, colour: [u8; 3]) {
        if !a.iter().chain(&b).all(|v| v.is_finite() && v.abs() < 1e7) {
            return;
        }
        let half = width.max(0.5) / 2.0;
        // Walk along the major axis; `steep` swaps the axes.
        let steep = (b[1] - a[1]).abs() > (b[0] - a[0]).abs();
        let (p, q) = if steep {
            ([a[1], a[0]], [b[1], b[0]])
        } else {
            (a, b)
        };
        let (p, q) = if p[0] <= q[0] { (p, q) } else { (q, p) };
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let len = (dx * dx + dy * dy).sqrt();
        let slope = if dx > 0.0 { dy / dx } else { 0.0 };
        let extent = half * if len > 0.0 { len / dx.max(1e-12) } else { 1.0 } + 1.5;
        let extent = extent.min(half + 1.5 + len);
        let (u_lo, u_hi) = (p[0] - half - 1.0, q[0] + half + 1.0);
        let (u_max, v_max) = if steep {
            (self.height, self.width)
        } else {
            (self.width, self.height)
        };
        let u0 = u_lo.floor().max(0.0) as i64;
        let u1 = (u_hi.ceil().min(u_max as f64) as i64).max(u0);
        for u in u0..u1 {
            let uc = u as f64 + 0.5;
            let vc = p[1] + (uc.clamp(p[0], q[0]) - p[0]) * slope;
            let v0 = (vc - extent).floor().max(0.0) as i64;
            let v1 = ((vc + extent).ceil().min(v_max as f64) as i64).max(v0);
            for v in v0..v1 {
                let d = dist_to_segment([uc, v as f64 + 0.5], p, q);
                let cover = (half + 0.5 - d).clamp(0.0, 1.0);
                if steep {
                    self.blend(v, u, colour, cover);
                } else {
                    self.blend(u, v, colour, cover);
                }
            }
        }
    }

    fn clip_x(&self, lo: f64, hi: f64) -> (i64, i64) {
        clip(lo, hi, self.width)
    }

    fn clip_y(&self, lo: f64, hi: f64) -> (i64, i64) {
        clip(lo, hi, self.height)
    }

    /// Encodes the image as PNG and writes it atomically.
    /// Draws the box of `frame` seen along axes (`h`, `v`) as lines of
    /// `width` pixels: periodic sides light grey, the others in `edge`;
    /// nothing when the box is not finite.
    pub fn draw_box(&mut self, frame: &Frame, (h, v): (usize, usize), width: f64, edge: [u8; 3]) {
        let (lo, hi) = (frame.box_lo, frame.box_hi);
        if ![lo[h], hi[h], lo[v], hi[v]].iter().all(|x| x.is_finite()) {
            return;
        }
        let p = |a: f64, b: f64| self.view.to_pixel([a, b]);
        let colour = |periodic: bool| if periodic { PERIODIC_EDGE } else { edge };
        let (side, flat) = (colour(frame.periodic[h]), colour(frame.periodic[v]));
        let (ll, lr, ul, ur) = (
            p(lo[h], lo[v]),
            p(hi[h], lo[v]),
            p(lo[h], hi[v]),
            p(hi[h], hi[v]),
        );
        self.draw_segment(ll, ul, width, side);
        self.draw_segment(lr, ur, width, side);
        self.draw_segment(ll, lr, width, flat);
        self.draw_segment(ul, ur, width, flat);
    }

    pub fn save_png(&self, path: &Path) -> Result<()> {
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let to_io = |e: png::EncodingError| Error::io(path, std::io::Error::other(e));
            let mut w = enc.write_header().map_err(to_io)?;
            w.write_image_data(&self.rgb).map_err(to_io)?;
            w.finish().map_err(to_io)?;
        }
        write_atomic(path, &bytes)
    }
}

fn clip(lo: f64, hi: f64, n: u32) -> (i64, i64) {
    let a = lo.floor().clamp(0.0, n as f64) as i64;
    let b = hi.ceil().clamp(0.0, n as f64) as i64;
    (a, b.max(a))
}

fn dist_to_segment(c: [f64; 2], p: [f64; 2], q: [f64; 2]) -> f64 {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((c[0] - p[0]) * dx + (c[1] - p[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((c[0] - p[0] - t * dx).powi(2) + (c[1] - p[1] - t * dy).powi(2)).sqrt()
}

/// Viridis colour map sampled at 0, 0.1, …, 1 (sRGB), interpolated linearly.
const VIRIDIS: [[u8; 3]; 11] = [
    [68, 1, 84],
    [72, 36, 117],
    [65, 68, 135],
    [53, 95, 141],
    [42, 120, 142],
    [33, 145, 140],
    [34, 168, 132],
    [68, 191, 112],
    [122, 209, 81],
    [189, 223, 38],
    [253, 231, 37],
];

/// The colour for `t` in [0, 1] (clamped; NaN reads as 0).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * 10.0;
    let k = (t.floor() as usize).min(9);
    let f = t - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    [0, 1, 2].map(|c| (a[c] as f64 + (b[c] as f64 - a[c] as f64) * f).round() as u8)
}

/// Axis shown horizontally (x) and vertically (y in 2D, z in 3D).
fn axes(frame: &Frame) -> (usize, usize) {
    (0, frame.vertical())
}

/// The world rectangle [h0, h1] × [v0, v1] a picture of `frame` shows: the
/// box horizontally; vertically from the bottom of the box (or the lowest
/// particle) to the box top, clipped to the particles' top plus a margin when
/// the particles fill less than 80% of the box height (or the box is open).
pub fn world_rect(frame: &Frame) -> [f64; 4] {
    world_rect_of(&[frame], axes(frame), true)
}

/// As [`world_rect`], for the grains of all `frames` seen along axes
/// (`h`, `v`) in the box of the first; the top is cut to the grains only
/// when `cut_top` (the vertical axis is the one gravity pulls along).
pub fn world_rect_of(frames: &[&Frame], (h, v): (usize, usize), cut_top: bool) -> [f64; 4] {
    let mut ext = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut rmax = 0.0f64;
    for f in frames {
        for (p, &r) in f.pos.iter().zip(&f.radius) {
            if p[h].is_finite() && p[v].is_finite() && r.is_finite() {
                ext = [
                    ext[0].min(p[h] - r),
                    ext[1].max(p[h] + r),
                    ext[2].min(p[v] - r),
                    ext[3].max(p[v] + r),
                ];
                rmax = rmax.max(r);
            }
        }
    }
    let have = ext[0] <= ext[1];
    let valid = |lo: f64, hi: f64| lo.is_finite() && hi.is_finite() && hi > lo;
    let (blo, bhi) = frames
        .first()
        .map_or(([f64::NAN; 3], [f64::NAN; 3]), |f| (f.box_lo, f.box_hi));
    let (mut h0, mut h1) = (blo[h], bhi[h]);
    if !valid(h0, h1) {
        (h0, h1) = if have { (ext[0], ext[1]) } else { (0.0, 1.0) };
    }
    let (mut v0, mut v1) = (blo[v], bhi[v]);
    if !valid(v0, v1) {
        (v0, v1) = if have { (ext[2], ext[3]) } else { (0.0, 1.0) };
    } else if have && cut_top {
        v0 = v0.min(ext[2]);
        let top = ext[3] + (0.1 * (ext[3] - v0)).max(2.0 * rmax);
        if top < v0 + 0.8 * (v1 - v0) {
            v1 = top;
        }
    }
    // Degenerate extents (a single point): give them some size.
    let size = (h1 - h0).max(v1 - v0).max(2.0 * rmax).max(1e-9);
    if h1 - h0 < 1e-6 * size {
        (h0, h1) = (h0 - 0.5 * size, h1 + 0.5 * size);
    }
    if v1 - v0 < 1e-6 * size {
        (v0, v1) = (v0 - 0.5 * size, v1 + 0.5 * size);
    }
    [h0, h1, v0, v1]
}

/// Renders the particles of `frame`, coloured by speed, over the box outline.
pub fn render_particles(frame: &Frame, opts: &PictureOptions) -> Image {
    frame.check_lengths();
    let (h, v) = axes(frame);
    let [h0, h1, v0, v1] = world_rect(frame);
    let pad = 0.02 * (h1 - h0).max(v1 - v0);
    let (h0, h1, v0, v1) = (h0 - pad, h1 + pad, v0 - pad, v1 + pad);
    let width = opts.width.max(1);
    let scale = width as f64 / (h1 - h0);
    let height = ((v1 - v0) * scale).round().clamp(1.0, MAX_HEIGHT as f64) as u32;
    let mut img = Image::new(
        width,
        height,
        View {
            origin: [h0, v0],
            scale,
            height,
        },
    );

    let vmax = opts.max_speed.unwrap_or_else(|| {
        (0..frame.len())
            .map(|i| frame.speed(i))
            .filter(|s| s.is_finite())
            .fold(0.0, f64::max)
    });
    let mut order: Vec<usize> = (0..frame.len()).collect();
    if frame.dim == 3 {
        // Far (large y) first, so nearer particles cover them.
        order.sort_by(|&a, &b| frame.pos[b][1].total_cmp(&frame.pos[a][1]));
    }
    for i in order {
        let t = if vmax > 0.0 {
            frame.speed(i) / vmax
        } else {
            0.0
        };
        let c = img.view.to_pixel([frame.pos[i][h], frame.pos[i][v]]);
        img.fill_disk(c, frame.radius[i] * scale, viridis(t), opts.antialias);
    }

    // Box outline, clipped to the drawn rectangle by the image bounds.
    img.draw_box(frame, (h, v), 1.5, WALL);
    img
}

/// Draws arrows from `from[i]` to `to[i]` (world coordinates, same mapping as
/// the picture): a line and a small head. Arrows shorter than half a pixel are
/// skipped. Panics if the slices differ in length.
pub fn draw_arrows(img: &mut Image, from: &[[f64; 2]], to: &[[f64; 2]], colour: [u8; 3]) {
    assert_eq!(
        from.len(),
        to.len(),
        "draw_arrows: {} starts but {} ends",
        from.len(),
        to.len()
    );
    for (&a, &b) in from.iter().zip(to) {
        let (pa, pb) = (img.view.to_pixel(a), img.view.to_pixel(b));
        let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len.is_nan() || len < 0.5 {
            continue;
        }
        img.draw_segment(pa, pb, 1.2, colour);
        let head = (0.35 * len).min(8.0);
        let (ux, uy) = (dx / len, dy / len);
        let (c, s) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
        for sign in [1.0, -1.0] {
            // The shaft direction reversed, turned by ±25°.
            let (hx, hy) = (-(ux * c - sign * uy * s), -(sign * ux * s + uy * c));
            img.draw_segment(pb, [pb[0] + head * hx, pb[1] + head * hy], 1.2, colour);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::frame::tests::sample_2d;

    /// The pixel under world point `w`.
    pub(crate) fn at(img: &Image, w: [f64; 2]) -> [u8; 3] {
        let p = img.view.to_pixel(w);
        img.pixel(p[0] as u32, p[1] as u32)
    }

    #[test]
    fn disks_are_coloured_by_speed_on_white() {
        let f = sample_2d();
        let img = render_particles(&f, &PictureOptions::default());
        assert_eq!(img.width, 1000);
        // Fastest particle (index 2, speed 2) at the top of the scale, the resting one at the bottom.
        assert_eq!(at(&img, [7.0, 4.0]), viridis(1.0));
        assert_eq!(at(&img, [3.25, 1.5]), viridis(0.0));
        assert_eq!(at(&img, [1.0, 1.0]), viridis(1.25f64.sqrt() / 2.0));
        assert_eq!(at(&img, [5.0, 3.0]), [255, 255, 255]);
        // Box 10 × 20 with particles up to y = 4.45: the picture is clipped well below 20.
        let [_, _, v0, v1] = world_rect(&f);
        assert_eq!(v0, 0.0);
        assert!(v1 < 6.0 && v1 > 4.45, "{v1}");
        assert!(img.height < img.width);
        // The floor (a wall) is drawn dark.
        let floor = img.view.to_pixel([5.0, 0.0]);
        let px = img.pixel(floor[0] as u32, floor[1] as u32);
        assert!(px.iter().all(|&c| c < 100), "{px:?}");
    }

    #[test]
    fn three_d_projects_on_xz_near_over_far() {
        let mut f = sample_2d();
        f.dim = 3;
        f.box_lo = [0.0, 0.0, 0.0];
        f.box_hi = [10.0, 10.0, 8.0];
        // Two particles at the same (x, z); the nearer (smaller y) is slow.
        f.pos = vec![[5.0, 1.0, 4.0], [5.0, 9.0, 4.0], [2.0, 5.0, 7.5]];
        f.vel = vec![[0.0; 3], [3.0, 0.0, 0.0], [0.0; 3]];
        let img = render_particles(
            &f,
            &PictureOptions {
                width: 400,
                ..Default::default()
            },
        );
        assert_eq!(at(&img, [5.0, 4.0]), viridis(0.0));
        // Particles reach the top: the whole box is shown, (8 + 2·0.2) / (10 + 2·0.2) · 400.
        assert_eq!(img.height, 323);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let empty = Frame {
            dim: 2,
            ..Default::default()
        };
        let img = render_particles(
            &empty,
            &PictureOptions {
                width: 0,
                ..Default::default()
            },
        );
        assert!(img.width >= 1 && img.height >= 1);
        let mut one = sample_2d();
        one.box_lo = [f64::NAN; 3];
        one.box_hi = [f64::INFINITY; 3];
        one.pos[1] = [f64::NAN; 3];
        let img = render_particles(&one, &PictureOptions::default());
        assert!(img.height >= 1 && img.height <= MAX_HEIGHT);
        let mut img2 = img.clone();
        draw_arrows(
            &mut img2,
            &[[0.0, 0.0], [f64::NAN, 1.0]],
            &[[0.0, 0.0], [1.0, 1.0]],
            [255, 0, 0],
        );
    }

    #[test]
    fn arrows_and_png_file() {
        let f = sample_2d();
        let mut img = render_particles(
            &f,
            &PictureOptions {
                width: 300,
                ..Default::default()
            },
        );
        draw_arrows(&mut img, &[[2.0, 3.0]], &[[8.0, 3.0]], [255, 0, 0]);
        let mid = at(&img, [5.0, 3.0]);
        assert!(mid[0] == 255 && mid[1] < 100 && mid[2] < 100, "{mid:?}");
        // Just behind the tip, the head's barbs sit above and below the shaft.
        let tip = img.view.to_pixel([8.0, 3.0]);
        let reddish = |p: [u8; 3]| p[0] == 255 && p[1] < 160;
        let red_rows = (0..img.height)
            .filter(|&y| reddish(img.pixel(tip[0] as u32 - 4, y)))
            .count();
        assert!(red_rows >= 3, "{red_rows}");
        let dir = scratch_dir("png");
        let path = dir.join("pic.png");
        img.save_png(&path).unwrap();
        let dec = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (img.width, img.height));
        assert_eq!(&buf[..info.buffer_size()], &img.rgb[..]);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    }

    #[test]
    fn colour_map_ends() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(2.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }
}
