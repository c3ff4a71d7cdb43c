//! Placeholder until the cross-process handshake benchmark lands.
fn main() {}
