//! `pushbot bench link`: N commands (moves, spins, stops and queries) against the in-process
//! target through a seeded fault pipe in each direction, and what became of them.
//!
//! Every number is in robot (simulated) time except the wall time. What the robot executed is
//! read from the simulator's own count of started primitives per sequence number
//! (the simulator's `starts_since_boot`: every session, as the host's numbering goes on
//! across recoveries), not from what the host believes:
//!
//! * `executed_twice`: motion commands the robot started more than once;
//! * `unasked_motions`: primitives started under a sequence number the host never used for a
//!   motion;
//! * `watchdog_trips`: the robot's link watchdog latching `LINK_LOST` (the simulator's count).
//!
//! Outcomes, as the host knows them: `completed` (a motion's `Done(Completed)`, a stop or query
//! acknowledged), `refused` (a `Nack`), `failed` (a motion that ended otherwise: fault, timeout,
//! aborted), `unknown` (no answer, or no end, before the client gave up, and the robot's report
//! after the recovery does not name it). A broken link (no answer, silence) or a latched
//! `LINK_LOST` is recovered with [`Robot::recover`] — a new session, the link's fault cleared —
//! and counted; the interrupted command's fate is then what the robot reports for it. With
//! `cut_every_s`, the wire is also cut periodically (both ways). `latency_ms` is the robot time
//! from sending a command to its answer (`Ack`/`Nack`), retries included.

use std::collections::BTreeSet;
use std::time::Instant;

use anyhow::Result;
use pushbot_protocol::{Command, ConfigUpdate, Faults, Outcome};
use pushbot_world::Pose;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::link::{Driver, LinkError};
use crate::robot::{LinkOptions, Robot, command_name, link_broke, motion_budget_us};
use crate::sim::inprocess::InProcess;
use crate::sim::target::LinkFaults;

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkBenchOptions {
    /// Commands to send.
    pub commands: usize,
    /// Per byte, each direction: probability of a flipped bit.
    pub corrupt: f64,
    /// Per frame, each direction: probability that it is lost.
    pub frame_loss: f64,
    /// Per frame, each direction: probability that it arrives twice.
    pub duplicate: f64,
    /// Per byte, each direction: probability that it is lost.
    pub drop: f64,
    /// Per byte, each direction: probability that a garbage byte is inserted before it.
    pub garbage: f64,
    /// Cut the wire every this many seconds of robot time (0: never)…
    pub cut_every_s: f64,
    /// …for this long, s.
    pub cut_for_s: f64,
    /// Seed of the simulator, the fault pipe and the command mix.
    pub seed: u64,
    /// Link settings of the host.
    pub link: LinkOptions,
}

impl Default for LinkBenchOptions {
    /// 1000 commands on a clean wire, seed 0, default link settings.
    fn default() -> Self {
        LinkBenchOptions {
            commands: 1000,
            corrupt: 0.0,
            frame_loss: 0.0,
            duplicate: 0.0,
            drop: 0.0,
            garbage: 0.0,
            cut_every_s: 0.0,
            cut_for_s: 0.0,
            seed: 0,
            link: LinkOptions::default(),
        }
    }
}

/// Percentiles of latency, ms of robot time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Latency {
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
}

/// What became of the commands.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinkBenchReport {
    /// Commands sent.
    pub sent: usize,
    /// Completed (see the module docs).
    pub completed: usize,
    /// Refused with a `Nack`.
    pub refused: usize,
    /// Motions that ended other than `Completed`.
    pub failed: usize,
    /// Outcome unknown: no answer or no end.
    pub unknown: usize,
    /// Motion commands the robot started more than once (the simulator's count).
    pub executed_twice: usize,
    /// Primitives started under a number the host never sent a motion with.
    pub unasked_motions: usize,
    /// Distinct motion commands the robot started (the simulator's count).
    pub motions_started: usize,
    /// Times the robot's link watchdog latched `LINK_LOST`.
    pub watchdog_trips: u64,
    /// Recoveries of the link ([`Robot::recover`]).
    pub recoveries: usize,
    /// Command frames resent, per command sent.
    pub retries_per_command: f64,
    /// Robot time from sending a command to its answer.
    pub latency_ms: Latency,
    /// Robot time of the whole run, s.
    pub robot_time_s: f64,
    /// Wall time of the whole run, s.
    pub wall_s: f64,
    /// Frames the client sent (commands, retries, heartbeats).
    pub frames_sent: u64,
    /// Bytes the host received.
    pub bytes_received: u64,
    /// Frames from the robot the client rejected.
    pub frames_rejected: u64,
}

impl LinkBenchReport {
    /// Completed commands per command sent.
    pub fn completed_share(&self) -> f64 {
        self.completed as f64 / self.sent.max(1) as f64
    }
}

/// The kinds of command in the mix.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Move,
    Spin,
    Stop,
    Query,
}

/// How one command ended.
enum Fate {
    Completed,
    Refused,
    Failed,
    Unknown,
}

/// The fate of a command that ended in `e`; a broken link is noted in `broke`.
fn fate_of(e: &LinkError, broke: &mut Option<String>) -> Fate {
    tracing::info!("command not completed: {e}");
    if link_broke(e) {
        *broke = Some(e.to_string());
    }
    match e {
        LinkError::Refused { .. } => Fate::Refused,
        _ => Fate::Unknown,
    }
}

/// The sign to use, then turn it over.
fn flip(sign: &mut f32) -> f32 {
    let s = *sign;
    *sign = -s;
    s
}

/// Run the bench.
pub fn run(opts: &LinkBenchOptions) -> Result<LinkBenchReport> {
    let wall = Instant::now();
    let faults = LinkFaults {
        drop: opts.drop,
        corrupt: opts.corrupt,
        garbage: opts.garbage,
        frame_loss: opts.frame_loss,
        duplicate: opts.duplicate,
        max_delay_us: 0,
        cut_every_us: (opts.cut_every_s.max(0.0) * 1e6) as u64,
        cut_for_us: (opts.cut_for_s.max(0.0) * 1e6) as u64,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    rng.set_stream(7);
    let first_seq: u16 = rng.random();
    // A large empty table: the back-and-forth mix never reaches a wall.
    let driver = InProcess::on_open_table(
        (6.0, 6.0),
        Pose::new(3.0, 3.0, 0.0),
        opts.seed,
        faults,
        opts.link.client_options(first_seq),
    )?;
    let mut robot = Robot::over(driver, opts.link.clone())?;
    let now_us = |r: &Robot<InProcess>| r.driver().sim().now_us();
    let start_us = now_us(&robot);

    let mut motions = BTreeSet::new();
    let mut latencies = Vec::with_capacity(opts.commands);
    let (mut completed, mut refused, mut failed, mut unknown) = (0, 0, 0, 0);
    // Moves and spins each go back and forth: the robot stays where it started.
    let (mut forth, mut left) = (1.0f32, 1.0f32);
    for _ in 0..opts.commands {
        let kind = match rng.random_range(0..10) {
            0..=3 => Kind::Move,
            4..=6 => Kind::Spin,
            7 => Kind::Stop,
            _ => Kind::Query,
        };
        let cmd = match kind {
            Kind::Move => Command::Move {
                distance: 0.02 * flip(&mut forth),
                speed: 0.2,
                stop_on_contact: false,
            },
            Kind::Spin => Command::Spin {
                angle: 0.3 * flip(&mut left),
                rate: 3.0,
            },
            Kind::Stop => Command::Stop,
            Kind::Query => Command::Configure(ConfigUpdate::default()),
        };
        let seq = robot.driver().inspect(|c| c.next_seq());
        let sent_us = now_us(&robot);
        let mut broke = None;
        let fate = if motion_budget_us(&cmd).is_some() {
            motions.insert(seq);
            match robot.start(cmd) {
                Ok(m) => {
                    latencies.push(now_us(&robot) - sent_us);
                    match robot.wait(&m) {
                        Ok(d) if d.outcome == Outcome::Completed => Fate::Completed,
                        Ok(d) => {
                            tracing::info!("#{seq} ended {:?}", d.outcome);
                            if let Outcome::Fault(f) = d.outcome
                                && f.contains(Faults::LINK_LOST)
                            {
                                broke = Some("the robot's link watchdog fired".to_string());
                            }
                            Fate::Failed
                        }
                        Err(e) => fate_of(&e, &mut broke),
                    }
                }
                Err(e) => {
                    if matches!(e, LinkError::Refused { .. }) {
                        latencies.push(now_us(&robot) - sent_us);
                    }
                    fate_of(&e, &mut broke)
                }
            }
        } else {
            let answered = robot.request(cmd);
            if answered.is_ok() || matches!(answered, Err(LinkError::Refused { .. })) {
                latencies.push(now_us(&robot) - sent_us);
            }
            match answered {
                Ok(_) => Fate::Completed,
                Err(e) => fate_of(&e, &mut broke),
            }
        };
        if broke.is_none()
            && robot
                .telemetry()
                .is_some_and(|t| t.faults.contains(Faults::LINK_LOST))
        {
            broke = Some("the robot latched LINK_LOST".to_string());
        }
        let fate = match broke {
            Some(cause) => {
                let rec = robot.recover(&cause, Some((seq, command_name(&cmd))))?;
                let reported = rec.interrupted.and_then(|i| i.outcome);
                match (fate, reported.as_deref()) {
                    (Fate::Unknown, Some("completed")) => Fate::Completed,
                    (Fate::Unknown, Some(_)) => Fate::Failed,
                    (f, _) => f,
                }
            }
            None => fate,
        };
        match fate {
            Fate::Completed => completed += 1,
            Fate::Refused => refused += 1,
            Fate::Failed => failed += 1,
            Fate::Unknown => unknown += 1,
        }
    }

    let stats = robot.stats();
    let sim = robot.driver().sim();
    // Numbering goes on across recovered sessions: count over all of them.
    let starts = sim.starts_since_boot();
    let executed_twice = starts
        .iter()
        .filter(|&(seq, &n)| motions.contains(seq) && n > 1)
        .count();
    let unasked_motions = starts.keys().filter(|s| !motions.contains(s)).count();
    latencies.sort_unstable();
    let pct = |p: f64| -> f64 {
        if latencies.is_empty() {
            return 0.0;
        }
        let i = ((latencies.len() - 1) as f64 * p).round() as usize;
        latencies[i.min(latencies.len() - 1)] as f64 / 1000.0
    };
    Ok(LinkBenchReport {
        sent: opts.commands,
        completed,
        refused,
        failed,
        unknown,
        executed_twice,
        unasked_motions,
        motions_started: starts.len(),
        watchdog_trips: sim.watchdog_trips(),
        recoveries: robot.recoveries().len(),
        retries_per_command: stats.retries as f64 / opts.commands.max(1) as f64,
        latency_ms: Latency {
            p50: pct(0.5),
            p99: pct(0.99),
        },
        robot_time_s: (sim.now_us() - start_us) as f64 / 1e6,
        wall_s: wall.elapsed().as_secs_f64(),
        frames_sent: stats.frames_sent,
        bytes_received: stats.bytes_received,
        frames_rejected: stats.frames_rejected,
    })
}
