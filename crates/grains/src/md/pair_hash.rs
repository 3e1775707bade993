//! A fast hash for the (id, id) keys of the springs carried over a
//! neighbour-list rebuild. The standard SipHash guards against keys chosen by
//! an attacker, which grain ids are not, and cost most of the carry-over.
//! Lookups only: the map's iteration order is never used, so the results do
//! not depend on the hash.

use std::hash::{BuildHasherDefault, Hasher};

/// Multiply-rotate hashing of whole words (the scheme of Firefox's hash).
#[derive(Default, Clone, Copy)]
pub struct PairHasher(u64);

const K: u64 = 0x517c_c1b7_2722_0a95;

impl Hasher for PairHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(K);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

pub type PairHash = BuildHasherDefault<PairHasher>;
