//! A frame as a picture that explains itself: grains to scale (disks in 2D,
//! shaded spheres back to front in 3D, points when they are smaller than a
//! pixel), the box and the walls in their place at the frame's time, and a
//! band below with the time, a scale bar and the colour legend.
//!
//! A [`Painter`] fixes the drawn rectangle and the colour range once, so
//! the frames of a movie share them.

use super::legend::{draw_band, id_colour, kind_colour, Legend, BAND_ROWS};
use super::wires::Wire;
use crate::io::{viridis, world_rect_of, Frame, Image, View};

/// What the grains' colour shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorBy {
    Speed,
    /// Height along the vertical axis (y in 2D, z in 3D).
    Height,
    /// A colour per grain id (to follow grains).
    Id,
    /// A colour per grain kind (the `type` of the frames).
    Kind,
}

impl ColorBy {
    pub const NAMES: &'static str = "speed, height, id, kind, material";

    /// Parses a `--color` value; `material` is the grain's kind (its species).
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "speed" => ColorBy::Speed,
            "height" => ColorBy::Height,
            "id" => ColorBy::Id,
            "kind" | "material" => ColorBy::Kind,
            _ => return None,
        })
    }
}

/// The axis a 3D picture looks along (2D pictures always show x–y).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewAxis {
    X,
    Y,
    Z,
}

impl ViewAxis {
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "x" => ViewAxis::X,
            "y" => ViewAxis::Y,
            "z" => ViewAxis::Z,
            _ => return None,
        })
    }
}

/// How world axes map onto the picture: axis `h` to the right, `v` up, and
/// the depth axis (3D) along which grains are drawn far to near.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    pub h: usize,
    pub v: usize,
    /// (axis, far side is the large coordinate).
    pub depth: Option<(usize, bool)>,
}

impl Projection {
    /// The camera for `dim` looking along `view`: along +y from -y (x right,
    /// z up), along -x from +x (y right, z up), down from +z (x right, y up).
    pub fn new(dim: usize, view: ViewAxis) -> Self {
        if dim != 3 {
            return Projection {
                h: 0,
                v: 1,
                depth: None,
            };
        }
        match view {
            ViewAxis::Y => Projection {
                h: 0,
                v: 2,
                depth: Some((1, true)),
            },
            ViewAxis::X => Projection {
                h: 1,
                v: 2,
                depth: Some((0, false)),
            },
            ViewAxis::Z => Projection {
                h: 0,
                v: 1,
                depth: Some((2, false)),
            },
        }
    }

    pub fn pair(&self, p: [f64; 3]) -> [f64; 2] {
        [p[self.h], p[self.v]]
    }
}

/// Choices for a picture.
#[derive(Clone, Debug, PartialEq)]
pub struct StillOptions {
    /// Width in pixels (the height follows the drawn rectangle).
    pub width: u32,
    pub color: ColorBy,
    pub view: ViewAxis,
    /// Top of the speed scale; None: the fastest grain of the frames given.
    pub max_speed: Option<f64>,
}

impl Default for StillOptions {
    fn default() -> Self {
        StillOptions {
            width: 1000,
            color: ColorBy::Speed,
            view: ViewAxis::Y,
            max_speed: None,
        }
    }
}

const BOX_EDGE: [u8; 3] = [60, 60, 60];
const WALL: [u8; 3] = [40, 40, 40];
const OBSTACLE: [u8; 3] = [120, 120, 120];
/// Draws frames with one rectangle, one colour range and one size.
#[derive(Clone, Debug)]
pub struct Painter {
    pub proj: Projection,
    /// Shown world rectangle [h0, h1, v0, v1] (padded).
    pub rect: [f64; 4],
    pub width: u32,
    /// Pixel height of the world part (the band comes below).
    pub world_height: u32,
    pub scale: f64,
    color: ColorBy,
    /// The colour scale's ends (speed or height).
    range: (f64, f64),
    text_scale: u32,
    kinds: Vec<u32>,
}

const MAX_HEIGHT: u32 = 16384;

impl Painter {
    /// A painter for `frames` (all of a movie, or a sample of them): the
    /// rectangle holds them all, the colour scale spans them.
    pub fn new(frames: &[&Frame], opts: &StillOptions) -> Self {
        let first = frames.first().copied();
        let dim = first.map_or(2, |f| f.dim);
        let proj = Projection::new(dim, opts.view);
        let [h0, h1, v0, v1] = extent(frames, proj);
        let pad = 0.02 * (h1 - h0).max(v1 - v0);
        let rect = [h0 - pad, h1 + pad, v0 - pad, v1 + pad];
        let width = opts.width.max(16);
        let scale = width as f64 / (rect[1] - rect[0]);
        let world_height = ((rect[3] - rect[2]) * scale)
            .round()
            .clamp(1.0, MAX_HEIGHT as f64) as u32;
        let vert = if dim == 3 { 2 } else { 1 };
        let range = match opts.color {
            ColorBy::Speed => {
                let top = opts.max_speed.unwrap_or_else(|| {
                    frames
                        .iter()
                        .flat_map(|f| (0..f.len()).map(|i| f.speed(i)))
                        .filter(|s| s.is_finite())
                        .fold(0.0, f64::max)
                });
                (0.0, top)
            }
            ColorBy::Height => frames
                .iter()
                .flat_map(|f| f.pos.iter().map(|p| p[vert]))
                .filter(|x| x.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(x), b.max(x))
                }),
            _ => (0.0, 1.0),
        };
        let mut kinds: Vec<u32> = frames.iter().flat_map(|f| f.kind.iter().copied()).collect();
        kinds.sort_unstable();
        kinds.dedup();
        Painter {
            proj,
            rect,
            width,
            world_height,
            scale,
            color: opts.color,
            range,
            text_scale: if width >= 700 { 2 } else { 1 },
            kinds,
        }
    }

    /// Pixel height of the whole picture.
    pub fn height(&self) -> u32 {
        self.world_height + BAND_ROWS * self.text_scale
    }

    /// A blank picture with this painter's mapping (world part on top).
    pub fn canvas(&self) -> Image {
        let band = (BAND_ROWS * self.text_scale) as f64;
        let height = self.height();
        Image::new(
            self.width,
            height,
            View {
                origin: [self.rect[0], self.rect[2] - band / self.scale],
                scale: self.scale,
                height,
            },
        )
    }

    /// The colour of grain `i` of `frame`.
    fn colour(&self, frame: &Frame, i: usize) -> [u8; 3] {
        let (lo, hi) = self.range;
        let t = |x: f64| {
            if hi > lo {
                (x - lo) / (hi - lo)
            } else {
                0.0
            }
        };
        match self.color {
            ColorBy::Speed => viridis(t(frame.speed(i))),
            ColorBy::Height => viridis(t(frame.pos[i][if frame.dim == 3 { 2 } else { 1 }])),
            ColorBy::Id => id_colour(frame.id[i]),
            ColorBy::Kind => kind_colour(frame.kind[i]),
        }
    }

    /// The frame drawn with `wires` (its walls at its time).
    pub fn paint(&self, frame: &Frame, wires: &[Wire]) -> Image {
        let mut img = self.canvas();
        img.draw_box(frame, (self.proj.h, self.proj.v), 1.0, BOX_EDGE);
        self.draw_grains(&mut img, frame);
        self.draw_wires(&mut img, wires);
        let legend = match self.color {
            ColorBy::Speed => Legend::Scale {
                name: "speed",
                lo: self.range.0,
                hi: self.range.1,
                unit: "m/s",
            },
            ColorBy::Height => Legend::Scale {
                name: "height",
                lo: self.range.0,
                hi: self.range.1,
                unit: "m",
            },
            ColorBy::Id => Legend::Note("colour: grain id"),
            ColorBy::Kind => Legend::Kinds(&self.kinds),
        };
        draw_band(
            &mut img,
            self.world_height,
            self.text_scale,
            frame.time,
            &legend,
        );
        img
    }

    fn draw_grains(&self, img: &mut Image, frame: &Frame) {
        let mut order: Vec<usize> = (0..frame.len()).collect();
        let Some((axis, far_large)) = self.proj.depth else {
            for i in order {
                let c = img.view.to_pixel(self.proj.pair(frame.pos[i]));
                let r = frame.radius[i] * self.scale;
                let colour = self.colour(frame, i);
                if r < 1.0 {
                    // Smaller than a pixel (a DSMC gas): a point.
                    fill_point(img, c, colour);
                } else {
                    img.fill_disk(c, r, colour, true);
                }
            }
            return;
        };
        // Near to far, each sphere under those already drawn: a pixel that is
        // covered is skipped at once, so the hidden bulk of a deep packing
        // costs a test per pixel, not a shading.
        order.sort_unstable_by(|&a, &b| {
            let c = frame.pos[a][axis].total_cmp(&frame.pos[b][axis]);
            if far_large {
                c
            } else {
                c.reverse()
            }
        });
        let mut layer = Layer::new(img.width, img.height);
        for i in order {
            let c = img.view.to_pixel(self.proj.pair(frame.pos[i]));
            let r = (frame.radius[i] * self.scale).max(0.5);
            layer.sphere(c, r, self.colour(frame, i));
        }
        layer.over(img);
    }

    fn draw_wires(&self, img: &mut Image, wires: &[Wire]) {
        let width = (self.width as f64 / 400.0).clamp(1.5, 4.0);
        for w in wires {
            match w {
                Wire::Line { points } => {
                    for pair in points.windows(2) {
                        let a = img.view.to_pixel(self.proj.pair(pair[0]));
                        let b = img.view.to_pixel(self.proj.pair(pair[1]));
                        img.draw_segment(a, b, width, WALL);
                    }
                }
                Wire::Ball { center, radius } => {
                    let c = img.view.to_pixel(self.proj.pair(*center));
                    img.fill_disk(c, radius * self.scale, OBSTACLE, true);
                }
            }
        }
    }
}

/// The rectangle the frames need, as `io::world_rect` chooses it for one;
/// the top is cut to the grains only along the axis gravity pulls.
fn extent(frames: &[&Frame], proj: Projection) -> [f64; 4] {
    let gravity_axis = frames.first().map_or(1, |f| f.vertical()) == proj.v;
    world_rect_of(frames, (proj.h, proj.v), gravity_axis)
}

/// One pixel (a grain smaller than a pixel).
fn fill_point(img: &mut Image, c: [f64; 2], colour: [u8; 3]) {
    if !(c[0] >= 0.0 && c[1] >= 0.0) {
        return;
    }
    let (x, y) = (c[0] as u32, c[1] as u32);
    if x < img.width && y < img.height {
        let k = (y as usize * img.width as usize + x as usize) * 3;
        img.rgb[k..k + 3].copy_from_slice(&colour);
    }
}

/// Spheres composited front to back ("under"): premultiplied colour and
/// coverage per pixel, laid over the picture at the end.
struct Layer {
    width: usize,
    height: usize,
    rgb: Vec<f32>,
    alpha: Vec<f32>,
    /// Per tile of TILE × TILE pixels, how many are covered: a sphere whose
    /// box lies in full tiles is skipped without looking at its pixels.
    covered: Vec<u16>,
    tiles_x: usize,
}

const TILE: usize = 8;
/// Coverage from which a pixel counts as covered.
const OPAQUE: f32 = 0.998;

impl Layer {
    fn new(width: u32, height: u32) -> Self {
        let (w, h) = (width as usize, height as usize);
        let tiles_x = w.div_ceil(TILE);
        Layer {
            width: w,
            height: h,
            rgb: vec![0.0; 3 * w * h],
            alpha: vec![0.0; w * h],
            covered: vec![0; tiles_x * h.div_ceil(TILE)],
            tiles_x,
        }
    }

    /// Whether every pixel of tile (tx, ty) is covered.
    fn tile_full(&self, tx: usize, ty: usize) -> bool {
        let area = TILE.min(self.width - tx * TILE) * TILE.min(self.height - ty * TILE);
        self.covered[ty * self.tiles_x + tx] as usize == area
    }

    /// A sphere lit from the upper left of the viewer (a diffuse term), with
    /// a soft edge one pixel wide, behind what is already drawn.
    fn sphere(&mut self, c: [f64; 2], r: f64, colour: [u8; 3]) {
        if !(c[0].is_finite() && c[1].is_finite() && r.is_finite()) {
            return;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let x0 = ((c[0] - r - 1.0).floor() as i64).clamp(0, w) as usize;
        let x1 = ((c[0] + r + 1.0).ceil() as i64).clamp(0, w) as usize;
        let y0 = ((c[1] - r - 1.0).floor() as i64).clamp(0, h) as usize;
        let y1 = ((c[1] + r + 1.0).ceil() as i64).clamp(0, h) as usize;
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        let hidden = (y0 / TILE..=(y1 - 1) / TILE)
            .all(|ty| (x0 / TILE..=(x1 - 1) / TILE).all(|tx| self.tile_full(tx, ty)));
        if hidden {
            return;
        }
        let inv = (1.0 / r) as f32;
        let (cx, cy, r) = (c[0] as f32, c[1] as f32, r as f32);
        let outer2 = (r + 0.5) * (r + 0.5);
        // Light direction (toward the viewer, up and left), unit length.
        let (lx, ly, lz) = (-0.40f32, -0.45, 0.80);
        let col = colour.map(|x| x as f32);
        for y in y0..y1 {
            let dy = y as f32 + 0.5 - cy;
            let row = y * self.width;
            for x in x0..x1 {
                let k = row + x;
                let a = self.alpha[k];
                if a >= OPAQUE {
                    continue;
                }
                let dx = x as f32 + 0.5 - cx;
                let d2 = dx * dx + dy * dy;
                if d2 >= outer2 {
                    continue;
                }
                let (nx, ny) = (dx * inv, dy * inv);
                let nz = (1.0 - nx * nx - ny * ny).max(0.0).sqrt();
                let light = 0.35 + 0.65 * (nx * lx + ny * ly + nz * lz).max(0.0);
                let cover = (r + 0.5 - d2.sqrt()).clamp(0.0, 1.0);
                let t = (1.0 - a) * cover;
                for (acc, c) in self.rgb[3 * k..3 * k + 3].iter_mut().zip(col) {
                    *acc += t * (c * light).min(255.0);
                }
                self.alpha[k] = a + t;
                if a + t >= OPAQUE {
                    self.covered[(y / TILE) * self.tiles_x + x / TILE] += 1;
                }
            }
        }
    }

    /// Lays the spheres over `img` (what it holds shows where they do not cover).
    fn over(&self, img: &mut Image) {
        for (k, &a) in self.alpha.iter().enumerate() {
            if a <= 0.0 {
                continue;
            }
            for ch in 0..3 {
                let old = img.rgb[3 * k + ch] as f32;
                img.rgb[3 * k + ch] =
                    (self.rgb[3 * k + ch] + (1.0 - a) * old).round().min(255.0) as u8;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::frame::tests::sample_2d;
    use crate::io::picture::tests::at;

    #[test]
    fn grains_walls_and_band_land_in_place() {
        let f = sample_2d();
        let painter = Painter::new(&[&f], &StillOptions::default());
        let floor = Wire::Line {
            points: vec![[0.0, 2.5, 0.0], [10.0, 2.5, 0.0]],
        };
        let img = painter.paint(&f, &[floor]);
        assert_eq!(img.width, 1000);
        assert_eq!(img.height, painter.world_height + BAND_ROWS * 2);
        // The fastest grain at the top of the scale, the resting one at the bottom.
        assert_eq!(at(&img, [7.0, 4.0]), viridis(1.0));
        assert_eq!(at(&img, [3.25, 1.5]), viridis(0.0));
        // The wall line at y = 2.5, away from grains.
        assert_eq!(at(&img, [5.5, 2.5]), WALL);
        assert_eq!(at(&img, [5.5, 3.0]), [255, 255, 255]);
        // The band holds dark text pixels below the world part.
        let band_dark = (painter.world_height..img.height)
            .flat_map(|y| (0..img.width).map(move |x| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y) == [0, 0, 0])
            .count();
        assert!(band_dark > 50, "{band_dark}");
    }

    #[test]
    fn views_of_a_3d_frame_put_the_near_grain_on_top() {
        let mut f = sample_2d();
        f.dim = 3;
        f.box_lo = [0.0; 3];
        f.box_hi = [10.0, 10.0, 8.0];
        f.pos = vec![[5.0, 1.0, 4.0], [5.0, 9.0, 4.0], [2.0, 5.0, 7.5]];
        f.vel = vec![[0.0; 3], [3.0, 0.0, 0.0], [0.0; 3]];
        f.kind = vec![1, 2, 2];
        let opts = StillOptions {
            width: 400,
            color: ColorBy::Kind,
            ..Default::default()
        };
        let img = Painter::new(&[&f], &opts).paint(&f, &[]);
        // Looking along +y, grain 0 (y = 1) is in front: its centre is lit,
        // so it is kind 1's colour scaled by the light, not kind 2's.
        let px = at(&img, [5.0, 4.0]);
        let blue = kind_colour(1);
        assert!(px[2] > px[0] && px[2] >= blue[2] / 2, "{px:?}");
        // Looking down z, grain 2 (z = 7.5) is seen at (x, y) = (2, 5).
        let top = Painter::new(
            &[&f],
            &StillOptions {
                view: ViewAxis::Z,
                ..opts
            },
        );
        assert_eq!(top.proj.depth, Some((2, false)));
        let img = top.paint(&f, &[]);
        let px = at(&img, [2.0, 5.0]);
        let orange = kind_colour(2);
        assert!(px[0] > px[2] && px[0] >= orange[0] / 2, "{px:?}");
    }
}
