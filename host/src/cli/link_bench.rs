//! `pushbot bench link`: arguments and printing of the link bench
//! (`crate::experiments::link_bench`, which needs the built-in simulated target).

use clap::Args;

use super::{CliError, CliResult, Global};

/// `pushbot bench link`.
#[derive(Args, Debug, Clone)]
pub struct BenchLinkArgs {
    /// Commands to send (a mix of moves, spins, stops and queries).
    #[arg(long, default_value_t = 1000)]
    pub commands: usize,
    /// Probability that a byte has a bit flipped, each direction.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub corrupt: f64,
    /// Probability that a whole frame is lost, each direction.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub frame_loss: f64,
    /// Probability that a frame arrives twice, each direction.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub duplicate: f64,
    /// Probability that a byte is lost, each direction.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub drop: f64,
    /// Probability that a garbage byte is inserted before a byte, each direction.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub garbage: f64,
    /// Cut the wire (both ways) every this many seconds of robot time; each cut is recovered
    /// (a new session, the link's fault cleared) and counted.
    #[arg(long, value_name = "S", default_value_t = 0.0)]
    pub cut_every: f64,
    /// How long each cut lasts, s of robot time.
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub cut_for: f64,
}

fn seconds(name: &str, s: f64) -> Result<f64, CliError> {
    if s.is_finite() && (0.0..1e6).contains(&s) {
        Ok(s)
    } else {
        Err(CliError::bad_input(format!(
            "--{name} must be a time in seconds ≥ 0, not {s}"
        )))
    }
}

fn probability(name: &str, p: f64) -> Result<f64, CliError> {
    if (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(CliError::bad_input(format!(
            "--{name} must be a probability in 0..=1, not {p}"
        )))
    }
}

/// Run `pushbot bench link`.
#[cfg(feature = "sim")]
pub fn run(g: &Global, a: &BenchLinkArgs) -> CliResult {
    use super::Status;
    use crate::experiments::link_bench::{LinkBenchOptions, run};
    let opts = LinkBenchOptions {
        commands: a.commands,
        corrupt: probability("corrupt", a.corrupt)?,
        frame_loss: probability("frame-loss", a.frame_loss)?,
        duplicate: probability("duplicate", a.duplicate)?,
        drop: probability("drop", a.drop)?,
        garbage: probability("garbage", a.garbage)?,
        cut_every_s: seconds("cut-every", a.cut_every)?,
        cut_for_s: seconds("cut-for", a.cut_for)?,
        seed: g.seed,
        ..LinkBenchOptions::default()
    };
    let r = run(&opts)?;
    if g.json {
        let line = serde_json::to_string(&r).map_err(|e| CliError::Failed(e.into()))?;
        println!("{line}");
        return Ok(Status::Success);
    }
    let share = |n: usize| 100.0 * n as f64 / r.sent.max(1) as f64;
    let rows: Vec<(&str, String)> = vec![
        ("sent", r.sent.to_string()),
        (
            "completed",
            format!("{} ({:.2} %)", r.completed, share(r.completed)),
        ),
        ("refused", r.refused.to_string()),
        ("failed (motion ended otherwise)", r.failed.to_string()),
        ("unknown", r.unknown.to_string()),
        ("motions the robot started", r.motions_started.to_string()),
        ("executed twice", r.executed_twice.to_string()),
        ("motions nobody asked for", r.unasked_motions.to_string()),
        ("watchdog trips", r.watchdog_trips.to_string()),
        ("recoveries", r.recoveries.to_string()),
        (
            "retries per command",
            format!("{:.3}", r.retries_per_command),
        ),
        (
            "latency p50 / p99 (robot time)",
            format!("{:.1} / {:.1} ms", r.latency_ms.p50, r.latency_ms.p99),
        ),
        ("robot time", format!("{:.1} s", r.robot_time_s)),
        ("wall time", format!("{:.1} s", r.wall_s)),
    ];
    let head = format!("link bench (seed {})", g.seed);
    let w = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .chain([head.chars().count()])
        .max()
        .unwrap_or(0);
    let v = rows
        .iter()
        .map(|(_, v)| v.chars().count())
        .chain([5])
        .max()
        .unwrap_or(0);
    // A Markdown table whose columns line up in a terminal too.
    println!("| {head:<w$} | {:<v$} |", "value");
    println!("|{}|{}|", "-".repeat(w + 2), "-".repeat(v + 2));
    for (k, val) in &rows {
        println!("| {k:<w$} | {val:>v$} |");
    }
    Ok(Status::Success)
}

/// Run `pushbot bench link` (this build has no simulated target).
#[cfg(not(feature = "sim"))]
pub fn run(_g: &Global, a: &BenchLinkArgs) -> CliResult {
    probability("corrupt", a.corrupt)?;
    seconds("cut-every", a.cut_every)?;
    Err(super::no_simulated_target())
}
