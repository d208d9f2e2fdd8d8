//! The robot end of the protocol: frame decoding, session, retry detection with a cached
//! answer, and the transmit queue.
//!
//! The queue holds messages, not bytes, and encodes each into a frame only when the link has
//! room for it. At most one telemetry message waits at a time (a newer one replaces it: it is
//! state, the latest wins), and when the queue is full, telemetry makes way for acks, dones and
//! contacts; a message that still finds no room is dropped and counted.

use heapless::Vec;
use pushbot_protocol::{
    Command, DecodeError, FrameDecoder, HostFrame, MAX_FRAME, RobotMsg, encode_frame,
};

/// Messages the transmit queue holds.
pub const TX_QUEUE: usize = 24;

/// Transmit queue of messages for the host.
pub struct TxQueue {
    queue: Vec<RobotMsg, TX_QUEUE>,
    frame: [u8; MAX_FRAME],
    frame_len: usize,
    frame_pos: usize,
    dropped: u32,
}

impl Default for TxQueue {
    fn default() -> Self {
        Self::new()
    }
}

fn is_telemetry(m: &RobotMsg) -> bool {
    matches!(m, RobotMsg::Telemetry(_))
}

impl TxQueue {
    /// An empty queue.
    pub const fn new() -> Self {
        TxQueue {
            queue: Vec::new(),
            frame: [0; MAX_FRAME],
            frame_len: 0,
            frame_pos: 0,
            dropped: 0,
        }
    }

    /// Messages dropped for want of room since start.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Messages waiting (not counting a frame partly sent).
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// Whether nothing waits, not even part of a frame.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty() && self.frame_pos >= self.frame_len
    }

    /// Queue a message (see the module docs for what gives way when full).
    pub fn push(&mut self, msg: RobotMsg) {
        if is_telemetry(&msg) {
            if let Some(slot) = self.queue.iter_mut().find(|m| is_telemetry(m)) {
                *slot = msg;
                return;
            }
        } else if self.queue.is_full()
            && let Some(i) = self.queue.iter().position(is_telemetry)
            && i < self.queue.len()
        {
            self.queue.remove(i);
        }
        if self.queue.push(msg).is_err() {
            self.dropped = self.dropped.saturating_add(1);
            warn!("tx queue full, message dropped");
        }
    }

    /// Copy as many queued bytes as fit into `out`; returns how many.
    pub fn drain(&mut self, out: &mut [u8]) -> usize {
        let mut n = 0;
        while n < out.len() {
            if self.frame_pos >= self.frame_len {
                if self.queue.is_empty() {
                    break;
                }
                let msg = self.queue.remove(0);
                match encode_frame(&msg, &mut self.frame) {
                    Ok(len) => {
                        self.frame_len = len;
                        self.frame_pos = 0;
                    }
                    Err(_) => {
                        // Cannot happen for our messages (all fit); never send half a frame.
                        self.dropped = self.dropped.saturating_add(1);
                        self.frame_len = 0;
                        self.frame_pos = 0;
                        continue;
                    }
                }
            }
            let (Some(src), Some(dst)) = (
                self.frame.get(self.frame_pos..self.frame_len),
                out.get_mut(n..),
            ) else {
                break;
            };
            let k = src.len().min(dst.len());
            if let (Some(d), Some(s)) = (dst.get_mut(..k), src.get(..k)) {
                d.copy_from_slice(s);
            }
            n += k;
            self.frame_pos += k;
        }
        n
    }
}

/// What the link makes of a received frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Received {
    /// A heartbeat: feeds the watchdog, needs no answer.
    Heartbeat,
    /// A retry of the last command: its cached answer has been queued again.
    Retry,
    /// A new command to execute and answer with [`Link::answer`].
    Command(HostFrame),
}

/// The robot end of the link.
pub struct Link {
    decoder: FrameDecoder,
    session: bool,
    last: Option<(HostFrame, RobotMsg)>,
    /// Outgoing messages.
    pub tx: TxQueue,
    rejected: u32,
}

impl Default for Link {
    fn default() -> Self {
        Self::new()
    }
}

impl Link {
    /// No session, nothing received.
    pub const fn new() -> Self {
        Link {
            decoder: FrameDecoder::new(),
            session: false,
            last: None,
            tx: TxQueue::new(),
            rejected: 0,
        }
    }

    /// Whether a host with our protocol version said hello.
    pub fn session(&self) -> bool {
        self.session
    }

    /// Start (or keep) a session.
    pub fn set_session(&mut self, on: bool) {
        self.session = on;
    }

    /// Frames rejected by the decoder (corrupt, too long, not a message) since start.
    pub fn rejected(&self) -> u32 {
        self.rejected
    }

    /// Feed one received byte; returns what a completed valid frame asks for.
    pub fn push(&mut self, byte: u8) -> Option<Received> {
        let frame: HostFrame = match self.decoder.push::<HostFrame>(byte)? {
            Ok(f) => f,
            Err(e) => {
                self.rejected = self.rejected.saturating_add(1);
                let code: u8 = match e {
                    DecodeError::Overflow => 0,
                    DecodeError::Cobs => 1,
                    DecodeError::TooShort => 2,
                    DecodeError::Crc => 3,
                    DecodeError::Message => 4,
                    DecodeError::TrailingBytes => 5,
                };
                debug!("frame rejected ({})", code);
                return None;
            }
        };
        if matches!(frame.cmd, Command::Heartbeat) {
            return Some(Received::Heartbeat);
        }
        if let Some((last, answer)) = self.last {
            // A retry repeats the last command's sequence number (and the command itself: a
            // different command under a reused number is a new command, e.g. a restarted host).
            if last.seq == frame.seq && last.cmd == frame.cmd {
                self.tx.push(answer);
                return Some(Received::Retry);
            }
        }
        Some(Received::Command(frame))
    }

    /// Answer a command: queue the answer and remember it for retries.
    pub fn answer(&mut self, frame: HostFrame, answer: RobotMsg) {
        self.last = Some((frame, answer));
        self.tx.push(answer);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_protocol::{Done, Faults, Mode, Outcome, Pose, Telemetry};

    fn telemetry(t: u64) -> RobotMsg {
        RobotMsg::Telemetry(Telemetry {
            time_us: t,
            pose: Pose::default(),
            wheel_speed: [0.0; 2],
            bumper: 0,
            mode: Mode::Idle,
            faults: Faults::NONE,
            active: None,
            last_done: None,
        })
    }

    fn decode_all(bytes: &[u8]) -> std::vec::Vec<RobotMsg> {
        let mut d = FrameDecoder::new();
        let mut out = std::vec::Vec::new();
        d.feed::<RobotMsg>(bytes, |r| out.push(r.expect("valid frame")));
        out
    }

    #[test]
    fn drains_frames_in_pieces() {
        let mut q = TxQueue::new();
        for s in 0..5 {
            q.push(RobotMsg::Ack { seq: s });
        }
        let mut bytes = std::vec::Vec::new();
        let mut buf = [0u8; 3];
        loop {
            let n = q.drain(&mut buf);
            if n == 0 {
                break;
            }
            bytes.extend_from_slice(&buf[..n]);
        }
        let msgs = decode_all(&bytes);
        assert_eq!(msgs.len(), 5);
        for (s, m) in msgs.iter().enumerate() {
            assert_eq!(*m, RobotMsg::Ack { seq: s as u16 });
        }
        assert!(q.is_empty());
    }

    #[test]
    fn telemetry_gives_way_to_acks_and_dones() {
        let mut q = TxQueue::new();
        q.push(telemetry(1));
        q.push(telemetry(2)); // replaces
        assert_eq!(q.len(), 1);
        for s in 0..(TX_QUEUE as u16 - 1) {
            q.push(RobotMsg::Ack { seq: s });
        }
        assert_eq!(q.len(), TX_QUEUE);
        let done = RobotMsg::Done(Done {
            seq: 99,
            outcome: Outcome::Completed,
            pose: Pose::default(),
            time_us: 5,
        });
        q.push(done);
        q.push(telemetry(3)); // no room: dropped... or replaces? None queued any more.
        assert_eq!(q.dropped(), 1);
        let mut buf = [0u8; 4096];
        let n = q.drain(&mut buf);
        let msgs = decode_all(&buf[..n]);
        assert!(!msgs.iter().any(|m| matches!(m, RobotMsg::Telemetry(_))));
        assert_eq!(msgs.last(), Some(&done));
        assert_eq!(msgs.len(), TX_QUEUE);
    }
}
