//! Experiments: the papers' evaluations run as sweeps in the in-process simulation (feature
//! `sim`), with their tables and figures; the CLI only parses their arguments and prints.
//!
//! - [`strategy_eval`]: delivery trials of the learned strategy and the dipole field from the
//!   scene's start positions (Lau et al. §V, Fig. 11).
//! - [`delivery`]: collect (or reuse) a strategy, then deliver among obstacles (§III-E).

pub mod delivery;
pub mod strategy_eval;
