//! Runner (stub).
