//! Validity diagnostics (stub).
