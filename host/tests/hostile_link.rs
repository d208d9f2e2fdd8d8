//! Hostile bytes into the host's link client, through its real byte input
//! ([`Client::handle_bytes`]): valid robot messages of every kind (`HelloReply`, `Ack`,
//! `Nack`, `Done`, `Telemetry`, `Contact`) with random fields and sequence numbers mostly near
//! the client's own, mutated (see `firmware/tests/hostile_gen`) and fed in random chunks while
//! the client issues commands, motions and hellos and its timers run, seeded. After every chunk:
//!
//! * `Ack`/`Nack` events only for commands the client issued and has not had answered,
//!   `GaveUp` only for its pending commands or hellos, each at most once;
//! * a motion ends at most once (`Done`, recovered `Done` or `MotionTimedOut`, each matching
//!   [`Client::take_motion_end`]); no `Done` is reported twice within the client's window of
//!   recent `Done`s; a recovered `Done` only for a motion being watched;
//! * one handshake outcome per `hello`;
//! * the counters of frames decoded and rejected, the bytes received, the telemetry and the
//!   contacts agree with a reference `FrameDecoder` fed the same bytes.
//!
//! Frame count: 520 000 generated frames (with `firmware/tests/hostile.rs`, over 10⁶),
//! about 1 s at the test profile (opt-level 1).

use std::collections::{HashMap, HashSet, VecDeque};

use pushbot::link::{Client, ClientOptions, Event, HostTime, MotionEnd};
use pushbot_protocol::{
    Command, ContactEvent, Done, Faults, FirmwareVersion, FrameDecoder, Geometry, HelloReply,
    MAX_FRAME, Mode, NackReason, Outcome, PROTOCOL_VERSION, Pose, RobotMsg, Telemetry,
    encode_frame,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "../../firmware/tests/hostile_gen/mod.rs"]
mod hostile_gen;

use hostile_gen::{MUTATIONS, chunks, mutate};

/// Frames generated for the client.
const FRAMES: u64 = 520_000;
/// The client's window of remembered `Done`s (`RECENT_DONES` in the client).
const RECENT_DONES: usize = 16;

fn float(rng: &mut impl Rng) -> f32 {
    match rng.random_range(0..10) {
        0 => f32::NAN,
        1 => f32::from_bits(rng.random()),
        _ => rng.random_range(-2.0..2.0),
    }
}

fn pose(rng: &mut impl Rng) -> Pose {
    Pose {
        x: float(rng),
        y: float(rng),
        theta: float(rng),
    }
}

fn outcome(rng: &mut impl Rng) -> Outcome {
    match rng.random_range(0..5) {
        0 => Outcome::Completed,
        1 => Outcome::Contact,
        2 => Outcome::Aborted,
        3 => Outcome::Fault(Faults(rng.random())),
        _ => Outcome::Timeout,
    }
}

fn mode(rng: &mut impl Rng) -> Mode {
    [
        Mode::Idle,
        Mode::Velocity,
        Mode::Move,
        Mode::Spin,
        Mode::Advance,
        Mode::Braking,
        Mode::Faulted,
    ][rng.random_range(0..7)]
}

/// A robot message of a random kind; sequence numbers mostly among the client's latest.
fn robot_msg(rng: &mut impl Rng, next_seq: u16, robot_us: u64) -> RobotMsg {
    let mut seq = || {
        if rng.random_bool(0.85) {
            next_seq.wrapping_sub(rng.random_range(1..=8))
        } else {
            rng.random()
        }
    };
    let (s1, s2) = (seq(), seq());
    match rng.random_range(0..12) {
        0 => RobotMsg::HelloReply(HelloReply {
            protocol: if rng.random_bool(0.8) {
                PROTOCOL_VERSION
            } else {
                rng.random()
            },
            accepted: rng.random_bool(0.8),
            firmware: FirmwareVersion {
                major: rng.random(),
                minor: rng.random(),
                patch: rng.random(),
            },
            geometry: Geometry {
                wheel_base: float(rng),
                wheel_radius: float(rng),
                bumper_radius: float(rng),
                encoder_cpr: rng.random(),
                control_hz: rng.random(),
            },
        }),
        1..=3 => RobotMsg::Ack { seq: s1 },
        4 => RobotMsg::Nack {
            seq: s1,
            reason: match rng.random_range(0..4) {
                0 => NackReason::VersionMismatch {
                    robot: rng.random(),
                },
                1 => NackReason::NoSession,
                2 => NackReason::OutOfRange,
                _ => NackReason::Faulted(Faults(rng.random())),
            },
        },
        5..=6 => RobotMsg::Done(Done {
            seq: s1,
            outcome: outcome(rng),
            pose: pose(rng),
            time_us: robot_us,
        }),
        7..=10 => RobotMsg::Telemetry(Telemetry {
            time_us: robot_us,
            pose: pose(rng),
            wheel_speed: [float(rng), float(rng)],
            bumper: rng.random(),
            mode: mode(rng),
            faults: Faults(rng.random()),
            active: rng.random_bool(0.5).then_some(s1),
            last_done: rng.random_bool(0.6).then(|| (s2, outcome(rng))),
        }),
        _ => RobotMsg::Contact(ContactEvent {
            time_us: robot_us,
            bumper: rng.random(),
            pose: pose(rng),
        }),
    }
}

fn encoded(m: &RobotMsg) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(m, &mut buf).expect("every robot message fits");
    buf[..n].to_vec()
}

/// What was issued, as the test sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Issued {
    Command,
    Motion,
    Hello,
}

/// The test's model of the client, checked against its events.
#[derive(Default)]
struct Model {
    /// Issued and not yet answered or given up.
    pending: HashMap<u16, Issued>,
    /// Motions not yet ended.
    watched: HashSet<u16>,
    /// The sequence number the client takes next, as last seen.
    next_seq: u16,
    hello_open: bool,
    recent_dones: VecDeque<u16>,
    telemetry_events: u64,
    contact_events: u64,
    motion_ends: u64,
}

impl Model {
    /// Sequence numbers the client took on its own (a new hello round) are hellos.
    fn sync(&mut self, c: &Client) {
        while self.next_seq != c.next_seq() {
            self.pending.insert(self.next_seq, Issued::Hello);
            self.next_seq = self.next_seq.wrapping_add(1);
        }
    }

    fn issue(&mut self, c: &Client, seq: u16, what: Issued) {
        self.next_seq = self.next_seq.wrapping_add(1);
        assert_eq!(self.next_seq, c.next_seq());
        self.pending.insert(seq, what);
        if what == Issued::Motion {
            self.watched.insert(seq);
        }
        if what == Issued::Hello {
            self.hello_open = true;
        }
    }

    fn end_motion(&mut self, c: &mut Client, seq: u16, want: impl Fn(&MotionEnd) -> bool) {
        self.motion_ends += 1;
        let end = c.take_motion_end(seq);
        assert!(end.as_ref().is_some_and(&want), "motion {seq} end {end:?}");
        assert_eq!(c.take_motion_end(seq), None, "motion {seq} ended twice");
    }

    /// Check every queued event against the model.
    fn events(&mut self, c: &mut Client) {
        self.sync(c);
        while let Some(e) = c.poll_event() {
            match e {
                Event::Ack { seq } | Event::Nack { seq, .. } => {
                    let what = self.pending.remove(&seq);
                    assert!(
                        matches!(what, Some(Issued::Command | Issued::Motion)),
                        "{e:?} for a command not pending ({what:?})"
                    );
                    if let Event::Nack { .. } = e {
                        self.watched.remove(&seq);
                    }
                }
                Event::GaveUp { seq, .. } => {
                    let what = self.pending.remove(&seq);
                    assert!(what.is_some(), "{e:?} for nothing pending");
                    self.watched.remove(&seq);
                }
                Event::MotionTimedOut { seq, budget_us } => {
                    assert!(self.watched.remove(&seq), "{e:?} for no watched motion");
                    self.end_motion(c, seq, |m| *m == MotionEnd::TimedOut { budget_us });
                }
                Event::Done { done, recovered } => {
                    assert!(
                        !self.recent_dones.contains(&done.seq),
                        "Done for {} twice: {e:?}",
                        done.seq
                    );
                    if self.recent_dones.len() >= RECENT_DONES {
                        self.recent_dones.pop_front();
                    }
                    self.recent_dones.push_back(done.seq);
                    let watched = self.watched.remove(&done.seq);
                    assert!(
                        watched || !recovered,
                        "recovered {e:?} for no watched motion"
                    );
                    if watched {
                        let same = |m: &MotionEnd| {
                            matches!(m, MotionEnd::Done { done: d, recovered: r, .. }
                                if format!("{d:?}") == format!("{done:?}") && *r == recovered)
                        };
                        self.end_motion(c, done.seq, same);
                    }
                }
                Event::Connected(_) | Event::VersionMismatch { .. } => {
                    assert!(self.hello_open, "{e:?} with no hello under way");
                    self.hello_open = false;
                }
                Event::Telemetry(_) => self.telemetry_events += 1,
                Event::Contact(_) => self.contact_events += 1,
                Event::LinkDead { .. } => {}
            }
        }
        // A handshake that ended without an event (too many sequence collisions) ended too.
        if c.handshake().is_some() {
            self.hello_open = false;
        }
    }
}

/// The reference: the protocol's own decoder over the same bytes.
#[derive(Default)]
struct Reference {
    ok: u64,
    rejected: u64,
    telemetry: u64,
    contacts: u64,
    last_telemetry: Option<Telemetry>,
}

/// A command for the client to send: a motion (with its budget) or not.
fn command(rng: &mut impl Rng) -> (Command, Option<u64>) {
    match rng.random_range(0..6) {
        0 => (Command::Stop, None),
        1 => (Command::ClearFaults, None),
        2 => (Command::ResetOdometry(Pose::default()), None),
        3 => (
            Command::Move {
                distance: 0.1,
                speed: 0.1,
                stop_on_contact: rng.random(),
            },
            Some(rng.random_range(0..3_000_000)),
        ),
        4 => (
            Command::Spin {
                angle: 1.0,
                rate: 1.0,
            },
            Some(rng.random_range(0..3_000_000)),
        ),
        _ => (
            Command::AdvanceUntilContact {
                max_distance: 0.5,
                speed: 0.1,
            },
            Some(rng.random_range(0..3_000_000)),
        ),
    }
}

fn run(seed: u64, frames: u64) -> (Model, [u64; MUTATIONS.len()]) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut now = HostTime::from_micros(0);
    let opts = ClientOptions {
        first_seq: rng.random(),
        ..ClientOptions::default()
    };
    let mut c = Client::new(now, opts);
    let mut model = Model {
        next_seq: c.next_seq(),
        ..Model::default()
    };
    let seq = c.hello(now);
    model.issue(&c, seq, Issued::Hello);
    let mut reference = FrameDecoder::new();
    let mut r = Reference::default();
    let mut by_kind = [0u64; MUTATIONS.len()];
    let mut bytes_fed = 0u64;
    let mut robot_us: u64 = 0;
    let mut generated = 0u64;
    let mut stream = Vec::new();
    while generated < frames {
        now = now.after(std::time::Duration::from_micros(
            rng.random_range(0..30_000),
        ));
        robot_us = if rng.random_bool(0.001) {
            rng.random_range(0..1_000_000) // the robot restarted
        } else {
            robot_us + rng.random_range(0..40_000)
        };
        match rng.random_range(0..100) {
            0..=1 => {
                let seq = c.hello(now);
                model.issue(&c, seq, Issued::Hello);
            }
            2..=24 => {
                let (cmd, budget) = command(&mut rng);
                let (seq, what) = match budget {
                    Some(b) => (c.motion(now, cmd, b), Issued::Motion),
                    None => (c.command(now, cmd), Issued::Command),
                };
                model.issue(&c, seq, what);
            }
            _ => {}
        }
        while c.poll_transmit(now).is_some() {}
        stream.clear();
        for _ in 0..rng.random_range(1..=6) {
            let m = robot_msg(&mut rng, c.next_seq(), robot_us);
            let other = robot_msg(&mut rng, c.next_seq(), robot_us);
            let mutated = mutate(&mut rng, &encoded(&m), &encoded(&other), &mut stream);
            by_kind[mutated.kind] += 1;
            generated += 1;
        }
        let mut from = 0;
        for end in chunks(&mut rng, stream.len(), 48) {
            let chunk = &stream[from..end];
            from = end;
            c.handle_bytes(now, chunk);
            bytes_fed += chunk.len() as u64;
            reference.feed::<RobotMsg>(chunk, |m| match m {
                Ok(m) => {
                    r.ok += 1;
                    match m {
                        RobotMsg::Telemetry(t) => {
                            r.telemetry += 1;
                            r.last_telemetry = Some(t);
                        }
                        RobotMsg::Contact(_) => r.contacts += 1,
                        _ => {}
                    }
                }
                Err(_) => r.rejected += 1,
            });
            model.events(&mut c);
            let s = c.stats();
            assert_eq!(
                (s.frames_ok, s.frames_rejected, s.bytes_received),
                (r.ok, r.rejected, bytes_fed),
                "seed {seed}: counters disagree with the reference decoder"
            );
        }
        if c.poll_timeout().is_some_and(|t| t <= now) {
            c.handle_timeout(now);
            model.events(&mut c);
        }
        assert_eq!(model.telemetry_events, r.telemetry, "seed {seed}");
        assert_eq!(model.contact_events, r.contacts, "seed {seed}");
        assert_eq!(c.contacts().len() as u64, r.contacts, "seed {seed}");
        assert_eq!(
            format!("{:?}", c.telemetry()),
            format!("{:?}", r.last_telemetry),
            "seed {seed}: latest telemetry"
        );
    }
    (model, by_kind)
}

#[test]
fn hostile_frames_into_the_client() {
    let t0 = std::time::Instant::now();
    let (model, by_kind) = run(0x5eed_0019, FRAMES);
    eprintln!(
        "{FRAMES} frames, mutations {by_kind:?}, {} motion ends, {} telemetry, in {:?}",
        model.motion_ends,
        model.telemetry_events,
        t0.elapsed()
    );
    // The run exercised what it claims.
    assert!(by_kind.iter().all(|&k| k > 1000), "{by_kind:?}");
    assert!(model.motion_ends > 1000);
}

/// Found by the run above: a `Done` under a number the client later gives a motion, then a
/// telemetry naming that motion as ended, made `watch_telemetry` loop forever (the repeated
/// `Done` was ignored and the motion never left the watch list). Now the motion stays watched
/// and ends by its budget.
#[test]
fn a_stale_done_under_a_motions_number_does_not_hang_the_client() {
    let now = HostTime::from_micros(0);
    let mut c = Client::new(now, ClientOptions::default());
    let seq = c.next_seq();
    let stale = Done {
        seq,
        outcome: Outcome::Completed,
        pose: Pose::default(),
        time_us: 1,
    };
    c.handle_bytes(now, &encoded(&RobotMsg::Done(stale)));
    let motion = Command::Spin {
        angle: 1.0,
        rate: 1.0,
    };
    assert_eq!(c.motion(now, motion, 1_000), seq);
    c.handle_bytes(now, &encoded(&RobotMsg::Ack { seq }));
    let telemetry = |time_us| {
        RobotMsg::Telemetry(Telemetry {
            time_us,
            pose: Pose::default(),
            wheel_speed: [0.0; 2],
            bumper: 0,
            mode: Mode::Idle,
            faults: Faults::NONE,
            active: None,
            last_done: Some((seq, Outcome::Completed)),
        })
    };
    c.handle_bytes(now, &encoded(&telemetry(10))); // looped forever before the fix
    assert_eq!(c.take_motion_end(seq), None);
    c.handle_bytes(now, &encoded(&telemetry(10_000)));
    assert_eq!(
        c.take_motion_end(seq),
        Some(MotionEnd::TimedOut { budget_us: 1_000 })
    );
}
