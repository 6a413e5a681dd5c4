//! Being written; see the crate README.
fn main() {}
