//! The Clay editor binary (a shell for now).
fn main() {}
