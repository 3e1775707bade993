//! The hash of the (id, id) keys of the springs carried over a rebuild.
//!
//! The standard SipHash guards against keys chosen by an attacker, which
//! grain ids are not, and cost most of the carry-over; rustc's Fx hash (a
//! multiplication per word, from the `rustc-hash` crate) does not. Lookups
//! only: the map's iteration order is never used, so the results do not
//! depend on the hash.

/// Builds the Fx hashers of the spring maps.
pub type PairHash = rustc_hash::FxBuildHasher;
