//! One motion primitive as a task of its own (`pushbot robot move`, `pushbot robot spin`): run
//! it to its end through breaks of the link. When a cut or a vanished port interrupts it, the
//! link is recovered ([`Robot::recover`]: a new session, only the link's fault cleared) and the
//! rest of the motion is sent as a new command, measured from the robot's odometry — never the
//! old command again, so nothing is driven twice.

use pushbot_protocol::{Command, Faults, NackReason, Outcome, Pose};

use crate::link::{Driver, LinkError, Refusal};
use crate::robot::{DoneReport, Recovery, Robot, command_name, link_broke};

/// Most recoveries one primitive may need before it gives up.
pub const MOST_RECOVERIES: usize = 5;
/// Below this remainder (m, or rad for spins) a resumed motion counts as done.
const DONE_WITHIN: f32 = 2e-3;

/// A primitive to run to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// Drive straight `distance` m at `speed` m/s, ending at a contact if asked.
    Move {
        /// Signed distance, m.
        distance: f32,
        /// Cruise speed, m/s.
        speed: f32,
        /// End at the first bumper contact.
        stop_on_contact: bool,
    },
    /// Turn on the spot by `angle` rad (at most half a turn when it may need resuming) at `rate`.
    Spin {
        /// Signed angle, rad.
        angle: f32,
        /// Cruise rate, rad/s.
        rate: f32,
    },
}

impl Primitive {
    /// The command for what is left after `progress` (m or rad) of it was done.
    fn command(self, progress: f32) -> Command {
        match self {
            Primitive::Move {
                distance,
                speed,
                stop_on_contact,
            } => Command::Move {
                distance: distance - progress,
                speed,
                stop_on_contact,
            },
            Primitive::Spin { angle, rate } => Command::Spin {
                angle: angle - progress,
                rate,
            },
        }
    }

    /// What was done of it between odometry poses `from` and `to`: the distance along the
    /// starting heading, or the turn (within half a turn of the asked angle's sign).
    fn progress(self, from: Pose, to: Pose) -> f32 {
        match self {
            Primitive::Move { .. } => {
                (to.x - from.x) * from.theta.cos() + (to.y - from.y) * from.theta.sin()
            }
            Primitive::Spin { .. } => {
                let d = (to.theta - from.theta).rem_euclid(std::f32::consts::TAU);
                if d > std::f32::consts::PI {
                    d - std::f32::consts::TAU
                } else {
                    d
                }
            }
        }
    }

    fn total(self) -> f32 {
        match self {
            Primitive::Move { distance, .. } => distance,
            Primitive::Spin { angle, .. } => angle,
        }
    }
}

/// How a primitive ended, with the recoveries it took.
#[derive(Debug, Clone, PartialEq)]
pub struct PrimitiveEnd {
    /// The last command's end (its outcome is the primitive's).
    pub done: DoneReport,
    /// Recoveries of the link on the way.
    pub recoveries: Vec<Recovery>,
}

/// Run `p` to its end; with `recover`, through breaks of the link (see the module docs).
pub fn run_primitive<D: Driver>(
    robot: &mut Robot<D>,
    p: Primitive,
    recover: bool,
) -> Result<PrimitiveEnd, LinkError> {
    let start = robot.wait_telemetry(None)?.pose;
    let resumable = match p {
        Primitive::Move { .. } => true,
        Primitive::Spin { angle, .. } => angle.abs() <= std::f32::consts::PI,
    };
    let mut recoveries = Vec::new();
    let mut progress = 0.0f32;
    loop {
        let cmd = p.command(progress);
        let seq = robot.last_seq().wrapping_add(1);
        let cause = match robot.start(cmd).and_then(|m| robot.wait(&m)) {
            Ok(done) => match done.outcome {
                Outcome::Fault(f) if f.contains(Faults::LINK_LOST) => {
                    if !recover || !resumable {
                        return Ok(PrimitiveEnd { done, recoveries });
                    }
                    "the robot's link watchdog stopped it".to_string()
                }
                _ => return Ok(PrimitiveEnd { done, recoveries }),
            },
            Err(e) if recover && resumable && link_broke(&e) => e.to_string(),
            // Refused for the link's own fault alone (the watchdog fired while the robot stood):
            // it never ran; recover and send it again.
            Err(
                e @ LinkError::Refused {
                    reason: Refusal(NackReason::Faulted(Faults::LINK_LOST)),
                    ..
                },
            ) if recover => e.to_string(),
            Err(e) => return Err(e),
        };
        if recoveries.len() >= MOST_RECOVERIES {
            return Err(LinkError::Disconnected {
                path: robot.path().to_string(),
                reason: format!(
                    "the link broke {} times during one {} ({cause}); giving up",
                    MOST_RECOVERIES + 1,
                    command_name(&cmd)
                ),
            });
        }
        recoveries.push(robot.recover(&cause, Some((seq, command_name(&cmd))))?);
        let now = robot.wait_telemetry(None)?.pose;
        progress = p.progress(start, now);
        if (p.total() - progress).abs() < DONE_WITHIN {
            // The cut came as it arrived: done, with the pose the robot reports now.
            let t = robot.wait_telemetry(None)?;
            let done = DoneReport {
                seq,
                outcome: Outcome::Completed,
                pose: t.pose,
                time_us: t.time_us,
                duration_s: 0.0,
                recovered: true,
            };
            return Ok(PrimitiveEnd { done, recoveries });
        }
        tracing::info!(
            "resuming {}: {:.4} of {:.4} done",
            command_name(&cmd),
            progress,
            p.total()
        );
    }
}
