//! `pushbot-sim`: the simulated robot on a pseudo-terminal.
fn main() {}
