//! Floats as text in every CSV and ASCII file the project writes: the
//! shortest decimal that reads back to the same `f64`, plain for moderate
//! magnitudes and scientific (`1e-300`) otherwise, byte for byte as Rust's
//! `{}` and `{:e}` print it.
//!
//! The digits come from `zmij` (Schubfach), several times faster than the
//! standard library's Grisu with Dragon fallback; both give the shortest
//! round-trip digits nearest the value, and the layout differs: zmij
//! writes `12.0` and `1e+16` where Rust writes `12` and `1e16`, which
//! [`num_parts`] trims. They can choose different digits only where the
//! choice is a tie or lies on the edge of the value's rounding interval
//! (750000000000000.25: zmij `.2`, std `.3`), which needs a value whose
//! exact decimal expansion is short (few significant bits, or a large
//! integer): [`short_expansion`] sends those few to the standard library.
//! The tests compare the two on a million values.

/// Displays an `f64` with full (round-trip) precision and compactly: plain
/// decimals for 1e-5 ≤ |x| < 1e16 (and zero), scientific notation
/// otherwise, the text of `{}` and `{:e}` respectively.
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if short_expansion(self.0) {
            return std_fmt(self.0, f);
        }
        let mut buf = zmij::Buffer::new();
        let (a, b) = num_parts(&mut buf, self.0);
        f.write_str(a)?;
        f.write_str(b)
    }
}

/// Appends [`Num`]`(v)`'s text to `out`, without a formatter.
#[inline]
pub fn push_num(out: &mut String, v: f64) {
    if short_expansion(v) {
        use std::fmt::Write as _;
        let _ = write!(out, "{}", StdNum(v));
        return;
    }
    let mut buf = zmij::Buffer::new();
    let (a, b) = num_parts(&mut buf, v);
    out.push_str(a);
    out.push_str(b);
}

/// Whether the exact decimal expansion of finite, non-zero `v` may have 19
/// significant digits or fewer, the only values where the shortest
/// round-trip digits can be a tie between two candidates or sit on the
/// edge of the rounding interval (where zmij and std may choose apart):
/// integers below 1e18, and fractions M 2^−j (M odd) with M 5^j below
/// about 1e19. Physical data (1.2345e-3 holds 60 and more digits exactly)
/// never are; non-finite values and zero are (std writes them).
#[inline]
fn short_expansion(v: f64) -> bool {
    let bits = v.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i64;
    let frac = bits & ((1u64 << 52) - 1);
    if biased == 0x7ff || (biased == 0 && frac == 0) {
        return true;
    }
    let (m, k) = if biased == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), biased - 1075)
    };
    let tz = m.trailing_zeros();
    let (m, k) = (m >> tz, k + i64::from(tz));
    if k >= 0 {
        return v.abs() < 1e18;
    }
    // log10(M 5^j) from below: (bits of M − 1) log10 2 + j log10 5.
    let bits_m = f64::from(64 - m.leading_zeros());
    (bits_m - 1.0) * std::f64::consts::LOG10_2 + (-k) as f64 * 5f64.log10() < 19.5
}

/// `Num`'s definition through the standard library: `{}` in the plain
/// range, `{:e}` outside it.
fn std_fmt(v: f64, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
        write!(f, "{v}")
    } else {
        write!(f, "{v:e}")
    }
}

/// [`std_fmt`] as a `Display`.
struct StdNum(f64);

impl std::fmt::Display for StdNum {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std_fmt(self.0, f)
    }
}

/// [`Num`]'s text in two pieces (the second often empty), in `buf`, for a
/// finite `v` without a [`short_expansion`].
#[inline]
fn num_parts(buf: &mut zmij::Buffer, v: f64) -> (&str, &str) {
    // zmij switches to scientific notation outside the same decimal
    // exponents, −5 to 15, as `Num`'s range.
    let s = buf.format_finite(v);
    match s.find('e') {
        // "1.5e+16" → "1.5e16"; a negative exponent stays as it is.
        Some(e) if s.as_bytes().get(e + 1) == Some(&b'+') => (&s[..=e], &s[e + 2..]),
        Some(_) => (s, ""),
        // "12.0" → "12".
        None => (s.strip_suffix(".0").unwrap_or(s), ""),
    }
}

#[cfg(test)]
mod tests {
    use super::{push_num, Num};

    /// Num's definition: std's `{}` in the plain range, `{:e}` outside it.
    fn std_text(v: f64) -> String {
        let a = v.abs();
        if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
            format!("{v}")
        } else {
            format!("{v:e}")
        }
    }

    fn check(v: f64) {
        let mut s = String::new();
        push_num(&mut s, v);
        assert_eq!(s, std_text(v), "bits {:#x}", v.to_bits());
        assert_eq!(Num(v).to_string(), s);
    }

    #[test]
    fn num_round_trips_and_stays_short() {
        for v in [
            0.0,
            -0.0,
            1.0,
            100.0,
            0.01,
            1.0 / 3.0,
            1e-300,
            -2.5e-17,
            6.02e23,
            f64::MAX,
            1e-5,
            9.99e15,
        ] {
            let s = Num(v).to_string();
            assert!(s.len() <= 24, "{s}");
            assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
        }
        assert_eq!(Num(100.0).to_string(), "100");
        assert_eq!(Num(1e-300).to_string(), "1e-300");
    }

    /// The text is std's, byte for byte: special values, the ends of the
    /// plain range and their neighbours, integers, powers of ten, and
    /// random bit patterns and random values of the magnitudes a run
    /// writes (xorshift, fixed seed).
    #[test]
    fn num_text_is_std_text() {
        let mut special = vec![
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            5e-324,
            -5e-324,
            1e-5,
            1e16,
            123456789012345680.0,
            // 750000000000000.25, a tie on which zmij and std choose apart.
            f64::from_bits(0x430550f7dca70002),
            0.5,
            2.5e-8,
            0.1,
            0.3,
        ];
        for p in -320..=308 {
            let x: f64 = format!("1e{p}").parse().unwrap();
            special.extend([x, -x, x * 3.0, x * 7.5]);
        }
        for v in special {
            for b in [-2i64, -1, 0, 1, 2] {
                let w = f64::from_bits(v.to_bits().wrapping_add(b as u64));
                check(w);
                check(-w);
            }
        }
        for k in 0..100_000u64 {
            check(k as f64);
            check(k as f64 * 0.5);
        }
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..500_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            check(f64::from_bits(x));
            // Magnitudes 1e-12 to 1e4, as positions, forces and overlaps.
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            check(10f64.powf(16.0 * u - 12.0) * if x & 1 == 0 { 1.0 } else { -1.0 });
        }
    }
}
