//! [`Num`], how every text file of a run writes a number: the shortest
//! decimal that reads back as the same `f64`, plain for moderate
//! magnitudes and in scientific notation (`1e-300`) otherwise, exactly as
//! `format!("{}")` and `format!("{:e}")` lay it out.
//!
//! The digits come from `zmij` (a shortest round-trip formatter faster
//! than the standard library's), then are laid out as the standard
//! library does; a tie between two shortest candidates goes to the
//! standard library, so every file keeps its bytes. The frames, contacts
//! and fields of a run are mostly numbers.

/// Displays an `f64` with full (round-trip) precision and compactly: plain
/// decimals for moderate magnitudes, scientific notation (`1e-300`) otherwise.
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() {
            return write!(f, "{}", self.0);
        }
        let plain = (1e-5..1e16).contains(&a);
        let mut out = [0u8; 40];
        match layout(self.0, plain, &mut out) {
            // Only ASCII digits, '-', '.' and 'e' are written.
            Some(n) => f.write_str(std::str::from_utf8(&out[..n]).expect("ASCII")),
            None if plain => write!(f, "{}", self.0),
            None => write!(f, "{:e}", self.0),
        }
    }
}

/// Writes finite, nonzero `v` into `out` as `{}` (`plain`) or `{:e}`
/// would; returns the length. None for a value whose exact decimal is a
/// tie between two shortest candidates (it has one digit more than they,
/// a 5): the standard library picks the even one there, `zmij` not
/// always.
fn layout(v: f64, plain: bool, out: &mut [u8; 40]) -> Option<usize> {
    let mut buf = zmij::Buffer::new();
    let text = buf.format_finite(v).as_bytes();
    // The significant digits d₁…dₙ (no leading or trailing zeros) and the
    // point's place k: |v| = 0.d₁…dₙ × 10^k.
    let mut digits = [0u8; 20];
    let (mut n, mut k, mut point) = (0usize, 0i32, None);
    let mut exp = 0i32;
    let mut i = usize::from(text[0] == b'-');
    while i < text.len() {
        match text[i] {
            b'.' => point = Some(n),
            b'e' => {
                exp = std::str::from_utf8(&text[i + 1..])
                    .ok()
                    .and_then(|e| e.parse().ok())
                    .expect("zmij writes an integer exponent");
                break;
            }
            d => {
                if n == 0 && d == b'0' {
                    // A leading zero: before the point it only moves it.
                    k -= i32::from(point.is_some());
                } else {
                    digits[n] = d;
                    n += 1;
                }
            }
        }
        i += 1;
    }
    k += point.unwrap_or(n) as i32 + exp;
    while n > 1 && digits[n - 1] == b'0' {
        n -= 1;
    }
    if exact_digits(v) == Some(n + 1) {
        return None;
    }
    let mut w = 0;
    let mut put = |b: u8| {
        out[w] = b;
        w += 1;
    };
    if v < 0.0 {
        put(b'-');
    }
    let digits = &digits[..n];
    if plain {
        if k <= 0 {
            put(b'0');
            put(b'.');
            (0..-k).for_each(|_| put(b'0'));
            digits.iter().for_each(|&d| put(d));
        } else {
            let k = k as usize;
            for (j, &d) in digits.iter().enumerate() {
                if j == k {
                    put(b'.');
                }
                put(d);
            }
            (n..k).for_each(|_| put(b'0'));
        }
    } else {
        put(digits[0]);
        if n > 1 {
            put(b'.');
            digits[1..].iter().for_each(|&d| put(d));
        }
        put(b'e');
        let mut e = k - 1;
        if e < 0 {
            put(b'-');
            e = -e;
        }
        let mut tmp = [0u8; 4];
        let mut m = 0;
        loop {
            tmp[m] = b'0' + (e % 10) as u8;
            m += 1;
            e /= 10;
            if e == 0 {
                break;
            }
        }
        tmp[..m].iter().rev().for_each(|&d| put(d));
    }
    Some(w)
}

/// The number of significant digits of `v`'s exact decimal value, where
/// it has at most 19 (None: more). `v` = m 2^e with m odd: for e < 0 its
/// decimal is m 5^-e / 10^-e, whose digits are those of m 5^-e (odd, so
/// no trailing zero); for e ≥ 0 the integer m 2^e.
fn exact_digits(v: f64) -> Option<usize> {
    let bits = v.abs().to_bits();
    let (biased, frac) = ((bits >> 52) as i32, bits & ((1u64 << 52) - 1));
    let (mut m, mut e) = match biased {
        0 => (frac, -1074),
        _ => (frac | (1u64 << 52), biased - 1075),
    };
    let zeros = m.trailing_zeros();
    m >>= zeros;
    e += zeros as i32;
    let exact: u128 = if e < 0 {
        // 5^28 > 10^19: beyond that the digits are too many to matter.
        if e < -27 {
            return None;
        }
        u128::from(m) * 5u128.pow((-e) as u32)
    } else {
        if e > 64 {
            return None;
        }
        u128::from(m) << e
    };
    let limit = 10u128.pow(19);
    (exact < limit).then(|| exact.to_string().len())
}

#[cfg(test)]
mod tests {
    use super::Num;

    /// The layout of the standard library, which [`Num`] reproduces.
    fn reference(v: f64) -> String {
        let a = v.abs();
        if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
            format!("{v}")
        } else {
            format!("{v:e}")
        }
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

    /// Byte for byte the standard library's text: every power of ten and
    /// its neighbours, the range's edges, subnormals, and a million random
    /// bit patterns and a million random values of moderate size (without
    /// the test for ties it fails: 0x42e0228c07f0f4d4 came out as
    /// 141924514105254.62 where the standard library writes …63).
    #[test]
    fn num_writes_what_the_standard_library_writes() {
        let mut vals = vec![
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::EPSILON,
            1e16,
            9_999_999_999_999_998.0,
            1e-5,
            0.99999e-5,
            123456789012345680.0,
            0.1 + 0.2,
        ];
        for e in -320..=308 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            vals.extend([
                p,
                f64::from_bits(p.to_bits() + 1),
                f64::from_bits(p.to_bits() - 1),
            ]);
        }
        // A xorshift stream: no dependence on a random crate's versions.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for _ in 0..1_000_000 {
            vals.push(f64::from_bits(next()));
            let u = (next() >> 11) as f64 / (1u64 << 53) as f64;
            vals.push((u - 0.5) * 10f64.powi((next() % 24) as i32 - 8));
        }
        for v in vals.into_iter().filter(|v| v.is_finite()) {
            for v in [v, -v] {
                assert_eq!(Num(v).to_string(), reference(v), "{:#x}", v.to_bits());
            }
        }
    }
}
