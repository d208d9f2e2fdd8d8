//! Recovery after the link broke (a cut, a re-enumerated port): open the port again (waiting
//! for it to come back, up to [`LinkOptions::reconnect_timeout`]), say `Hello` in a new
//! session, read the robot's state, and — the robot standing and the only latched fault the
//! link's own — clear it, so that the interrupted task's executor can go on from the *measured*
//! pose. Motor, stall, encoder, emergency-stop and control faults are never cleared here: they
//! need the user.
//!
//! Exactly once: the new session's client numbers its commands on from the old one's, so no
//! frame of the old session is ever sent again, and the robot's retry cache (which `Hello`
//! replaces) cannot take a new command for an old one. The interrupted command's outcome is
//! what the robot's telemetry says (`last_done` under its number), or unknown — never guessed.
//!
//! [`LinkOptions::reconnect_timeout`]: super::LinkOptions::reconnect_timeout

use std::time::{Duration, Instant};

use pushbot_protocol::{Faults, Mode, Outcome};
use serde::Serialize;

use super::Robot;
use crate::link::{Driver, FaultNames, LinkError};

/// How many times recovery sends `ClearFaults` while the watchdog keeps firing.
const CLEAR_ATTEMPTS: usize = 5;

/// The command that was in flight or running when the link broke.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Interrupted {
    /// Its sequence number.
    pub seq: u16,
    /// Its name (`Move`, `Spin`, …).
    pub command: &'static str,
    /// How it ended, as the robot's telemetry reported after the recovery (`completed`,
    /// `fault (LINK_LOST)`, …); `None` when the robot's report does not name it: unknown.
    pub outcome: Option<String>,
}

/// One recovery of the link, as logged and counted in `--json` output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Recovery {
    /// What broke the link, in words.
    pub cause: String,
    /// The command in flight or running then, if one was.
    pub interrupted: Option<Interrupted>,
    /// How many times the port was opened (and `Hello` said) until a session stood.
    pub reopen_attempts: u32,
    /// Whether the robot was still moving when read back (the host then stopped it).
    pub was_moving: bool,
    /// The latched faults the recovery cleared (only ever the link's own).
    pub cleared: Vec<String>,
    /// Robot time when the link was back, s.
    pub robot_time_s: f64,
    /// Wall time the recovery took, s.
    pub wall_s: f64,
}

/// The lower-case name of an outcome, as printed (`completed`, `fault (LINK_LOST)`).
pub fn outcome_name(o: Outcome) -> String {
    match o {
        Outcome::Completed => "completed".into(),
        Outcome::Contact => "contact".into(),
        Outcome::Aborted => "aborted".into(),
        Outcome::Fault(f) => format!("fault ({})", FaultNames(f)),
        Outcome::Timeout => "timeout".into(),
    }
}

/// Whether `e` says the link itself broke (silence, no answer, the port gone) — what
/// [`Robot::recover`] is for — rather than the robot refusing or failing a command.
pub fn link_broke(e: &LinkError) -> bool {
    matches!(
        e,
        LinkError::NoAnswer { .. }
            | LinkError::HelloUnanswered { .. }
            | LinkError::Silent { .. }
            | LinkError::Disconnected { .. }
    )
}

impl<D: Driver> Robot<D> {
    /// Close the link and open it again, then shake hands anew (a new session; `Hello` also
    /// clears a latched `LINK_LOST`). Tries once, and keeps trying every 100 ms for
    /// [`super::LinkOptions::reconnect_timeout`] of wall time while the port is away or mute.
    /// Returns how many attempts it took.
    pub fn reconnect(&mut self) -> Result<u32, LinkError> {
        let started = Instant::now();
        let deadline = started + self.opts.reconnect_timeout;
        let mut attempts = 0;
        loop {
            attempts += 1;
            let before = self.driver.inspect(|c| c.stats());
            let attempt = self.driver.reopen().and_then(|()| {
                // The old session's client is gone: keep its counters.
                self.past_stats += before;
                self.handshake()
            });
            match attempt {
                Ok(h) => {
                    self.hello = h;
                    return Ok(attempts);
                }
                Err(e @ LinkError::VersionMismatch { .. }) => return Err(e),
                Err(e) if Instant::now() >= deadline => {
                    return Err(match e {
                        LinkError::NoSuchPort { .. }
                        | LinkError::NotASerialPort { .. }
                        | LinkError::Open { .. }
                        | LinkError::Disconnected { .. } => LinkError::Vanished {
                            path: self.path().to_string(),
                            waited_s: started.elapsed().as_secs_f64(),
                            reason: e.to_string(),
                        },
                        other => other,
                    });
                }
                Err(e) => {
                    tracing::debug!("reconnect to {}: {e}; retrying", self.path());
                    // Waiting for a device to reappear is wall-clock business.
                    std::thread::sleep(Duration::from_millis(100));
                }
            }
        }
    }

    /// Recover the link after `cause` broke it (see the module docs); `interrupted` is the
    /// sequence number and name of the command in flight or running then. Fails — leaving the
    /// robot as it is — when the port does not come back, or when the robot holds a fault that
    /// is not the link's ([`LinkError::RecoveryRefused`]).
    pub fn recover(
        &mut self,
        cause: &str,
        interrupted: Option<(u16, &'static str)>,
    ) -> Result<Recovery, LinkError> {
        let started = Instant::now();
        tracing::warn!("link to {} broke ({cause}); recovering", self.path());
        let reopen_attempts = self.reconnect()?;
        let mut t = self.wait_telemetry(None)?;
        let was_moving = !matches!(t.mode, Mode::Idle | Mode::Faulted);
        if was_moving {
            // The cut was shorter than the robot's watchdog: what runs is ours, and over.
            t = self.stop()?;
        }
        let others = t.faults.without(Faults::LINK_LOST);
        if !others.is_empty() {
            return Err(LinkError::RecoveryRefused {
                path: self.path().to_string(),
                faults: others,
            });
        }
        let mut cleared = Vec::new();
        // The watchdog may fire again while the link is still shaky: clear it a few times.
        let mut faults = t.faults;
        for _ in 0..CLEAR_ATTEMPTS {
            if !faults.contains(Faults::LINK_LOST) {
                break;
            }
            faults = self.clear_faults()?;
            if cleared.is_empty() {
                cleared.push("LINK_LOST".to_string());
            }
        }
        if !faults.is_empty() {
            return Err(LinkError::RecoveryRefused {
                path: self.path().to_string(),
                faults,
            });
        }
        let latest = self.telemetry().unwrap_or(t);
        let interrupted = interrupted.map(|(seq, command)| Interrupted {
            seq,
            command,
            outcome: latest
                .last_done
                .filter(|&(s, _)| s == seq)
                .map(|(_, o)| outcome_name(o)),
        });
        let rec = Recovery {
            cause: cause.to_string(),
            interrupted,
            reopen_attempts,
            was_moving,
            cleared,
            robot_time_s: latest.time_us as f64 * 1e-6,
            wall_s: started.elapsed().as_secs_f64(),
        };
        tracing::warn!(
            "link to {} recovered in {:.2} s ({} attempt(s)); interrupted: {}",
            self.path(),
            rec.wall_s,
            rec.reopen_attempts,
            rec.interrupted
                .as_ref()
                .map_or("nothing".to_string(), |i| format!(
                    "{} #{} ({})",
                    i.command,
                    i.seq,
                    i.outcome.as_deref().unwrap_or("outcome unknown")
                ))
        );
        match self.recoveries.lock() {
            Ok(mut r) => r.push(rec.clone()),
            Err(p) => p.into_inner().push(rec.clone()),
        }
        Ok(rec)
    }

    /// Every recovery so far, in order.
    pub fn recoveries(&self) -> Vec<Recovery> {
        match self.recoveries.lock() {
            Ok(r) => r.clone(),
            Err(p) => p.into_inner().clone(),
        }
    }

    /// The sequence number of the last command sent (what was in flight when the link broke:
    /// the robot layer has one command in flight at a time).
    pub fn last_seq(&self) -> u16 {
        self.driver.inspect(|c| c.next_seq().wrapping_sub(1))
    }
}
