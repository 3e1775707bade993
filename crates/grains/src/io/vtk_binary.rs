//! VTK XML data arrays in the inline `binary` format: the values' little-
//! endian bytes after a UInt32 byte count, base64-encoded (RFC 4648) as
//! one stream, which VTK's XML readers (ParaView, OVITO) decode. Eight
//! bytes per value where the shortest decimal takes up to 24 characters,
//! and no float formatting: the contact network and the fields of every
//! sample cost a fraction of their ASCII form to write.

use std::fmt::Write as _;

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Appends the base64 encoding of `bytes` (with `=` padding) to `out`.
pub fn base64_into(out: &mut String, bytes: &[u8]) {
    out.reserve(bytes.len().div_ceil(3) * 4);
    let mut chunks = bytes.chunks_exact(3);
    for c in &mut chunks {
        let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
        for shift in [18, 12, 6, 0] {
            out.push(ALPHABET[(n >> shift) as usize & 63] as char);
        }
    }
    let rest = chunks.remainder();
    if !rest.is_empty() {
        let b1 = rest.get(1).copied().unwrap_or(0);
        let n = (u32::from(rest[0]) << 16) | (u32::from(b1) << 8);
        out.push(ALPHABET[(n >> 18) as usize & 63] as char);
        out.push(ALPHABET[(n >> 12) as usize & 63] as char);
        out.push(if rest.len() == 2 {
            ALPHABET[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        out.push('=');
    }
}

/// The payload of a binary data array: the byte count (UInt32, the
/// default `header_type`) and the bytes, base64-encoded together.
fn payload(out: &mut String, bytes: &[u8]) {
    let mut all = Vec::with_capacity(4 + bytes.len());
    all.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
    all.extend_from_slice(bytes);
    base64_into(out, &all);
}

/// A `Float64` data array of `components` per tuple, `indent` spaces in.
pub fn f64_array(
    out: &mut String,
    indent: usize,
    name: &str,
    components: usize,
    values: impl Iterator<Item = f64>,
) {
    let bytes: Vec<u8> = values.flat_map(f64::to_le_bytes).collect();
    let _ = write!(
        out,
        "{:indent$}<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"{components}\" \
         format=\"binary\">",
        ""
    );
    payload(out, &bytes);
    out.push_str("</DataArray>\n");
}

/// An `Int64` data array, `indent` spaces in.
pub fn i64_array(out: &mut String, indent: usize, name: &str, values: impl Iterator<Item = i64>) {
    let bytes: Vec<u8> = values.flat_map(i64::to_le_bytes).collect();
    let _ = write!(
        out,
        "{:indent$}<DataArray type=\"Int64\" Name=\"{name}\" format=\"binary\">",
        ""
    );
    payload(out, &bytes);
    out.push_str("</DataArray>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(text: &str) -> Vec<u8> {
        let value = |c: u8| ALPHABET.iter().position(|&a| a == c).unwrap() as u32;
        let mut out = Vec::new();
        for q in text.as_bytes().chunks(4) {
            let pad = q.iter().filter(|&&c| c == b'=').count();
            let n = q
                .iter()
                .map(|&c| if c == b'=' { 0 } else { value(c) })
                .fold(0, |n, v| (n << 6) | v);
            out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
        }
        out
    }

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        // RFC 4648 §10.
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            let mut s = String::new();
            base64_into(&mut s, plain.as_bytes());
            assert_eq!(s, coded);
            assert_eq!(decode(&s), plain.as_bytes());
        }
    }

    #[test]
    fn arrays_carry_their_byte_count_and_values_exactly() {
        let values = [0.1, -2.5e-300, f64::MAX, 3.0];
        let mut s = String::new();
        f64_array(&mut s, 2, "v", 2, values.iter().copied());
        let body = s.split('>').nth(1).unwrap().split('<').next().unwrap();
        let bytes = decode(body);
        assert_eq!(u32::from_le_bytes(bytes[..4].try_into().unwrap()), 32);
        let back: Vec<f64> = bytes[4..]
            .chunks(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(back, values);
        assert!(s.starts_with("  <DataArray type=\"Float64\" Name=\"v\" NumberOfComponents=\"2\""));
        let mut s = String::new();
        i64_array(&mut s, 0, "id", [-1i64, 7].into_iter());
        let body = s.split('>').nth(1).unwrap().split('<').next().unwrap();
        let bytes = decode(body);
        assert_eq!(u32::from_le_bytes(bytes[..4].try_into().unwrap()), 16);
        assert_eq!(i64::from_le_bytes(bytes[4..12].try_into().unwrap()), -1);
        assert_eq!(i64::from_le_bytes(bytes[12..20].try_into().unwrap()), 7);
    }
}
