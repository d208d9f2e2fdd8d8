//! Errors of the host link: each says what went wrong and, where there is one, what to do.

use std::fmt;

use pushbot_protocol::{Faults, NackReason};

use super::client::{FLOOD_BYTES_PER_S, Heard};

/// Everything that can go wrong talking to the robot.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// Nothing exists at the port path.
    #[error("no serial port at {path}: no such file")]
    NoSuchPort {
        /// The path asked for.
        path: String,
    },
    /// Something exists at the path but it is not a serial port (a regular file, `/dev/null`…).
    #[error("{path} is not a serial port: {reason}")]
    NotASerialPort {
        /// The path asked for.
        path: String,
        /// What the operating system said.
        reason: String,
    },
    /// The port exists but could not be opened (permissions, in use).
    #[error("cannot open the serial port {path}: {reason}")]
    Open {
        /// The path asked for.
        path: String,
        /// What the operating system said.
        reason: String,
    },
    /// The port went away (USB unplugged, the simulator stopped) or failed mid-session.
    #[error("the serial port {path} disappeared: {reason}")]
    Disconnected {
        /// The port's path.
        path: String,
        /// What the operating system said.
        reason: String,
    },
    /// The robot speaks another protocol version: refused in the handshake.
    #[error(
        "protocol version mismatch on {path}: this host speaks pushbot protocol v{host}, the robot \
         speaks v{robot}; update the host or reflash the robot's firmware"
    )]
    VersionMismatch {
        /// The port's path.
        path: String,
        /// The version the host offered.
        host: u16,
        /// The robot's version.
        robot: u16,
    },
    /// The robot never answered a command, even after retries.
    #[error(
        "no answer from the robot on {path} to {what} after {attempts} attempts (is a robot \
         running pushbot firmware connected, and powered?)"
    )]
    NoAnswer {
        /// The port's path.
        path: String,
        /// The command that went unanswered.
        what: &'static str,
        /// How many times it was sent.
        attempts: u32,
    },
    /// The handshake went unanswered: what arrived instead tells a dead line (nothing), a line
    /// held low (zeros), a loopback (echo), another device or baud rate (garbage, a flood).
    #[error("{}", unanswered_hello(path, *attempts, heard))]
    HelloUnanswered {
        /// The port's path.
        path: String,
        /// How many times `Hello` was sent.
        attempts: u32,
        /// What arrived instead.
        heard: Heard,
    },
    /// No byte at all arrived for too long while waiting: the link is dead.
    #[error("the robot on {path} sent nothing for {secs:.1} s of wall time: link dead")]
    Silent {
        /// The port's path.
        path: String,
        /// How long nothing arrived, s.
        secs: f64,
    },
    /// The robot answered with a `Nack`.
    #[error("robot refused {what}: {reason}")]
    Refused {
        /// The refused command.
        what: &'static str,
        /// Why, as the robot said.
        reason: Refusal,
    },
    /// A motion did not end within its budget of robot time; the host sent `Stop`.
    #[error("{what} did not finish within {budget_s:.1} s of robot time; the host sent Stop")]
    DoneTimeout {
        /// The motion command.
        what: &'static str,
        /// Its budget, s of robot time.
        budget_s: f64,
    },
    /// The port went away and did not come back in time (a USB re-enumeration that took longer,
    /// a robot unplugged).
    #[error(
        "the serial port {path} went away and did not come back{}: {reason}; give \
         --reconnect SECONDS to wait for it",
        if *waited_s > 0.05 { format!(" within {waited_s:.1} s") } else { String::new() }
    )]
    Vanished {
        /// The port's path.
        path: String,
        /// How long the host waited for it, s of wall time.
        waited_s: f64,
        /// The last error opening it.
        reason: String,
    },
    /// The link came back but the robot holds faults that only the user may clear.
    #[error(
        "the link to {path} is back, but the robot holds {}: recovery clears only the link's \
         own fault; check the robot, then run `pushbot robot clear-faults`",
        FaultNames(*faults)
    )]
    RecoveryRefused {
        /// The port's path.
        path: String,
        /// The faults latched besides `LINK_LOST`.
        faults: Faults,
    },
    /// An argument the host can already tell is wrong (not finite, wrong sign).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
}

/// The message for a `Hello` that went unanswered, by what arrived instead.
fn unanswered_hello(path: &str, attempts: u32, heard: &Heard) -> String {
    match *heard {
        Heard::Nothing => format!(
            "no answer from the robot on {path}: nothing arrived while Hello was sent {attempts} \
             times (is a robot running pushbot firmware connected, and powered?)"
        ),
        Heard::Zeros { bytes } => format!(
            "only zero bytes arrive on {path} ({bytes} of them, no frame): the line is held low \
             (a break), or a device sends at another baud rate; check the wiring (TX to RX) and \
             that the robot runs pushbot firmware"
        ),
        Heard::Echo { .. } => format!(
            "{path} echoes back what the host sends: a loopback (TX wired to RX) or a terminal \
             that echoes, not a pushbot robot"
        ),
        Heard::Garbage { bytes, secs } if secs > 0.0 && bytes as f64 / secs > FLOOD_BYTES_PER_S => {
            format!(
                "a flood of bytes arrives on {path} ({:.0} kB/s, more than a serial line at \
                 115 200 baud carries) and none is a pushbot frame: another device or another \
                 program on the port, not a pushbot robot",
                bytes as f64 / secs / 1e3
            )
        }
        Heard::Garbage { bytes, secs } => format!(
            "bytes arrive on {path} ({bytes} in {secs:.1} s) but none is a pushbot frame: wrong \
             baud rate or another device? (or another program on the port)"
        ),
        Heard::Frames { frames } => format!(
            "the robot on {path} sends pushbot frames ({frames}) but does not answer Hello \
             after {attempts} attempts; reset the robot and try again"
        ),
    }
}

impl LinkError {
    /// Whether the error is the user's input (a bad path or argument) rather than a failure.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            LinkError::NoSuchPort { .. }
                | LinkError::NotASerialPort { .. }
                | LinkError::InvalidArgument(_)
                | LinkError::Refused {
                    reason: Refusal(NackReason::OutOfRange),
                    ..
                }
        )
    }
}

/// The robot's reason for a `Nack`, shown with what to do about it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Refusal(pub NackReason);

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            NackReason::VersionMismatch { robot } => {
                write!(f, "protocol version mismatch (the robot speaks v{robot})")
            }
            NackReason::NoSession => {
                f.write_str("no session open (the robot restarted or dropped the link); reconnect")
            }
            NackReason::OutOfRange => {
                f.write_str("a value is not finite or outside the robot's limits")
            }
            NackReason::Faulted(faults) => write!(
                f,
                "faults latched: {}; run `pushbot robot clear-faults`",
                FaultNames(faults)
            ),
        }
    }
}

/// The names of the flags in a [`Faults`] set, as in the protocol (`STALL_LEFT, LINK_LOST`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultNames(pub Faults);

/// Every fault flag with its name, in bit order.
pub const FAULT_NAMES: [(Faults, &str); 6] = [
    (Faults::STALL_LEFT, "STALL_LEFT"),
    (Faults::STALL_RIGHT, "STALL_RIGHT"),
    (Faults::LINK_LOST, "LINK_LOST"),
    (Faults::EMERGENCY_STOP, "EMERGENCY_STOP"),
    (Faults::ENCODER, "ENCODER"),
    (Faults::CONTROL_OVERRUN, "CONTROL_OVERRUN"),
];

impl FaultNames {
    /// The names of the set flags; unknown bits as `BIT<n>`.
    pub fn names(self) -> Vec<String> {
        (0..16)
            .filter(|bit| self.0.0 & (1 << bit) != 0)
            .map(|bit| {
                FAULT_NAMES
                    .iter()
                    .find(|(f, _)| f.0 == 1 << bit)
                    .map_or_else(|| format!("BIT{bit}"), |(_, n)| (*n).to_string())
            })
            .collect()
    }
}

impl fmt::Display for FaultNames {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = self.names();
        if names.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&names.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fault_names_list_every_set_flag_once() {
        for mask in 0u16..64 {
            let names = FaultNames(Faults(mask)).names();
            assert_eq!(names.len(), mask.count_ones() as usize);
            for (flag, name) in FAULT_NAMES {
                assert_eq!(names.iter().any(|n| n == name), Faults(mask).contains(flag));
            }
        }
        assert_eq!(FaultNames(Faults(1 << 15)).to_string(), "BIT15");
        assert_eq!(FaultNames(Faults::NONE).to_string(), "none");
    }

    #[test]
    fn faulted_refusal_says_what_to_do() {
        let msg = LinkError::Refused {
            what: "Move",
            reason: Refusal(NackReason::Faulted(Faults::STALL_LEFT)),
        }
        .to_string();
        assert_eq!(
            msg,
            "robot refused Move: faults latched: STALL_LEFT; run `pushbot robot clear-faults`"
        );
    }
}
