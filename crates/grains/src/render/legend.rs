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

/// Draws the band whose top is pixel row `top`: the time `t` (s), a scale
/// bar for the image's world-to-pixel scale, and `legend`.
pub fn draw_band(img: &mut Image, top: u32, s: u32, t: f64, legend: &Legend) {
    fill_rect(
        img,
        0,
        top as i64,
        img.width,
        BAND_ROWS * s,
        [255, 255, 255],
    );
    let y = top as i64 + 3 * s as i64;
    let gap = (2 * GLYPH * s) as i64;
    let time = format!("t = {} s", sig3(t));
    draw_text(img, (GLYPH * s) as i64 / 2, y, s, &time, INK);
    // Scale bar: about a sixth of the width.
    let mut x = (GLYPH * s) as i64 / 2 + text_width(&time, s) as i64 + gap;
    let scale = img.view.scale;
    if scale.is_finite() && scale > 0.0 {
        let (len, label) = nice_length(img.width as f64 / 6.0 / scale);
        let px = (len * scale).round() as u32;
        let mid = y + (GLYPH * s) as i64 / 2;
        fill_rect(img, x, mid - s as i64 / 2, px, s.max(1), INK);
        fill_rect(img, x, y, s.max(1), GLYPH * s, INK);
        fill_rect(img, x + px as i64 - s as i64, y, s.max(1), GLYPH * s, INK);
        x += px as i64 + (GLYPH * s) as i64 / 2;
        draw_text(img, x, y, s, &label, INK);
        x += text_width(&label, s) as i64 + gap;
    }
    match legend {
        Legend::Scale { name, lo, hi, unit } => {
            let left = format!("{name} {}", sig3(*lo));
            let right = format!("{} {unit}", sig3(*hi));
            let bar = (img.width as i64 / 6).max(20);
            let need = text_width(&left, s) as i64 + bar + text_width(&right, s) as i64;
            // Right-aligned when there is room, else after the scale bar.
            let x0 = (img.width as i64 - need - 2 * (GLYPH * s) as i64).max(x);
            draw_text(img, x0, y, s, &left, INK);
            let bx = x0 + text_width(&left, s) as i64 + (GLYPH * s) as i64 / 2;
            for k in 0..bar {
                let c = viridis(k as f64 / (bar - 1) as f64);
                fill_rect(img, bx + k, y, 1, GLYPH * s, c);
            }
            draw_text(img, bx + bar + (GLYPH * s) as i64 / 2, y, s, &right, INK);
        }
        Legend::Kinds(kinds) => {
            let mut x0 = x;
            draw_text(img, x0, y, s, "kind", INK);
            x0 += text_width("kind ", s) as i64;
            for &k in kinds.iter().take(8) {
                fill_rect(img, x0, y, GLYPH * s, GLYPH * s, kind_colour(k));
                x0 += (GLYPH * s) as i64 + s as i64 * 2;
                let label = k.to_string();
                draw_text(img, x0, y, s, &label, INK);
                x0 += text_width(&label, s) as i64 + (GLYPH * s) as i64;
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
}
