//! One open link: a reader thread that decodes frames, keeps the latest telemetry, the answers,
//! the `Done`s and the contacts, counts rejected frames, and paces heartbeats by robot time;
//! a writer behind a mutex shared by commands and heartbeats.
//!
//! Heartbeats (DESIGN.md, "Time"): the robot's link watchdog counts robot time, so the host
//! sends a heartbeat whenever the telemetry shows that a quarter of the watchdog period of
//! *robot* time has passed since the last frame it sent. An accelerated simulator therefore
//! gets heartbeats often enough, and a real robot still stops when the host goes quiet. A
//! wall-clock quarter period also triggers one, for a robot whose telemetry is off.

use std::collections::HashMap;
use std::io::{Read, Write};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use pushbot_protocol::{
    Command, ContactEvent, DecodeError, Done, FrameDecoder, HelloReply, HostFrame, MAX_FRAME,
    NackReason, RobotMsg, Telemetry, encode_frame,
};
use serialport::TTYPort;

use super::error::LinkError;
use super::transport;

/// Something the robot reported, as delivered to [`super::Robot::subscribe`] receivers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RobotEvent {
    /// Periodic state.
    Telemetry(Telemetry),
    /// The bumper closed.
    Contact(ContactEvent),
    /// A motion command ended.
    Done(Done),
}

/// Counters of the link, for diagnostics and tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct LinkStats {
    /// Bytes received.
    pub bytes_received: u64,
    /// Frames received that decoded to a message.
    pub frames_ok: u64,
    /// Frames received that were rejected (CRC, COBS, not a message, overflow).
    pub frames_rejected: u64,
    /// Frames sent (commands, retries, heartbeats).
    pub frames_sent: u64,
    /// Heartbeats sent.
    pub heartbeats_sent: u64,
    /// Command frames sent again because no answer came in time.
    pub retries: u64,
}

/// The answer to one command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Answer {
    /// Accepted.
    Ack,
    /// Refused.
    Nack(NackReason),
}

/// How many unclaimed `Done`s to keep (those of commands nobody waits for).
const MAX_DONES: usize = 64;

/// What the reader thread learned, guarded by [`Shared::state`].
pub(crate) struct State {
    pub telemetry: Option<Telemetry>,
    pub answers: HashMap<u16, Answer>,
    pub hello: Option<HelloReply>,
    /// The protocol version of a `HelloReply` from another protocol version, read from the
    /// fields that never change (variant 0, first field) of a frame this host cannot decode.
    pub foreign_hello: Option<u16>,
    pub dones: HashMap<u16, Done>,
    pub contacts: Vec<ContactEvent>,
    pub stats: LinkStats,
    pub last_rx: Instant,
    last_tx_wall: Instant,
    last_tx_robot_us: Option<u64>,
    pub watchdog_ms: u16,
    heartbeats_paused: bool,
    /// Sequence number heartbeats carry (the robot ignores it).
    pub heartbeat_seq: u16,
    /// Why the port closed under us, once it has.
    closed: Option<String>,
    stop: bool,
}

/// Everything the reader thread and the API share.
pub(crate) struct Shared {
    pub path: String,
    state: Mutex<State>,
    cond: Condvar,
    writer: Mutex<Option<TTYPort>>,
    subscribers: Mutex<Vec<mpsc::Sender<RobotEvent>>>,
    dead_link: Duration,
}

/// An open link: the port, its reader thread, the shared state.
pub(crate) struct Session {
    pub shared: Arc<Shared>,
    reader: Option<JoinHandle<()>>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic in another thread holding the lock leaves plain data behind; keep going.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Whether a heartbeat is due: a quarter watchdog period of robot time since the last frame
/// sent (by the telemetry), or of wall time (for a robot that sends no telemetry), or the robot
/// clock went backwards (it restarted).
pub(crate) fn heartbeat_due(
    robot_now_us: Option<u64>,
    last_tx_robot_us: Option<u64>,
    since_tx_wall: Duration,
    watchdog_ms: u16,
) -> bool {
    let period_us = u64::from(watchdog_ms) * 1000 / 4;
    let by_robot_time = match (robot_now_us, last_tx_robot_us) {
        (Some(now), Some(last)) => now < last || now - last >= period_us,
        (Some(_), None) => true,
        (None, _) => false,
    };
    by_robot_time || since_tx_wall >= Duration::from_micros(period_us)
}

impl Session {
    /// Open `path` and start the reader thread.
    pub fn open(path: &str, watchdog_ms: u16, dead_link: Duration) -> Result<Session, LinkError> {
        let port = transport::open(path)?;
        let reader_port = port.try_clone_native().map_err(|e| LinkError::Open {
            path: path.to_string(),
            reason: e.description,
        })?;
        let now = Instant::now();
        let shared = Arc::new(Shared {
            path: path.to_string(),
            state: Mutex::new(State {
                telemetry: None,
                answers: HashMap::new(),
                hello: None,
                foreign_hello: None,
                dones: HashMap::new(),
                contacts: Vec::new(),
                stats: LinkStats::default(),
                last_rx: now,
                last_tx_wall: now,
                last_tx_robot_us: None,
                watchdog_ms,
                heartbeats_paused: false,
                heartbeat_seq: 0,
                closed: None,
                stop: false,
            }),
            cond: Condvar::new(),
            writer: Mutex::new(Some(port)),
            subscribers: Mutex::new(Vec::new()),
            dead_link,
        });
        let for_reader = Arc::clone(&shared);
        let reader = std::thread::Builder::new()
            .name("pushbot-link-rx".into())
            .spawn(move || reader_loop(&for_reader, reader_port))
            .map_err(|e| LinkError::Open {
                path: path.to_string(),
                reason: format!("cannot start the reader thread: {e}"),
            })?;
        Ok(Session {
            shared,
            reader: Some(reader),
        })
    }

    /// Stop the reader and close the port.
    pub fn close(&mut self) {
        lock(&self.shared.state).stop = true;
        self.shared.cond.notify_all();
        if let Some(h) = self.reader.take() {
            let _ = h.join();
        }
        if let Some(mut port) = lock(&self.shared.writer).take() {
            transport::release(&mut port);
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.close();
    }
}

impl Shared {
    /// Lock the state.
    pub fn state(&self) -> MutexGuard<'_, State> {
        lock(&self.state)
    }

    fn disconnected(&self, reason: String) -> LinkError {
        LinkError::Disconnected {
            path: self.path.clone(),
            reason,
        }
    }

    /// Send one frame (a command, a retry or a heartbeat).
    pub fn send(&self, frame: &HostFrame) -> Result<(), LinkError> {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode_frame(frame, &mut buf).map_err(|e| {
            LinkError::InvalidArgument(format!("cannot frame {:?}: {e}", frame.cmd))
        })?;
        let heartbeat = matches!(frame.cmd, Command::Heartbeat);
        self.write_bytes(&buf[..n])?;
        let mut st = self.state();
        st.stats.frames_sent += 1;
        if heartbeat {
            st.stats.heartbeats_sent += 1;
        }
        st.last_tx_wall = Instant::now();
        st.last_tx_robot_us = st.telemetry.map(|t| t.time_us);
        Ok(())
    }

    /// Write raw bytes to the port (no framing, does not count as a frame sent).
    pub fn write_bytes(&self, bytes: &[u8]) -> Result<(), LinkError> {
        if let Some(reason) = self.state().closed.clone() {
            return Err(self.disconnected(reason));
        }
        let mut w = lock(&self.writer);
        let port = w
            .as_mut()
            .ok_or_else(|| self.disconnected("the link was closed".into()))?;
        let result = write_patiently(port, bytes);
        drop(w);
        result.map_err(|e| {
            let reason = e.to_string();
            self.mark_closed(reason.clone());
            self.disconnected(reason)
        })
    }

    fn mark_closed(&self, reason: String) {
        let mut st = self.state();
        if st.closed.is_none() {
            st.closed = Some(reason);
        }
        drop(st);
        self.cond.notify_all();
    }

    /// Stop or resume heartbeats (a test hook: the robot's watchdog should then stop it).
    pub fn pause_heartbeats(&self, paused: bool) {
        self.state().heartbeats_paused = paused;
    }

    /// Register a receiver of every event from now on.
    pub fn subscribe(&self) -> mpsc::Receiver<RobotEvent> {
        let (tx, rx) = mpsc::channel();
        lock(&self.subscribers).push(tx);
        rx
    }

    /// Wait until `f` returns `Some`, the wall-clock `deadline` passes (`Ok(None)`), the port
    /// closes, or nothing arrives for the dead-link time.
    pub fn wait_until<T>(
        &self,
        deadline: Option<Instant>,
        mut f: impl FnMut(&mut State) -> Option<Result<T, LinkError>>,
    ) -> Result<Option<T>, LinkError> {
        let mut st = self.state();
        loop {
            if let Some(r) = f(&mut st) {
                return r.map(Some);
            }
            if let Some(reason) = st.closed.clone() {
                return Err(self.disconnected(reason));
            }
            let silent = st.last_rx.elapsed();
            if silent > self.dead_link {
                return Err(LinkError::Silent {
                    path: self.path.clone(),
                    secs: silent.as_secs_f64(),
                });
            }
            let mut wait = Duration::from_millis(50);
            if let Some(d) = deadline {
                let now = Instant::now();
                if now >= d {
                    return Ok(None);
                }
                wait = wait.min(d - now);
            }
            st = self
                .cond
                .wait_timeout(st, wait)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }

    fn handle(&self, msg: RobotMsg) {
        let event = {
            let mut st = self.state();
            st.stats.frames_ok += 1;
            match msg {
                RobotMsg::HelloReply(h) => {
                    st.hello = Some(h);
                    None
                }
                RobotMsg::Ack { seq } => {
                    st.answers.insert(seq, Answer::Ack);
                    None
                }
                RobotMsg::Nack { seq, reason } => {
                    st.answers.insert(seq, Answer::Nack(reason));
                    None
                }
                RobotMsg::Done(d) => {
                    if st.dones.len() >= MAX_DONES {
                        st.dones.clear();
                    }
                    st.dones.insert(d.seq, d);
                    Some(RobotEvent::Done(d))
                }
                RobotMsg::Telemetry(t) => {
                    st.telemetry = Some(t);
                    Some(RobotEvent::Telemetry(t))
                }
                RobotMsg::Contact(c) => {
                    st.contacts.push(c);
                    Some(RobotEvent::Contact(c))
                }
            }
        };
        self.cond.notify_all();
        if let Some(ev) = event {
            lock(&self.subscribers).retain(|s| s.send(ev).is_ok());
        }
    }

    fn heartbeat_if_due(&self) {
        let seq = {
            let st = self.state();
            if st.heartbeats_paused
                || st.closed.is_some()
                || !heartbeat_due(
                    st.telemetry.map(|t| t.time_us),
                    st.last_tx_robot_us,
                    st.last_tx_wall.elapsed(),
                    st.watchdog_ms,
                )
            {
                return;
            }
            st.heartbeat_seq
        };
        // A failed write marks the link closed; waiters see it.
        let _ = self.send(&HostFrame {
            seq,
            cmd: Command::Heartbeat,
        });
    }
}

/// Write all of `bytes`, waiting out a full output buffer for up to [`WRITE_PATIENCE`].
fn write_patiently(port: &mut TTYPort, mut bytes: &[u8]) -> std::io::Result<()> {
    let deadline = Instant::now() + WRITE_PATIENCE;
    while !bytes.is_empty() {
        match port.write(bytes) {
            Ok(0) => return Err(std::io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if !transport::is_fatal(&e) && Instant::now() < deadline => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// How long a write may wait for room in the output buffer before the link counts as dead.
const WRITE_PATIENCE: Duration = Duration::from_secs(2);

/// The protocol version in a serialised `HelloReply` of any protocol version: the crate docs
/// promise it is variant 0 of the robot's messages and its first field, a postcard varint.
pub(crate) fn peek_hello_version(payload: &[u8]) -> Option<u16> {
    let (&variant, rest) = payload.split_first()?;
    if variant != 0 {
        return None;
    }
    let mut value: u32 = 0;
    for (i, &b) in rest.iter().take(3).enumerate() {
        value |= u32::from(b & 0x7f) << (7 * i);
        if b & 0x80 == 0 {
            return u16::try_from(value).ok();
        }
    }
    None
}

/// The message bytes of a frame (COBS decoded, CRC stripped; the decoder checked the CRC).
fn frame_payload(encoded: &[u8]) -> Option<Vec<u8>> {
    let mut buf = encoded.to_vec();
    let n = cobs::decode_in_place(&mut buf).ok()?;
    buf.truncate(n.checked_sub(pushbot_protocol::CRC_LEN)?);
    Some(buf)
}

fn reader_loop(shared: &Shared, mut port: TTYPort) {
    let mut decoder = FrameDecoder::new();
    let mut buf = [0u8; 512];
    // The current frame's raw bytes, to read the version of a reply we cannot decode.
    let mut raw: Vec<u8> = Vec::with_capacity(MAX_FRAME);
    loop {
        if shared.state().stop {
            return;
        }
        match port.read(&mut buf) {
            Ok(0) => {
                shared.mark_closed("end of file (hang-up)".into());
                return;
            }
            Ok(n) => {
                {
                    let mut st = shared.state();
                    st.last_rx = Instant::now();
                    st.stats.bytes_received += n as u64;
                }
                for &b in &buf[..n] {
                    if b != 0 && raw.len() < MAX_FRAME {
                        raw.push(b);
                    }
                    let result = decoder.push::<RobotMsg>(b);
                    let frame = if b == 0 {
                        std::mem::take(&mut raw)
                    } else {
                        Vec::new()
                    };
                    match result {
                        None => {}
                        Some(Ok(msg)) => shared.handle(msg),
                        Some(Err(e)) => {
                            tracing::debug!("rejected frame from the robot: {e}");
                            let mut st = shared.state();
                            st.stats.frames_rejected += 1;
                            // CRC good but not a message of ours: another protocol version?
                            if matches!(e, DecodeError::Message | DecodeError::TrailingBytes)
                                && let Some(v) =
                                    frame_payload(&frame).and_then(|p| peek_hello_version(&p))
                            {
                                st.foreign_hello = Some(v);
                                drop(st);
                                shared.cond.notify_all();
                            }
                        }
                    }
                }
            }
            Err(e) if !transport::is_fatal(&e) => {}
            Err(e) => {
                shared.mark_closed(e.to_string());
                return;
            }
        }
        shared.heartbeat_if_due();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hello_version_is_read_from_any_hello_reply() {
        // Our own HelloReply, serialised: its version is where every version keeps it.
        let mut frame = [0u8; MAX_FRAME];
        for version in [0u16, 1, 127, 128, 300, u16::MAX] {
            let msg = RobotMsg::HelloReply(HelloReply {
                protocol: version,
                accepted: false,
                firmware: pushbot_protocol::FirmwareVersion {
                    major: 1,
                    minor: 2,
                    patch: 3,
                },
                geometry: pushbot_protocol::Geometry {
                    wheel_base: 0.1,
                    wheel_radius: 0.02,
                    bumper_radius: 0.05,
                    encoder_cpr: 1000,
                    control_hz: 1000,
                },
            });
            let n = encode_frame(&msg, &mut frame).unwrap();
            let payload = frame_payload(&frame[..n - 1]).unwrap();
            assert_eq!(peek_hello_version(&payload), Some(version));
        }
        // Other messages are not hellos.
        let n = encode_frame(&RobotMsg::Ack { seq: 0 }, &mut frame).unwrap();
        assert_eq!(
            peek_hello_version(&frame_payload(&frame[..n - 1]).unwrap()),
            None
        );
        assert_eq!(peek_hello_version(&[]), None);
        assert_eq!(peek_hello_version(&[0, 0xff, 0xff, 0xff]), None);
    }

    #[test]
    fn heartbeat_paced_by_robot_time() {
        let wd = 200; // quarter period: 50 ms
        let wall = Duration::from_millis(1);
        assert!(!heartbeat_due(Some(1_049_999), Some(1_000_000), wall, wd));
        assert!(heartbeat_due(Some(1_050_000), Some(1_000_000), wall, wd));
        // First telemetry after opening: nothing sent in robot time yet.
        assert!(heartbeat_due(Some(5), None, wall, wd));
        // The robot restarted: its clock went back.
        assert!(heartbeat_due(Some(10), Some(1_000_000), wall, wd));
        // No telemetry: wall clock only.
        assert!(!heartbeat_due(None, None, Duration::from_millis(49), wd));
        assert!(heartbeat_due(None, None, Duration::from_millis(50), wd));
    }
}
