//! Line and point plots as PNG, in pure Rust on the io::picture [`Image`]:
//! a framed axis box, ticks with labels in a tiny built-in digit font, and
//! series drawn as points joined by lines. Used for profiles and sweeps.

use crate::error::Result;
use crate::io::picture::{Image, View};
use std::path::Path;

/// One series: points (x, y) drawn in order, joined by lines if `lines`;
/// `errors`, when given, holds one half-height of a vertical error bar per
/// point (e.g. the standard error of a mean over seeds).
#[derive(Clone, Debug)]
pub struct Series {
    pub points: Vec<[f64; 2]>,
    pub colour: [u8; 3],
    pub lines: bool,
    pub errors: Option<Vec<f64>>,
}

/// Colours for successive series.
pub const PALETTE: [[u8; 3]; 6] = [
    [31, 90, 180],
    [200, 40, 40],
    [40, 150, 60],
    [150, 60, 170],
    [230, 140, 20],
    [60, 60, 60],
];

/// 3×5 glyphs as rows of 3 bits: digits, '.', '-', '+', a small 'e' for
/// exponents, capital letters (other lower-case letters are drawn as
/// capitals) and a little punctuation for axis titles.
fn glyph(c: char) -> Option<[u8; 5]> {
    let c = if c.is_ascii_lowercase() && c != 'e' {
        c.to_ascii_uppercase()
    } else {
        c
    };
    Some(match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        'e' => [0, 7, 7, 4, 7],
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [7, 4, 4, 4, 7],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 7, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [7, 4, 5, 5, 7],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 7],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [7, 5, 5, 5, 7],
        'P' => [7, 5, 7, 4, 4],
        'Q' => [7, 5, 5, 7, 1],
        'R' => [6, 5, 6, 5, 5],
        'S' => [7, 4, 7, 1, 7],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '_' => [0, 0, 0, 0, 7],
        '(' => [1, 2, 2, 2, 1],
        ')' => [4, 2, 2, 2, 4],
        '[' => [3, 2, 2, 2, 3],
        ']' => [6, 2, 2, 2, 6],
        '/' => [1, 1, 2, 4, 4],
        ':' => [0, 2, 0, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        ',' => [0, 0, 0, 2, 4],
        _ => return None,
    })
}

/// Draws `text` with its top-left corner at pixel (x, y), `px` pixels per dot.
pub fn draw_text(img: &mut Image, x: f64, y: f64, text: &str, px: f64, colour: [u8; 3]) {
    let mut cx = x;
    for c in text.chars() {
        if let Some(rows) = glyph(c) {
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..3 {
                    if bits & (4 >> col) != 0 {
                        let x0 = cx + col as f64 * px;
                        let y0 = y + r as f64 * px;
                        for yy in 0..px.ceil() as i64 {
                            for xx in 0..px.ceil() as i64 {
                                let (xi, yi) = (x0 as i64 + xx, y0 as i64 + yy);
                                if xi >= 0
                                    && yi >= 0
                                    && (xi as u32) < img.width
                                    && (yi as u32) < img.height
                                {
                                    let k = (yi as usize * img.width as usize + xi as usize) * 3;
                                    img.rgb[k..k + 3].copy_from_slice(&colour);
                                }
                            }
                        }
                    }
                }
            }
        }
        cx += 4.0 * px;
    }
}

/// Width in pixels of `text` drawn at `px` pixels per dot.
pub fn text_width(text: &str, px: f64) -> f64 {
    (4 * text.chars().count()) as f64 * px - px
}

/// "Nice" tick positions covering [lo, hi], about `n` of them.
pub fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return vec![lo];
    }
    let raw = (hi - lo) / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A short label for a tick value.
pub fn label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.1e}");
        return s.replace(".0e", "e");
    }
    let mut s = format!("{v:.4}");
    while s.contains('.') && (s.ends_with('0') || s.ends_with('.')) {
        s.pop();
    }
    s
}

fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 * (hi.abs() + lo.abs()).max(1e-300) {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Axis titles: `x` under the horizontal axis, `y` above the frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Titles<'a> {
    pub x: &'a str,
    pub y: &'a str,
}

/// Draws the series on framed axes; `zero_line` adds y = 0 when in range.
pub fn plot(series: &[Series], width: u32, height: u32, zero_line: bool, titles: Titles) -> Image {
    let (x0, x1) = range(series.iter().flat_map(|s| s.points.iter().map(|p| p[0])));
    let (y0, y1) = range(series.iter().flat_map(|s| {
        s.points.iter().enumerate().flat_map(move |(i, p)| {
            let e = s.errors.as_ref().map_or(0.0, |e| e[i]);
            [p[1] - e, p[1] + e]
        })
    }));
    let (ml, mr, mt, mb) = (80.0, 20.0, 34.0, 60.0);
    let (w, h) = (width as f64, height as f64);
    let sx = (w - ml - mr) / (x1 - x0);
    let sy = (h - mt - mb) / (y1 - y0);
    let px = |p: [f64; 2]| [ml + (p[0] - x0) * sx, h - mb - (p[1] - y0) * sy];
    let mut img = Image::new(
        width,
        height,
        View {
            origin: [0.0, 0.0],
            scale: 1.0,
            height,
        },
    );
    let dark = [40, 40, 40];
    let grid = [225, 225, 225];
    let font = 2.0;
    for t in ticks(x0, x1, 6) {
        let a = px([t, y0]);
        img.draw_segment(a, px([t, y1]), 1.0, grid);
        img.draw_segment(a, [a[0], a[1] + 5.0], 1.0, dark);
        let s = label(t);
        draw_text(
            &mut img,
            a[0] - 0.5 * text_width(&s, font),
            a[1] + 9.0,
            &s,
            font,
            dark,
        );
    }
    for t in ticks(y0, y1, 6) {
        let a = px([x0, t]);
        img.draw_segment(a, px([x1, t]), 1.0, grid);
        img.draw_segment(a, [a[0] - 5.0, a[1]], 1.0, dark);
        let s = label(t);
        draw_text(
            &mut img,
            a[0] - 9.0 - text_width(&s, font),
            a[1] - 5.0,
            &s,
            font,
            dark,
        );
    }
    if zero_line && y0 < 0.0 && y1 > 0.0 {
        img.draw_segment(px([x0, 0.0]), px([x1, 0.0]), 1.0, [150, 150, 150]);
    }
    let title_x = titles.x.to_uppercase();
    let title_y = titles.y.to_uppercase();
    let mid = ml + 0.5 * (w - ml - mr);
    draw_text(
        &mut img,
        mid - 0.5 * text_width(&title_x, font),
        h - 22.0,
        &title_x,
        font,
        dark,
    );
    draw_text(&mut img, 8.0, 10.0, &title_y, font, dark);
    let corners = [px([x0, y0]), px([x1, y0]), px([x1, y1]), px([x0, y1])];
    for k in 0..4 {
        img.draw_segment(corners[k], corners[(k + 1) % 4], 1.5, dark);
    }
    for s in series {
        let pts: Vec<[f64; 2]> = s
            .points
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .map(|&p| px(p))
            .collect();
        if s.lines {
            for w in pts.windows(2) {
                img.draw_segment(w[0], w[1], 2.0, s.colour);
            }
        }
        for p in &pts {
            img.fill_disk(*p, 3.5, s.colour, true);
        }
        for (p, e) in s.points.iter().zip(s.errors.iter().flatten()) {
            if p[0].is_finite() && p[1].is_finite() && e.is_finite() && *e > 0.0 {
                let (lo, hi) = (px([p[0], p[1] - e]), px([p[0], p[1] + e]));
                img.draw_segment(lo, hi, 1.5, s.colour);
                img.draw_segment([lo[0] - 4.0, lo[1]], [lo[0] + 4.0, lo[1]], 1.5, s.colour);
                img.draw_segment([hi[0] - 4.0, hi[1]], [hi[0] + 4.0, hi[1]], 1.5, s.colour);
            }
        }
    }
    img
}

/// Plots with axis titles and saves as PNG.
pub fn save_plot(path: &Path, series: &[Series], zero_line: bool, titles: Titles) -> Result<()> {
    plot(series, 640, 460, zero_line, titles).save_png(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        let t = ticks(0.03, 0.97, 5);
        assert_eq!(t.first().copied(), Some(0.2));
        assert!(t.iter().all(|v| (0.03..=0.97).contains(v)));
        assert_eq!(label(0.25), "0.25");
        assert_eq!(label(-3.0), "-3");
        assert_eq!(label(2e-5), "2e-5");
    }

    #[test]
    fn series_are_drawn() {
        let s = Series {
            points: vec![[0.0, 0.0], [1.0, 1.0]],
            colour: PALETTE[1],
            lines: true,
            errors: Some(vec![0.1, 0.0]),
        };
        let img = plot(&[s], 200, 150, false, Titles { x: "x (m)", y: "y" });
        assert!(img.rgb.chunks(3).any(|p| p == PALETTE[1]));
    }
}
