//! The host end of the link as a sans-IO state machine, in the manner of `quinn-proto`: it
//! owns no port, thread or clock, and is driven from outside.
//!
//! CONTRACT (the drivers in [`super::serial`] and `crate::sim::inprocess` follow it):
//!
//! ```text
//! let mut client = Client::new(now, ClientOptions::default());
//! let seq = client.hello(now);                       // or command(now, cmd), motion(…)
//! loop {
//!     while let Some(bytes) = client.poll_transmit(now) { port.write(&bytes) }
//!     while let Some(event) = client.poll_event() { … }
//!     // wait for bytes, at most until client.poll_timeout()
//!     client.handle_bytes(now, &bytes_read);          // any time bytes arrive
//!     if client.poll_timeout() <= Some(now) { client.handle_timeout(now) }
//! }
//! ```
//!
//! | what | where it lives |
//! |---|---|
//! | framing (`encode_frame`, `FrameDecoder`), rejected frames | here, through `wire`: the one place on the host that frames |
//! | `Hello`, version check (also of a foreign `HelloReply`), sequence collisions | [`Client::hello`], [`Client::handshake`] |
//! | sequence numbers, retries with the *same* number, giving up after `attempts` | [`Client::command`], [`Client::handle_timeout`], [`Client::take_answer`] |
//! | replies matched by number: duplicates and late replies ignored, any order | [`Client::handle_bytes`] |
//! | a motion's end: its `Done`, or read from the telemetry when the `Done` was lost, or its budget of robot time spent | [`Client::motion`], [`Client::take_motion_end`] |
//! | heartbeats paced by robot time, with a host-time fallback | [`Client::handle_bytes`], [`Client::handle_timeout`] |
//! | the emergency stop ahead of any command in flight, which is withdrawn, never resent | [`Client::emergency_stop`] |
//! | a dead link (no byte for `dead_link_timeout` of host time) | [`Client::link_dead`], [`Event::LinkDead`] |
//!
//! `now` is the driver's monotonic host time ([`HostTime`]): wall time since the port opened
//! for the serial driver, simulated time in process. Heartbeats (DESIGN.md, "Time"): the
//! robot's link watchdog counts robot time, so a heartbeat goes out whenever the telemetry shows
//! that a quarter of the watchdog period of *robot* time has passed since the last frame sent;
//! a quarter period of host time also triggers one, for a robot whose telemetry is off.
//!
//! A noisy wire (a frame from the robot rejected, or a gap in its telemetry, within the last
//! [`NOISY_FOR`] of host time) tightens the policy: heartbeats go every eighth of the watchdog
//! period (eight chances before the watchdog trips instead of four), a command is sent up to
//! twice `attempts` times, and a motion whose `Ack` was lost counts as accepted as soon as the
//! telemetry shows it running or ended under its number. A clean wire keeps the plain policy.

use std::collections::{HashMap, VecDeque};
use std::time::Duration;

use pushbot_protocol::{
    Command, ContactEvent, Done, HostFrame, NackReason, PROTOCOL_VERSION, RobotMsg, Telemetry,
};

mod estop;
mod heard;
mod types;
mod wire;

use heard::Listened;
pub use heard::heartbeat_due;

pub use types::{
    Answer, ClientOptions, Event, Handshake, Heard, HostTime, LinkStats, MotionEnd, RobotEvent,
};
use wire::{Incoming, Reader};

/// How many unclaimed answers and motion ends to keep.
const MAX_KEPT: usize = 64;
/// How many `Done` sequence numbers to remember, to ignore a repeated `Done`.
const RECENT_DONES: usize = 16;
/// How many rounds of `Hello` a sequence collision may cost.
const HELLO_ROUNDS: u32 = 3;
/// How long a rejected frame or a telemetry gap marks the wire as noisy, host time.
pub const NOISY_FOR: Duration = Duration::from_secs(5);
/// How many of its latest frames the host remembers, to recognise them coming back (echo).
const ECHO_FRAMES: usize = 8;
/// A flood: more bytes per second than a serial line at 115 200 baud can carry.
pub const FLOOD_BYTES_PER_S: f64 = 11_520.0;

/// A command sent and not yet answered.
#[derive(Debug, Clone, Copy)]
struct Pending {
    frame: HostFrame,
    sent: u32,
    max: u32,
    deadline: HostTime,
}

/// A motion being watched for its end.
#[derive(Debug, Clone, Copy)]
struct Watched {
    seq: u16,
    budget_us: u64,
    acked: bool,
    started_us: Option<u64>,
}

/// The handshake under way.
#[derive(Debug, Clone, Copy)]
struct HelloRound {
    seq: u16,
    round: u32,
}

/// The link client. See the module docs for its contract.
pub struct Client {
    opts: ClientOptions,
    reader: Reader,
    transmits: VecDeque<Vec<u8>>,
    events: VecDeque<Event>,
    next_seq: u16,
    heartbeat_seq: u16,
    pending: Vec<Pending>,
    answers: HashMap<u16, Answer>,
    hello: Option<HelloRound>,
    handshake: Option<Handshake>,
    watched: Vec<Watched>,
    motion_ends: HashMap<u16, MotionEnd>,
    recent_dones: VecDeque<u16>,
    telemetry: Option<Telemetry>,
    contacts: Vec<ContactEvent>,
    stats: LinkStats,
    last_rx: HostTime,
    last_tx: HostTime,
    last_tx_robot_us: Option<u64>,
    watchdog_ms: u16,
    heartbeats_paused: bool,
    dead_reported: bool,
    /// The wire counts as noisy until then (see the module docs).
    noisy_until: Option<HostTime>,
    /// The shortest step between telemetries seen, µs of robot time (the robot's period).
    telemetry_step_us: Option<u64>,
    /// What arrived since the latest `Hello`.
    listened: Listened,
    /// The latest frames sent (without delimiters), kept until a robot frame arrives: an echo
    /// of them is not the robot talking.
    sent_frames: VecDeque<Vec<u8>>,
}

impl Client {
    /// A client whose link opened at `now`; nothing sent yet.
    pub fn new(now: HostTime, opts: ClientOptions) -> Client {
        Client {
            reader: Reader::new(),
            transmits: VecDeque::new(),
            events: VecDeque::new(),
            next_seq: opts.first_seq,
            heartbeat_seq: 0,
            pending: Vec::new(),
            answers: HashMap::new(),
            hello: None,
            handshake: None,
            watched: Vec::new(),
            motion_ends: HashMap::new(),
            recent_dones: VecDeque::new(),
            telemetry: None,
            contacts: Vec::new(),
            stats: LinkStats::default(),
            last_rx: now,
            last_tx: now,
            last_tx_robot_us: None,
            watchdog_ms: opts.watchdog_ms,
            heartbeats_paused: false,
            dead_reported: false,
            noisy_until: None,
            telemetry_step_us: None,
            listened: Listened {
                since: now,
                ..Listened::default()
            },
            sent_frames: VecDeque::new(),
            opts,
        }
    }

    /// The options.
    pub fn options(&self) -> &ClientOptions {
        &self.opts
    }

    /// The sequence number the next command will take.
    pub fn next_seq(&self) -> u16 {
        self.next_seq
    }

    fn take_seq(&mut self) -> u16 {
        let seq = self.next_seq;
        self.next_seq = seq.wrapping_add(1);
        seq
    }

    /// Start the handshake: send `Hello` with the offered version, resent every
    /// `ack_timeout` until `hello_timeout` has passed (at least `attempts` times). Its end is
    /// [`Client::handshake`] (and an event).
    pub fn hello(&mut self, now: HostTime) -> u16 {
        self.handshake = None;
        self.listened = Listened {
            since: now,
            ..Listened::default()
        };
        self.hello_round(now, 0)
    }

    fn hello_attempts(&self) -> u32 {
        let per_attempt = self.opts.ack_timeout.max(Duration::from_millis(1));
        self.opts
            .attempts
            .max((self.opts.hello_timeout.as_millis() / per_attempt.as_millis()) as u32)
    }

    fn hello_round(&mut self, now: HostTime, round: u32) -> u16 {
        if let Some(h) = self.hello.take() {
            self.pending.retain(|p| p.frame.seq != h.seq);
        }
        let seq = self.take_seq();
        self.hello = Some(HelloRound { seq, round });
        let cmd = Command::Hello {
            protocol: self.opts.protocol_version,
        };
        let max = self.hello_attempts();
        self.start(now, HostFrame { seq, cmd }, max);
        seq
    }

    /// Send a command with the next sequence number; resent with the same number after
    /// `ack_timeout`, `attempts` times in all. Its answer is [`Client::take_answer`].
    pub fn command(&mut self, now: HostTime, cmd: Command) -> u16 {
        let seq = self.take_seq();
        let max = self.opts.attempts;
        self.start(now, HostFrame { seq, cmd }, max);
        seq
    }

    /// Send a motion command, as [`Client::command`], and watch for its end: its `Done`, the
    /// telemetry's `last_done` (when the `Done` frame is lost), or `budget_us` of robot time
    /// from the acknowledgement. The end is [`Client::take_motion_end`].
    pub fn motion(&mut self, now: HostTime, cmd: Command, budget_us: u64) -> u16 {
        let seq = self.command(now, cmd);
        self.watched.retain(|w| w.seq != seq);
        self.watched.push(Watched {
            seq,
            budget_us,
            acked: false,
            started_us: None,
        });
        seq
    }

    fn start(&mut self, now: HostTime, frame: HostFrame, max: u32) {
        self.heartbeat_seq = frame.seq;
        self.send_frame(now, &frame);
        self.pending.push(Pending {
            frame,
            sent: 1,
            max,
            deadline: now.after(self.opts.ack_timeout),
        });
    }

    fn send_frame(&mut self, now: HostTime, frame: &HostFrame) {
        match wire::encode(frame) {
            Ok(bytes) => {
                if self.stats.frames_ok == 0 {
                    if self.sent_frames.len() >= ECHO_FRAMES {
                        self.sent_frames.pop_front();
                    }
                    self.sent_frames
                        .push_back(bytes.iter().copied().filter(|&b| b != 0).collect());
                }
                self.transmits.push_back(bytes);
            }
            Err(e) => {
                tracing::error!("cannot frame {:?}: {e}", frame.cmd);
                return;
            }
        }
        self.stats.frames_sent += 1;
        if frame.cmd == Command::Heartbeat {
            self.stats.heartbeats_sent += 1;
        }
        self.last_tx = now;
        self.last_tx_robot_us = self.telemetry.map(|t| t.time_us);
    }

    /// Queue raw bytes for the robot, bypassing framing (a diagnostic to inject garbage; not
    /// counted as a frame sent).
    pub fn send_raw(&mut self, bytes: &[u8]) {
        self.transmits.push_back(bytes.to_vec());
    }

    /// The next bytes to write to the robot, in order.
    pub fn poll_transmit(&mut self, _now: HostTime) -> Option<Vec<u8>> {
        self.transmits.pop_front()
    }

    /// The next event, in order.
    pub fn poll_event(&mut self) -> Option<Event> {
        self.events.pop_front()
    }

    /// When [`Client::handle_timeout`] wants to be called next.
    pub fn poll_timeout(&self) -> Option<HostTime> {
        let retries = self.pending.iter().map(|p| p.deadline);
        let heartbeat = (!self.heartbeats_paused).then(|| {
            self.last_tx.after(Duration::from_micros(
                u64::from(self.paced_watchdog_ms(self.last_tx)) * 250,
            ))
        });
        let dead = (!self.dead_reported).then(|| {
            self.last_rx
                .after(self.opts.dead_link_timeout)
                .after(Duration::from_micros(1))
        });
        retries.chain(heartbeat).chain(dead).min()
    }

    /// Bytes from the robot arrived at `now`.
    pub fn handle_bytes(&mut self, now: HostTime, bytes: &[u8]) {
        if !bytes.is_empty() {
            self.last_rx = now;
            self.dead_reported = false;
            self.stats.bytes_received += bytes.len() as u64;
            self.listened.bytes += bytes.len() as u64;
            self.listened.zeros += bytes.iter().filter(|&&b| b == 0).count() as u64;
        }
        for &b in bytes {
            let incoming = self.reader.push(b);
            if b == 0 && incoming.is_some() && self.is_echo() {
                self.listened.echoes += 1;
                continue;
            }
            match incoming {
                None => {}
                Some(Incoming::Msg(msg)) => {
                    self.listened.frames += 1;
                    self.sent_frames.clear();
                    self.stats.frames_ok += 1;
                    self.handle_msg(now, msg);
                }
                Some(Incoming::Rejected {
                    error,
                    foreign_hello,
                }) => {
                    tracing::debug!("rejected frame from the robot: {error}");
                    self.stats.frames_rejected += 1;
                    self.mark_noisy(now);
                    if let (Some(robot), Some(_)) = (foreign_hello, self.hello) {
                        self.finish_hello(Handshake::VersionMismatch {
                            host: self.opts.protocol_version,
                            robot,
                        });
                    }
                }
            }
        }
        self.heartbeat_if_due(now);
    }

    /// Time passed: resend or give up unanswered commands, send a heartbeat when due, report a
    /// dead link.
    pub fn handle_timeout(&mut self, now: HostTime) {
        let mut i = 0;
        while i < self.pending.len() {
            let p = self.pending[i];
            if p.deadline > now {
                i += 1;
                continue;
            }
            // A noisy wire earns more attempts only once the robot was heard: a line that
            // never carried one pushbot frame is not a robot on a bad wire.
            let noisy = self.noisy(now) && self.stats.frames_ok > 0;
            if p.sent < p.max || (noisy && p.sent < 2 * p.max) {
                tracing::debug!("no answer to {:?} #{}; resending", p.frame.cmd, p.frame.seq);
                self.stats.retries += 1;
                self.send_frame(now, &p.frame);
                self.pending[i].sent += 1;
                self.pending[i].deadline = now.after(self.opts.ack_timeout);
                i += 1;
                continue;
            }
            self.pending.remove(i);
            let seq = p.frame.seq;
            self.events.push_back(Event::GaveUp {
                seq,
                attempts: p.sent,
            });
            if self.hello.is_some_and(|h| h.seq == seq) {
                let heard = self.heard(now);
                self.finish_hello(Handshake::NoAnswer {
                    attempts: p.sent,
                    heard,
                });
            } else {
                self.watched.retain(|w| w.seq != seq);
                self.answer(seq, Answer::GaveUp { attempts: p.sent });
            }
        }
        self.heartbeat_if_due(now);
        if let Some(silent) = self.link_dead(now)
            && !self.dead_reported
        {
            self.dead_reported = true;
            self.events.push_back(Event::LinkDead { silent });
        }
    }

    fn answer(&mut self, seq: u16, answer: Answer) {
        if self.answers.len() >= MAX_KEPT {
            self.answers.clear();
        }
        self.answers.insert(seq, answer);
    }

    fn finish_hello(&mut self, outcome: Handshake) {
        if let Some(h) = self.hello.take() {
            self.pending.retain(|p| p.frame.seq != h.seq);
        }
        self.handshake = Some(outcome);
        self.events.push_back(match outcome {
            Handshake::Connected(h) => Event::Connected(h),
            Handshake::VersionMismatch { host, robot } => Event::VersionMismatch { host, robot },
            // Its GaveUp event was queued already.
            Handshake::NoAnswer { .. } => return,
        });
    }

    /// The robot answered the `Hello` with an `Ack`/`Nack`: it took our number for a retry of
    /// an earlier session's command. Try again with the next number, a few times.
    fn hello_collided(&mut self, now: HostTime, h: HelloRound) {
        if h.round + 1 < HELLO_ROUNDS {
            self.hello_round(now, h.round + 1);
        } else {
            let attempts = self
                .pending
                .iter()
                .find(|p| p.frame.seq == h.seq)
                .map_or(0, |p| p.sent);
            let heard = self.heard(now);
            self.finish_hello(Handshake::NoAnswer {
                attempts: attempts.max(self.hello_attempts()),
                heard,
            });
        }
    }

    fn handle_msg(&mut self, now: HostTime, msg: RobotMsg) {
        let hello = self.hello;
        match msg {
            RobotMsg::HelloReply(h) => {
                if hello.is_none() {
                    return;
                }
                let offered = self.opts.protocol_version;
                self.finish_hello(
                    if !h.accepted || h.protocol != offered || h.protocol != PROTOCOL_VERSION {
                        Handshake::VersionMismatch {
                            host: offered,
                            robot: h.protocol,
                        }
                    } else {
                        Handshake::Connected(h)
                    },
                );
            }
            RobotMsg::Ack { seq } => match hello {
                Some(h) if h.seq == seq => self.hello_collided(now, h),
                _ => {
                    if !self.take_pending(seq) {
                        return; // a duplicate or late answer
                    }
                    let at_us = self.telemetry.map(|t| t.time_us);
                    if let Some(w) = self.watched.iter_mut().find(|w| w.seq == seq) {
                        w.acked = true;
                        w.started_us = at_us;
                    }
                    self.answer(seq, Answer::Ack { at_us });
                    self.events.push_back(Event::Ack { seq });
                }
            },
            RobotMsg::Nack { seq, reason } => match (hello, reason) {
                (Some(h), NackReason::VersionMismatch { robot }) if h.seq == seq => {
                    self.finish_hello(Handshake::VersionMismatch {
                        host: self.opts.protocol_version,
                        robot,
                    });
                }
                (Some(h), _) if h.seq == seq => self.hello_collided(now, h),
                _ => {
                    if !self.take_pending(seq) {
                        return;
                    }
                    self.watched.retain(|w| w.seq != seq);
                    self.answer(seq, Answer::Nack(reason));
                    self.events.push_back(Event::Nack { seq, reason });
                }
            },
            RobotMsg::Done(d) => self.done(d, false),
            RobotMsg::Telemetry(t) => {
                self.telemetry_gap(now, &t);
                self.telemetry = Some(t);
                self.events.push_back(Event::Telemetry(t));
                self.ack_from_telemetry(now, &t);
                self.watch_telemetry(&t);
            }
            RobotMsg::Contact(c) => {
                self.contacts.push(c);
                self.events.push_back(Event::Contact(c));
            }
        }
    }

    /// Learn the robot's telemetry period; a step of more than one and a half periods means a
    /// telemetry frame was lost: the wire is noisy.
    fn telemetry_gap(&mut self, now: HostTime, t: &Telemetry) {
        let Some(last) = self.telemetry.map(|l| l.time_us) else {
            return;
        };
        if t.time_us <= last {
            return;
        }
        let step = t.time_us - last;
        let period = *self.telemetry_step_us.get_or_insert(step);
        if step < period {
            self.telemetry_step_us = Some(step);
        } else if 2 * step > 3 * period {
            self.mark_noisy(now);
        }
    }

    /// On a noisy wire, a motion whose `Ack` was lost is accepted when the telemetry shows it
    /// running or ended under its number.
    fn ack_from_telemetry(&mut self, now: HostTime, t: &Telemetry) {
        if !self.noisy(now) {
            return;
        }
        let seen: Vec<u16> = self
            .watched
            .iter()
            .filter(|w| !w.acked)
            .map(|w| w.seq)
            .filter(|&seq| t.active == Some(seq) || t.last_done.is_some_and(|(d, _)| d == seq))
            .collect();
        for seq in seen {
            if !self.take_pending(seq) {
                continue;
            }
            tracing::debug!("#{seq}: acknowledgement read from the telemetry");
            if let Some(w) = self.watched.iter_mut().find(|w| w.seq == seq) {
                w.acked = true;
                w.started_us = Some(t.time_us);
            }
            self.answer(
                seq,
                Answer::Ack {
                    at_us: Some(t.time_us),
                },
            );
            self.events.push_back(Event::Ack { seq });
        }
    }

    /// Remove the pending command `seq`; whether there was one.
    fn take_pending(&mut self, seq: u16) -> bool {
        let before = self.pending.len();
        self.pending.retain(|p| p.frame.seq != seq);
        self.pending.len() != before
    }

    fn done(&mut self, done: Done, recovered: bool) {
        if self.recent_dones.contains(&done.seq) {
            return; // a repeated Done
        }
        if self.recent_dones.len() >= RECENT_DONES {
            self.recent_dones.pop_front();
        }
        self.recent_dones.push_back(done.seq);
        if let Some(i) = self.watched.iter().position(|w| w.seq == done.seq) {
            let w = self.watched.remove(i);
            self.end_motion(
                done.seq,
                MotionEnd::Done {
                    done,
                    recovered,
                    started_us: w.started_us,
                },
            );
        }
        self.events.push_back(Event::Done { done, recovered });
    }

    fn end_motion(&mut self, seq: u16, end: MotionEnd) {
        if self.motion_ends.len() >= MAX_KEPT {
            self.motion_ends.clear();
        }
        self.motion_ends.insert(seq, end);
    }

    fn watch_telemetry(&mut self, t: &Telemetry) {
        let mut i = 0;
        while i < self.watched.len() {
            let w = &mut self.watched[i];
            if !w.acked {
                i += 1;
                continue;
            }
            let start = *w.started_us.get_or_insert(t.time_us);
            let seq = w.seq;
            if let Some((done_seq, outcome)) = t.last_done
                && done_seq == seq
                && t.active != Some(seq)
            {
                let done = Done {
                    seq,
                    outcome,
                    pose: t.pose,
                    time_us: t.time_us,
                };
                self.done(done, true);
                if self.watched.get(i).is_none_or(|w| w.seq != seq) {
                    continue; // `done` removed it
                }
                // A `Done` under this number was seen already (a stale one, from before the
                // motion was sent): `done` ignored it; the motion stays watched, on its budget.
            }
            let budget_us = self.watched[i].budget_us;
            if t.time_us.saturating_sub(start) > budget_us {
                self.watched.remove(i);
                self.end_motion(seq, MotionEnd::TimedOut { budget_us });
                self.events
                    .push_back(Event::MotionTimedOut { seq, budget_us });
                continue;
            }
            i += 1;
        }
    }

    /// How the handshake ended, once it has.
    pub fn handshake(&self) -> Option<Handshake> {
        self.handshake
    }

    /// The answer to command `seq`, once there is one (taken: asked once).
    pub fn take_answer(&mut self, seq: u16) -> Option<Answer> {
        self.answers.remove(&seq)
    }

    /// The end of motion `seq`, once it ended (taken: asked once).
    pub fn take_motion_end(&mut self, seq: u16) -> Option<MotionEnd> {
        self.motion_ends.remove(&seq)
    }

    /// The latest telemetry, if any arrived.
    pub fn telemetry(&self) -> Option<Telemetry> {
        self.telemetry
    }

    /// Every bumper contact reported since the link opened.
    pub fn contacts(&self) -> &[ContactEvent] {
        &self.contacts
    }

    /// Link counters.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// How long nothing arrived, when that is longer than the dead-link time.
    pub fn link_dead(&self, now: HostTime) -> Option<Duration> {
        let silent = now.since(self.last_rx);
        (silent > self.opts.dead_link_timeout).then_some(silent)
    }

    /// The watchdog period heartbeats are paced for, ms of robot time.
    pub fn watchdog_ms(&self) -> u16 {
        self.watchdog_ms
    }

    /// Pace heartbeats for a watchdog of `ms` of robot time.
    pub fn set_watchdog_ms(&mut self, ms: u16) {
        self.watchdog_ms = ms;
    }

    /// Stop (`true`) or resume heartbeats, as if the host went quiet (a test hook: the robot's
    /// watchdog should then stop it).
    pub fn pause_heartbeats(&mut self, paused: bool) {
        self.heartbeats_paused = paused;
    }
}
