//! What a driver of the link client does, whatever it moves bytes over: it owns the
//! [`Client`], hands it bytes and time, writes out what it transmits, and fans its events out
//! to subscribers. The robot layer (`crate::robot`) is written once against this trait.

use std::sync::mpsc;

use super::client::{Client, HostTime, RobotEvent};
use super::error::LinkError;

/// A driver of the link client: a serial port (with a thread) or an in-process target.
pub trait Driver {
    /// A name for the other end (the port's path), used in error messages.
    fn path(&self) -> &str;

    /// Run `f` on the client at the current host time, then send what it queued.
    fn with_client<T>(&self, f: impl FnOnce(&mut Client, HostTime) -> T) -> Result<T, LinkError>;

    /// Read the client's state (sends nothing).
    fn inspect<T>(&self, f: impl FnOnce(&Client) -> T) -> T;

    /// Move bytes and time until `f` returns `Some`. Fails when the port closes, or when
    /// nothing arrived for the client's dead-link time ([`LinkError::Silent`]).
    fn wait<T>(&self, f: impl FnMut(&mut Client, HostTime) -> Option<T>) -> Result<T, LinkError>;

    /// A receiver of every telemetry, contact and `Done` from now on.
    fn subscribe(&self) -> mpsc::Receiver<RobotEvent>;

    /// Close the link and open it again with a fresh client (same options, the sequence
    /// numbers going on), where the driver can.
    fn reopen(&mut self) -> Result<(), LinkError>;
}

/// Senders of robot events, pruned of receivers that hung up.
#[derive(Default)]
pub struct Subscribers(Vec<mpsc::Sender<RobotEvent>>);

impl Subscribers {
    /// A new receiver.
    pub fn subscribe(&mut self) -> mpsc::Receiver<RobotEvent> {
        let (tx, rx) = mpsc::channel();
        self.0.push(tx);
        rx
    }

    /// Drain the client's events, sending the robot's reports on.
    pub fn dispatch(&mut self, client: &mut Client) {
        while let Some(ev) = client.poll_event() {
            if let Some(ev) = ev.robot_event() {
                self.0.retain(|s| s.send(ev).is_ok());
            }
        }
    }
}

/// The [`LinkError::Silent`] error for `path`, if the client says the link is dead.
pub fn silent(client: &Client, now: HostTime, path: &str) -> Result<(), LinkError> {
    match client.link_dead(now) {
        Some(d) => Err(LinkError::Silent {
            path: path.to_string(),
            secs: d.as_secs_f64(),
        }),
        None => Ok(()),
    }
}
