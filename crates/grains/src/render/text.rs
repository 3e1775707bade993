//! Text on pictures: the public-domain 8×8 bitmap font of the `font8x8`
//! crate (ASCII), scaled by whole pixels, and the short number formats the
//! labels use.

use crate::io::Image;

/// Height (and width) of a glyph at scale 1, in pixels.
pub const GLYPH: u32 = 8;

/// Width in pixels of `text` at `scale`.
pub fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * GLYPH * scale
}

/// Draws `text` with its top-left corner at pixel (x, y); characters
/// outside ASCII are drawn as '?'.
pub fn draw_text(img: &mut Image, x: i64, y: i64, scale: u32, text: &str, colour: [u8; 3]) {
    let s = scale.max(1) as i64;
    for (k, ch) in text.chars().enumerate() {
        let code = if ch.is_ascii() {
            ch as usize
        } else {
            b'?' as usize
        };
        let glyph = font8x8::legacy::BASIC_LEGACY[code];
        let x0 = x + k as i64 * 8 * s;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                // Bit 0 is the leftmost pixel of the row.
                if bits >> col & 1 == 1 {
                    fill_rect(
                        img,
                        x0 + col * s,
                        y + row as i64 * s,
                        s as u32,
                        s as u32,
                        colour,
                    );
                }
            }
        }
    }
}

/// Fills a w × h rectangle of pixels from (x, y), clipped to the image.
pub fn fill_rect(img: &mut Image, x: i64, y: i64, w: u32, h: u32, colour: [u8; 3]) {
    let x0 = x.clamp(0, img.width as i64) as usize;
    let x1 = (x + w as i64).clamp(0, img.width as i64) as usize;
    let y0 = y.clamp(0, img.height as i64) as usize;
    let y1 = (y + h as i64).clamp(0, img.height as i64) as usize;
    let width = img.width as usize;
    for row in y0..y1 {
        for px in img.rgb[(row * width + x0) * 3..(row * width + x1) * 3].chunks_exact_mut(3) {
            px.copy_from_slice(&colour);
        }
    }
}

/// `x` with three significant digits, plain for moderate magnitudes.
pub fn sig3(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let e = x.abs().log10().floor() as i32;
    if (-3..4).contains(&e) {
        let decimals = (2 - e).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.2e}")
    }
}

/// A length of 1, 2 or 5 × 10^k at most `target` (positive), and its label
/// in m, cm, mm or µm ("um": the font is ASCII).
pub fn nice_length(target: f64) -> (f64, String) {
    let p = 10f64.powf(target.log10().floor());
    let m = target / p;
    let f = if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    };
    let len = f * p;
    let (unit, name) = if len >= 1.0 {
        (1.0, "m")
    } else if len >= 0.01 {
        (0.01, "cm")
    } else if len >= 0.001 {
        (0.001, "mm")
    } else {
        (1e-6, "um")
    };
    let v = ((len / unit) * 1e6).round() / 1e6;
    (len, format!("{v} {name}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::View;

    #[test]
    fn numbers_and_lengths_read_well() {
        assert_eq!(sig3(0.123456), "0.123");
        assert_eq!(sig3(12.345), "12.3");
        assert_eq!(sig3(1234.6), "1235");
        assert_eq!(sig3(2.5e-6), "2.50e-6");
        assert_eq!(nice_length(0.0031), (0.002, "2 mm".into()));
        assert_eq!(nice_length(0.07).1, "5 cm");
        assert_eq!(nice_length(3.0).1, "2 m");
        assert_eq!(nice_length(0.0004).1, "200 um");
    }

    #[test]
    fn glyphs_land_where_asked() {
        let view = View {
            origin: [0.0, 0.0],
            scale: 1.0,
            height: 20,
        };
        let mut img = Image::new(40, 20, view);
        draw_text(&mut img, 2, 3, 2, "I", [0, 0, 0]);
        let dark = (0..20)
            .flat_map(|y| (0..40).map(move |x| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y) == [0, 0, 0])
            .collect::<Vec<_>>();
        assert!(!dark.is_empty());
        // All within the glyph's 16 × 16 cell at (2, 3).
        assert!(dark
            .iter()
            .all(|&(x, y)| (2..18).contains(&x) && (3..19).contains(&y)));
        assert_eq!(text_width("abc", 2), 48);
    }
}
