//! The band under a picture: the time on the left, a scale bar in the
//! middle, the colour legend on the right; and the grains' colours by kind
//! and by id.

use super::text::{draw_text, fill_rect, nice_length, sig3, text_width, GLYPH};
use crate::io::{viridis, Image};

/// Height of the band in pixels per unit of text scale.
pub const BAND_ROWS: u32 = 14;

const INK: [u8; 3] = [0, 0, 0];

/// What the colours of the grains mean.
#[derive(Clone, Debug)]
pub enum Legend<'a> {
    /// A continuous quantity from `lo` to `hi` on the viridis map.
    Scale {
        name: &'a str,
        lo: f64,
        hi: f64,
        unit: &'a str,
    },
    /// One swatch per kind.
    Kinds(&'a [u32]),
    /// A sentence (categorical colours with no key).
    Note(&'a str),
}

/// How much of the band to draw, from the full layout down to the legend
/// alone: the first that fits the picture's width is drawn.
#[derive(Clone, Copy, Debug)]
struct Fit {
    /// The scale bar's target length is width / this (0: no scale bar).
    scale_div: u32,
    /// The colour bar's length is width / this (at least 20 px).
    bar_div: u32,
    /// Glyphs between the parts.
    gap: u32,
    /// The time's long label (else its short one; `None`: no time).
    time: Option<bool>,
    /// The colour scale's name before its lower end.
    name: bool,
}

const FITS: [Fit; 6] = [
    Fit {
        scale_div: 6,
        bar_div: 6,
        gap: 2,
        time: Some(true),
        name: true,
    },
    Fit {
        scale_div: 12,
        bar_div: 12,
        gap: 1,
        time: Some(true),
        name: true,
    },
    Fit {
        scale_div: 12,
        bar_div: 12,
        gap: 1,
        time: Some(false),
        name: true,
    },
    Fit {
        scale_div: 0,
        bar_div: 12,
        gap: 1,
        time: Some(false),
        name: true,
    },
    Fit {
        scale_div: 0,
        bar_div: 12,
        gap: 1,
        time: None,
        name: true,
    },
    Fit {
        scale_div: 0,
        bar_div: 12,
        gap: 1,
        time: None,
        name: false,
    },
];

/// Where the parts of the band go under one [`Fit`].
struct Placed {
    time: Option<String>,
    /// The scale bar's left end, length in pixels and label.
    scale: Option<(i64, u32, String)>,
    /// The legend's left end, its colour scale's lower label and its
    /// colour bar's length.
    legend_x: i64,
    left: String,
    bar: i64,
    /// The right end of the last thing drawn.
    end: i64,
}

/// The parts of the band laid out under `fit` in an image `width` pixels
/// wide at `world_scale` pixels per metre.
fn place(
    fit: Fit,
    width: u32,
    world_scale: f64,
    s: u32,
    [long, short]: [&str; 2],
    legend: &Legend,
) -> Placed {
    let glyph = (GLYPH * s) as i64;
    let gap = fit.gap as i64 * glyph;
    let time = fit.time.map(|l| {
        if l {
            long.to_string()
        } else {
            short.to_string()
        }
    });
    let mut x = glyph / 2;
    if let Some(time) = &time {
        x += text_width(time, s) as i64 + gap;
    }
    let mut scale = None;
    if fit.scale_div > 0 && world_scale.is_finite() && world_scale > 0.0 {
        let (len, label) = nice_length(width as f64 / fit.scale_div as f64 / world_scale);
        let px = (len * world_scale).round() as u32;
        let at = x;
        x += px as i64 + glyph / 2 + text_width(&label, s) as i64 + gap;
        scale = Some((at, px, label));
    }
    let bar = (width as i64 / fit.bar_div as i64).max(20);
    let mut left = String::new();
    let (legend_x, extent) = match legend {
        Legend::Scale { name, lo, hi, unit } => {
            left = if fit.name {
                format!("{name} {}", sig3(*lo))
            } else {
                sig3(*lo)
            };
            let left = text_width(&left, s) as i64;
            let right = text_width(&format!("{} {unit}", sig3(*hi)), s) as i64;
            let need = left + bar + right;
            // Right-aligned when there is room, else after the scale bar.
            let margin = if fit.gap == 2 {
                2 * glyph
            } else {
                glyph / 2 + glyph
            };
            ((width as i64 - need - margin).max(x), need + glyph)
        }
        Legend::Kinds(kinds) => {
            let mut w = text_width("kind ", s) as i64;
            for &k in kinds.iter().take(8) {
                w += glyph + 2 * s as i64 + text_width(&k.to_string(), s) as i64 + glyph;
            }
            (x, w - glyph)
        }
        Legend::Note(note) => (x, text_width(note, s) as i64),
    };
    Placed {
        time,
        scale,
        legend_x,
        left,
        bar,
        end: legend_x + extent,
    }
}

/// Draws the band whose top is pixel row `top`: the time `t` (s), a scale
/// bar for the image's world-to-pixel scale, and `legend`. On a narrow
/// picture the bars shorten and then the scale bar and the time give way,
/// so that what is drawn is never cut at the right edge.
pub fn draw_band(img: &mut Image, top: u32, s: u32, t: f64, legend: &Legend) {
    let long = format!("t = {} s", sig3(t));
    let short = format!("{} s", sig3(t));
    draw_band_labelled(img, top, s, [&long, &short], legend);
}

/// [`draw_band`] with the time's label given, long and short (say, a time
/// span).
pub fn draw_band_labelled(img: &mut Image, top: u32, s: u32, time: [&str; 2], legend: &Legend) {
    fill_rect(
        img,
        0,
        top as i64,
        img.width,
        BAND_ROWS * s,
        [255, 255, 255],
    );
    let y = top as i64 + 3 * s as i64;
    let glyph = (GLYPH * s) as i64;
    let scale = img.view.scale;
    let mut placed = place(FITS[0], img.width, scale, s, time, legend);
    for fit in &FITS[1..] {
        if placed.end <= img.width as i64 {
            break;
        }
        placed = place(*fit, img.width, scale, s, time, legend);
    }
    if let Some(time) = &placed.time {
        draw_text(img, glyph / 2, y, s, time, INK);
    }
    if let Some((x, px, label)) = &placed.scale {
        let (x, px) = (*x, *px);
        let mid = y + glyph / 2;
        fill_rect(img, x, mid - s as i64 / 2, px, s.max(1), INK);
        fill_rect(img, x, y, s.max(1), GLYPH * s, INK);
        fill_rect(img, x + px as i64 - s as i64, y, s.max(1), GLYPH * s, INK);
        draw_text(img, x + px as i64 + glyph / 2, y, s, label, INK);
    }
    let x = placed.legend_x;
    match legend {
        Legend::Scale { hi, unit, .. } => {
            let left = &placed.left;
            let right = format!("{} {unit}", sig3(*hi));
            let bar = placed.bar;
            draw_text(img, x, y, s, left, INK);
            let bx = x + text_width(left, s) as i64 + glyph / 2;
            for k in 0..bar {
                let c = viridis(k as f64 / (bar - 1) as f64);
                fill_rect(img, bx + k, y, 1, GLYPH * s, c);
            }
            draw_text(img, bx + bar + glyph / 2, y, s, &right, INK);
        }
        Legend::Kinds(kinds) => {
            let mut x0 = x;
            draw_text(img, x0, y, s, "kind", INK);
            x0 += text_width("kind ", s) as i64;
            for &k in kinds.iter().take(8) {
                fill_rect(img, x0, y, GLYPH * s, GLYPH * s, kind_colour(k));
                x0 += glyph + s as i64 * 2;
                let label = k.to_string();
                draw_text(img, x0, y, s, &label, INK);
                x0 += text_width(&label, s) as i64 + glyph;
            }
        }
        Legend::Note(note) => draw_text(img, x, y, s, note, INK),
    }
}

/// Colours for kinds 1, 2, … (kind 0 and beyond the list wrap around).
const KIND_COLOURS: [[u8; 3]; 8] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
];

/// The colour of the grains of `kind`.
pub fn kind_colour(kind: u32) -> [u8; 3] {
    KIND_COLOURS[(kind as usize + KIND_COLOURS.len() - 1) % KIND_COLOURS.len()]
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::View;

    #[test]
    fn the_scale_bar_is_as_long_as_its_label_says() {
        // 1000 px for 0.02 m: 50 000 px/m; a sixth of the width is 3.3 mm,
        // so the bar is 2 mm = 100 px long.
        let view = View {
            origin: [0.0, 0.0],
            scale: 50_000.0,
            height: 100,
        };
        let mut img = Image::new(1000, 100, view);
        draw_band(
            &mut img,
            72,
            2,
            0.5,
            &Legend::Scale {
                name: "speed",
                lo: 0.0,
                hi: 1.0,
                unit: "m/s",
            },
        );
        // The bar's middle row: the longest run of black pixels.
        let row = 72 + 6 + 8;
        let mut best = 0;
        let mut run = 0;
        for x in 0..1000 {
            if img.pixel(x, row) == INK {
                run += 1;
                best = best.max(run);
            } else {
                run = 0;
            }
        }
        assert_eq!(best, 100);
        // The colour bar ends at the top of the map.
        let yellow = (0..1000).any(|x| img.pixel(x, row) == viridis(1.0));
        assert!(yellow);
    }

    /// On narrow pictures (a movie at --width 480, say) everything drawn
    /// stays inside: no ink in the band's last columns, and the colour
    /// bar's top end (the legend's last part but its label) is still there.
    #[test]
    fn a_narrow_band_keeps_its_legend_inside() {
        for width in [200, 240, 320, 480, 640, 1000] {
            let view = View {
                origin: [0.0, 0.0],
                // A scale bar of 52 px at 480: the old layout's cut then
                // falls inside a glyph of the last number (ink at 478).
                scale: width as f64 / 0.0093,
                height: 40,
            };
            let s = if width >= 700 { 2 } else { 1 };
            let mut img = Image::new(width, 40 + BAND_ROWS * s, view);
            let legend = Legend::Scale {
                name: "height",
                lo: -1.2345e-4,
                hi: 1.2345e-2,
                unit: "m",
            };
            draw_band(&mut img, 40, s, 1.2345e-3, &legend);
            let band = 40..img.height;
            for x in width - 2..width {
                for y in band.clone() {
                    assert_eq!(
                        img.pixel(x, y),
                        [255; 3],
                        "ink at ({x}, {y}), width {width}"
                    );
                }
            }
            let yellow = band
                .clone()
                .any(|y| (0..width).any(|x| img.pixel(x, y) == viridis(1.0)));
            assert!(yellow, "no colour bar at width {width}");
        }
    }
}
