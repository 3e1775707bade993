//! Messages between ranks in the house's one byte codec
//! ([`crate::codec`]). A malformed message is a bug in the sender (both
//! ends are this program), so the reader panics on one rather than
//! returning errors.

use crate::codec::Dec;

/// Appends values to a message.
pub use crate::codec::Enc as Writer;

/// Reads a message back in the order it was written.
#[derive(Clone, Debug)]
pub struct Reader<'a>(Dec<'a>);

const MALFORMED: &str = "message shorter than its layout";

impl<'a> Reader<'a> {
    pub fn new(buf: &'a [u8]) -> Self {
        Self(Dec::new(buf))
    }
    pub fn u64(&mut self) -> u64 {
        self.0.u64("message").expect(MALFORMED)
    }
    pub fn u32(&mut self) -> u32 {
        self.0.u32("message").expect(MALFORMED)
    }
    pub fn f64(&mut self) -> f64 {
        self.0.f64("message").expect(MALFORMED)
    }
    pub fn bytes(&mut self) -> Vec<u8> {
        self.0.bytes("message").expect(MALFORMED).to_vec()
    }
    /// Whether everything was read.
    pub fn done(&self) -> bool {
        self.0.remaining() == 0
    }
}
