//! Experiments: the papers' evaluations run as sweeps, with their tables and figures; the CLI
//! only parses their arguments and prints. Those that run in the in-process simulation need the
//! feature `sim`.
//!
//! - [`trials`]: statistics of delivery trials (Lau et al. §V, Fig. 11), for any robot.
//! - `strategy_eval`: delivery trials of the learned strategy and the dipole field from the
//!   scene's start positions (Lau et al. §V, Fig. 11), simulated.
//! - `eval_bench`: those trials' speed with the truth and the rendered camera (`pushbot bench
//!   eval`).
//! - `fig11`: Lau et al. Fig. 11's table and figure from those trials.
//! - `data_need`, `data_need_figure`: samples collected vs delivery success, for the paper's
//!   collection and the active one (`eval delivery --figure 7`).
//! - `jsonl`: the JSON-lines files that keep finished cells (header, then a cell a line).
//! - `resume`: the file of finished cells that lets such an evaluation be interrupted and
//!   resumed (`eval delivery --resume`).
//! - [`shard`]: the K-th of N shares of a sweep's cells (`--shard K/N`), and the sweep each
//!   shard's file names for `eval merge`.
//! - `trace`: every trial's poses and a drawing of it (`eval delivery --trace-dir`).
//! - `delivery`: collect (or reuse) a strategy, then deliver among obstacles (§III-E).
//! - `demo`: the demo's three stages, one per paper, into a report.
//! - [`rearrange_bench`]: the exact cost map and the practical mode of the rearrangement
//!   planner on large rooms (`pushbot bench rearrange`).
//! - `stable_trials`: stable pushing (Lynch & Mason §4) open and closed loop in perturbed
//!   simulated worlds (`pushbot run stable`, `pushbot eval stable`).
//! - `stable_sweep`: the file of finished stable trials (`eval stable --resume`, `--shard`).
//! - `link_bench`: commands through a faulty wire to the in-process target (`pushbot bench
//!   link`).

#[cfg(feature = "sim")]
pub mod data_need;
#[cfg(feature = "sim")]
pub mod data_need_figure;
#[cfg(feature = "sim")]
pub mod delivery;
#[cfg(feature = "sim")]
pub mod demo;
#[cfg(feature = "sim")]
pub mod eval_bench;
#[cfg(feature = "sim")]
pub mod fig11;
#[cfg(feature = "sim")]
pub mod jsonl;
#[cfg(feature = "sim")]
pub mod link_bench;
pub mod rearrange_bench;
#[cfg(feature = "sim")]
pub mod resume;
pub mod shard;
#[cfg(feature = "sim")]
pub mod stable_sweep;
#[cfg(feature = "sim")]
pub mod stable_trials;
#[cfg(feature = "sim")]
pub mod strategy_eval;
#[cfg(feature = "sim")]
pub mod trace;
pub mod trials;
