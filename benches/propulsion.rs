//! Placeholder: replaced by the propulsion benches.
fn main() {}
