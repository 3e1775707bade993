//! The MD engine and its step pipeline.
