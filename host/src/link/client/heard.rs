//! What the client heard while its `Hello` went unanswered (nothing, zeros, its own frames
//! echoed, garbage, pushbot frames without a reply), and when a heartbeat is due.

use std::time::Duration;

use super::{Client, Command, Heard, HostFrame, HostTime, NOISY_FOR};

/// What arrived since the handshake began (see [`Heard`]).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Listened {
    pub(super) since: HostTime,
    pub(super) bytes: u64,
    pub(super) zeros: u64,
    pub(super) echoes: u64,
    pub(super) frames: u64,
}

/// Whether a heartbeat is due: a quarter watchdog period of robot time since the last frame
/// sent (by the telemetry), or of host time (for a robot that sends no telemetry), or the robot
/// clock went backwards (it restarted).
pub fn heartbeat_due(
    robot_now_us: Option<u64>,
    last_tx_robot_us: Option<u64>,
    since_tx_host: Duration,
    watchdog_ms: u16,
) -> bool {
    let period_us = u64::from(watchdog_ms) * 1000 / 4;
    let by_robot_time = match (robot_now_us, last_tx_robot_us) {
        (Some(now), Some(last)) => now < last || now - last >= period_us,
        (Some(_), None) => true,
        (None, _) => false,
    };
    by_robot_time || since_tx_host >= Duration::from_micros(period_us)
}

impl Client {
    /// Whether the frame the reader just completed is one of the host's own, come back.
    pub(super) fn is_echo(&self) -> bool {
        let frame = self.reader.last_frame();
        !frame.is_empty() && self.sent_frames.iter().any(|s| s.as_slice() == frame)
    }

    /// What arrived since the latest `Hello`, at `now`.
    pub(super) fn heard(&self, now: HostTime) -> Heard {
        let l = self.listened;
        if l.bytes == 0 {
            Heard::Nothing
        } else if l.frames > 0 {
            Heard::Frames { frames: l.frames }
        } else if l.echoes > 0 {
            Heard::Echo { bytes: l.bytes }
        } else if l.zeros == l.bytes {
            Heard::Zeros { bytes: l.bytes }
        } else {
            Heard::Garbage {
                bytes: l.bytes,
                secs: now.since(l.since).as_secs_f64(),
            }
        }
    }
    /// Whether the wire counts as noisy at `now`.
    pub fn noisy(&self, now: HostTime) -> bool {
        self.noisy_until.is_some_and(|t| now < t)
    }

    pub(super) fn mark_noisy(&mut self, now: HostTime) {
        self.noisy_until = Some(now.after(NOISY_FOR));
    }

    /// The watchdog period heartbeats are paced for at `now`: half the real one on a noisy wire.
    pub(super) fn paced_watchdog_ms(&self, now: HostTime) -> u16 {
        if self.noisy(now) {
            (self.watchdog_ms / 2).max(1)
        } else {
            self.watchdog_ms
        }
    }

    pub(super) fn heartbeat_if_due(&mut self, now: HostTime) {
        if self.heartbeats_paused
            || !heartbeat_due(
                self.telemetry.map(|t| t.time_us),
                self.last_tx_robot_us,
                now.since(self.last_tx),
                self.paced_watchdog_ms(now),
            )
        {
            return;
        }
        let frame = HostFrame {
            seq: self.heartbeat_seq,
            cmd: Command::Heartbeat,
        };
        self.send_frame(now, &frame);
    }
}
