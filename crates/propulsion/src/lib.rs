//! Propulsion chain (placeholder until the propulsion crate lands).
