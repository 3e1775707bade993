//! The one little-endian byte codec of the house: checkpoints (through
//! each engine's and measurement's own packing) and the messages between
//! ranks (`comm::codec`). Every read checks the bytes left before
//! it allocates, so a damaged or hostile file ends in an error, never a
//! panic or a huge allocation.

use crate::dim::Dim;

/// Appends values to a byte buffer.
#[derive(Clone, Debug, Default)]
pub struct Enc {
    pub buf: Vec<u8>,
}

impl Enc {
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    pub fn bool(&mut self, v: bool) {
        self.u8(v as u8);
    }
    pub fn u32(&mut self, v: u32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    /// The exact bits of `v` (NaN payloads and −0 included).
    pub fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    pub fn len(&mut self, n: usize) {
        self.u64(n as u64);
    }
    pub fn str(&mut self, s: &str) {
        self.bytes(s.as_bytes());
    }
    /// A length-prefixed byte string.
    pub fn bytes(&mut self, b: &[u8]) {
        self.len(b.len());
        self.buf.extend_from_slice(b);
    }
    pub fn vec<D: Dim>(&mut self, v: D::V) {
        for a in 0..D::D {
            self.f64(D::get(v, a));
        }
    }
    pub fn ang<D: Dim>(&mut self, a: D::A) {
        for x in D::ang_to_xyz(a) {
            self.f64(x);
        }
    }
    pub fn vecs<D: Dim>(&mut self, v: &[D::V]) {
        self.len(v.len());
        v.iter().for_each(|&x| self.vec::<D>(x));
    }
    pub fn angs<D: Dim>(&mut self, v: &[D::A]) {
        self.len(v.len());
        v.iter().for_each(|&x| self.ang::<D>(x));
    }
    pub fn f64s(&mut self, v: &[f64]) {
        self.len(v.len());
        v.iter().for_each(|&x| self.f64(x));
    }
}

/// Reads values back; errors say what was being read and where.
#[derive(Clone, Debug)]
pub struct Dec<'a> {
    data: &'a [u8],
    pos: usize,
}

pub type DecResult<T> = std::result::Result<T, String>;

impl<'a> Dec<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    pub fn take(&mut self, n: usize, what: &str) -> DecResult<&'a [u8]> {
        if n > self.remaining() {
            return Err(format!(
                "ends early: {what} needs {n} bytes at offset {}, {} left",
                self.pos,
                self.remaining()
            ));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    pub fn u8(&mut self, what: &str) -> DecResult<u8> {
        Ok(self.take(1, what)?[0])
    }
    pub fn bool(&mut self, what: &str) -> DecResult<bool> {
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!("{what}: byte {b} is not a boolean")),
        }
    }
    pub fn u32(&mut self, what: &str) -> DecResult<u32> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }
    pub fn u64(&mut self, what: &str) -> DecResult<u64> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
    pub fn f64(&mut self, what: &str) -> DecResult<f64> {
        Ok(f64::from_bits(self.u64(what)?))
    }
    /// A count of items of `item_bytes` each, checked against the bytes left.
    pub fn len(&mut self, item_bytes: usize, what: &str) -> DecResult<usize> {
        let n = self.u64(what)?;
        let fits = (n as u128) * (item_bytes.max(1) as u128) <= self.remaining() as u128;
        if !fits {
            return Err(format!(
                "{what}: {n} entries do not fit in the {} bytes left",
                self.remaining()
            ));
        }
        Ok(n as usize)
    }
    /// A length-prefixed byte string.
    pub fn bytes(&mut self, what: &str) -> DecResult<&'a [u8]> {
        let n = self.len(1, what)?;
        self.take(n, what)
    }
    pub fn str(&mut self, what: &str) -> DecResult<String> {
        let n = self.len(1, what)?;
        let b = self.take(n, what)?;
        String::from_utf8(b.to_vec()).map_err(|_| format!("{what}: not UTF-8 text"))
    }
    pub fn vec<D: Dim>(&mut self, what: &str) -> DecResult<D::V> {
        let mut v = D::zero();
        for a in 0..D::D {
            D::set(&mut v, a, self.f64(what)?);
        }
        Ok(v)
    }
    pub fn ang<D: Dim>(&mut self, what: &str) -> DecResult<D::A> {
        let x = [self.f64(what)?, self.f64(what)?, self.f64(what)?];
        Ok(D::ang_from_xyz(x))
    }
    pub fn vecs<D: Dim>(&mut self, what: &str) -> DecResult<Vec<D::V>> {
        let n = self.len(8 * D::D, what)?;
        (0..n).map(|_| self.vec::<D>(what)).collect()
    }
    pub fn angs<D: Dim>(&mut self, what: &str) -> DecResult<Vec<D::A>> {
        let n = self.len(24, what)?;
        (0..n).map(|_| self.ang::<D>(what)).collect()
    }
    pub fn f64s(&mut self, what: &str) -> DecResult<Vec<f64>> {
        let n = self.len(8, what)?;
        (0..n).map(|_| self.f64(what)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_and_text_read_back() {
        let mut e = Enc::default();
        e.bytes(b"abc");
        e.str("grains");
        e.f64(-0.0);
        let mut d = Dec::new(&e.buf);
        assert_eq!(d.bytes("b").unwrap(), b"abc");
        assert_eq!(d.str("s").unwrap(), "grains");
        assert_eq!(d.f64("x").unwrap().to_bits(), (-0.0f64).to_bits());
        assert_eq!(d.remaining(), 0);
        assert!(d.u8("past the end").unwrap_err().contains("ends early"));
    }

    #[test]
    fn huge_length_is_refused_without_allocating() {
        let mut e = Enc::default();
        e.u64(u64::MAX);
        let mut d = Dec::new(&e.buf);
        assert!(d.f64s("x").unwrap_err().contains("do not fit"));
    }
}
