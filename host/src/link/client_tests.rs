//! The link client's state machine, byte by byte, with no I/O at all: no port, thread, sleep or
//! clock. The robot side is the real firmware core ([`pushbot_firmware::Core`]) or hand-built
//! [`RobotMsg`] frames; host time is whatever each test says it is.

use std::time::Duration;

use pushbot_firmware::{Core, Inputs, RobotParams};
use pushbot_protocol::{
    Command, ConfigUpdate, Done, FirmwareVersion, FrameDecoder, Geometry, HelloReply, HostFrame,
    MAX_FRAME, Mode, NackReason, Outcome, PROTOCOL_VERSION, Pose, RobotMsg, Telemetry,
    encode_frame,
};

use super::client::{
    Answer, Client, ClientOptions, Event, Handshake, Heard, HostTime, MotionEnd, heartbeat_due,
};

fn ms(v: u64) -> HostTime {
    HostTime::from_micros(v * 1000)
}

fn opts() -> ClientOptions {
    ClientOptions {
        first_seq: 100,
        ..ClientOptions::default()
    }
}

/// Robot messages as the robot frames them.
fn wire(msgs: &[RobotMsg]) -> Vec<u8> {
    let mut out = Vec::new();
    for m in msgs {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode_frame(m, &mut buf).unwrap();
        out.extend_from_slice(&buf[..n]);
    }
    out
}

/// Everything the client wants sent, as bytes and as the frames the robot decodes.
fn sent(c: &mut Client, now: HostTime) -> (Vec<u8>, Vec<HostFrame>) {
    let mut bytes = Vec::new();
    while let Some(b) = c.poll_transmit(now) {
        bytes.extend(b);
    }
    let mut dec = FrameDecoder::new();
    let mut frames = Vec::new();
    dec.feed::<HostFrame>(&bytes, |f| frames.push(f.unwrap()));
    (bytes, frames)
}

fn events(c: &mut Client) -> Vec<Event> {
    std::iter::from_fn(|| c.poll_event()).collect()
}

fn telemetry(time_us: u64, active: Option<u16>, last_done: Option<(u16, Outcome)>) -> RobotMsg {
    RobotMsg::Telemetry(Telemetry {
        time_us,
        pose: Pose::default(),
        wheel_speed: [0.0; 2],
        bumper: 0,
        mode: if active.is_some() {
            Mode::Move
        } else {
            Mode::Idle
        },
        faults: pushbot_protocol::Faults::NONE,
        active,
        last_done,
    })
}

fn hello_reply(protocol: u16, accepted: bool) -> RobotMsg {
    RobotMsg::HelloReply(HelloReply {
        protocol,
        accepted,
        firmware: FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        geometry: Geometry {
            wheel_base: 0.1,
            wheel_radius: 0.02,
            bumper_radius: 0.07,
            encoder_cpr: 1440,
            control_hz: 500,
        },
    })
}

/// The firmware core at robot time `robot_us`, standing still.
struct Firmware {
    core: Core,
    robot_us: u64,
}

impl Firmware {
    fn new() -> Firmware {
        Firmware {
            core: Core::new(RobotParams::default()),
            robot_us: 0,
        }
    }

    /// Hand the core `bytes`, run one control period, return what it sends.
    fn exchange(&mut self, bytes: &[u8]) -> Vec<u8> {
        self.core.receive(self.robot_us, bytes);
        self.core.step(self.robot_us, &Inputs::default());
        self.robot_us += u64::from(self.core.tick_period_us());
        let mut out = Vec::new();
        let mut buf = [0u8; 512];
        loop {
            let n = self.core.transmit(&mut buf);
            if n == 0 {
                return out;
            }
            out.extend_from_slice(&buf[..n]);
        }
    }
}

/// A client that shook hands with the firmware core at host time 0.
fn connected() -> (Client, Firmware) {
    let mut c = Client::new(ms(0), opts());
    let mut fw = Firmware::new();
    c.hello(ms(0));
    let (bytes, _) = sent(&mut c, ms(0));
    let reply = fw.exchange(&bytes);
    c.handle_bytes(ms(1), &reply);
    assert!(matches!(c.handshake(), Some(Handshake::Connected(_))));
    events(&mut c);
    sent(&mut c, ms(1));
    (c, fw)
}

#[test]
fn handshake_with_the_firmware_core() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.hello(ms(0));
    assert_eq!(seq, 100);
    let (bytes, frames) = sent(&mut c, ms(0));
    assert_eq!(
        frames,
        [HostFrame {
            seq: 100,
            cmd: Command::Hello {
                protocol: PROTOCOL_VERSION
            }
        }]
    );
    assert_eq!(c.handshake(), None);
    let reply = Firmware::new().exchange(&bytes);
    c.handle_bytes(ms(2), &reply);
    let Some(Handshake::Connected(h)) = c.handshake() else {
        panic!("{:?}", c.handshake());
    };
    assert_eq!(h.protocol, PROTOCOL_VERSION);
    assert!(events(&mut c).contains(&Event::Connected(h)));
    assert_eq!(c.next_seq(), 101);
}

#[test]
fn lost_answers_are_resent_with_the_same_seq_then_given_up() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.command(ms(0), Command::Stop);
    assert_eq!(sent(&mut c, ms(0)).1.len(), 1);
    assert_eq!(
        c.poll_timeout(),
        Some(ms(50)),
        "the heartbeat fallback comes first"
    );
    // Not yet: 149 ms.
    c.pause_heartbeats(true);
    assert_eq!(c.poll_timeout(), Some(ms(150)));
    c.handle_timeout(ms(149));
    assert!(sent(&mut c, ms(149)).1.is_empty());
    let mut now = 150;
    for attempt in 2..=5 {
        c.handle_timeout(ms(now));
        let (_, frames) = sent(&mut c, ms(now));
        assert_eq!(
            frames,
            [HostFrame {
                seq,
                cmd: Command::Stop
            }],
            "attempt {attempt}"
        );
        assert_eq!(c.take_answer(seq), None);
        now += 150;
    }
    assert_eq!(c.stats().retries, 4);
    assert_eq!(c.stats().frames_sent, 5);
    c.handle_timeout(ms(now));
    assert!(sent(&mut c, ms(now)).1.is_empty(), "given up, not resent");
    assert_eq!(c.take_answer(seq), Some(Answer::GaveUp { attempts: 5 }));
    assert!(events(&mut c).contains(&Event::GaveUp { seq, attempts: 5 }));
}

#[test]
fn the_firmware_answers_a_retry_again_and_executes_it_once() {
    let (mut c, mut fw) = connected();
    let pose = Pose {
        x: 0.5,
        y: 0.0,
        theta: 0.0,
    };
    let seq = c.command(ms(10), Command::ResetOdometry(pose));
    let (bytes, _) = sent(&mut c, ms(10));
    let _lost = fw.exchange(&bytes);
    assert_eq!(fw.core.pose().x, 0.5);
    c.handle_timeout(ms(160));
    let (retry, frames) = sent(&mut c, ms(160));
    assert_eq!(frames[0].seq, seq);
    let reply = fw.exchange(&retry);
    c.handle_bytes(ms(161), &reply);
    assert!(matches!(c.take_answer(seq), Some(Answer::Ack { .. })));
    let acks = events(&mut c)
        .iter()
        .filter(|e| matches!(e, Event::Ack { .. }))
        .count();
    assert_eq!(acks, 1);
    assert_eq!(c.stats().retries, 1);
}

#[test]
fn duplicate_and_late_replies_are_ignored() {
    let mut c = Client::new(ms(0), opts());
    let a = c.command(ms(0), Command::Stop);
    c.handle_bytes(
        ms(1),
        &wire(&[RobotMsg::Ack { seq: a }, RobotMsg::Ack { seq: a }]),
    );
    assert_eq!(c.take_answer(a), Some(Answer::Ack { at_us: None }));
    let b = c.command(ms(2), Command::ClearFaults);
    // A late duplicate of `a`'s answer, and a Nack for `a`, are not `b`'s.
    c.handle_bytes(
        ms(3),
        &wire(&[
            RobotMsg::Ack { seq: a },
            RobotMsg::Nack {
                seq: a,
                reason: NackReason::OutOfRange,
            },
        ]),
    );
    assert_eq!(c.take_answer(a), None);
    assert_eq!(c.take_answer(b), None);
    let acks: Vec<_> = events(&mut c)
        .into_iter()
        .filter(|e| matches!(e, Event::Ack { .. } | Event::Nack { .. }))
        .collect();
    assert_eq!(acks, [Event::Ack { seq: a }]);
    c.handle_bytes(ms(4), &wire(&[RobotMsg::Ack { seq: b }]));
    assert_eq!(c.take_answer(b), Some(Answer::Ack { at_us: None }));
}

#[test]
fn out_of_order_replies_are_matched_by_seq() {
    let mut c = Client::new(ms(0), opts());
    let a = c.command(ms(0), Command::Stop);
    let b = c.command(ms(0), Command::ClearFaults);
    assert_eq!(sent(&mut c, ms(0)).1.len(), 2);
    c.handle_bytes(
        ms(1),
        &wire(&[
            RobotMsg::Ack { seq: b },
            RobotMsg::Nack {
                seq: a,
                reason: NackReason::NoSession,
            },
        ]),
    );
    assert_eq!(c.take_answer(b), Some(Answer::Ack { at_us: None }));
    assert_eq!(c.take_answer(a), Some(Answer::Nack(NackReason::NoSession)));
    // Neither is resent.
    c.handle_timeout(ms(1000));
    assert!(
        sent(&mut c, ms(1000))
            .1
            .iter()
            .all(|f| f.cmd == Command::Heartbeat)
    );
}

#[test]
fn a_refused_hello_is_a_version_mismatch() {
    let mut c = Client::new(
        ms(0),
        ClientOptions {
            protocol_version: PROTOCOL_VERSION + 41,
            ..opts()
        },
    );
    c.hello(ms(0));
    let (bytes, _) = sent(&mut c, ms(0));
    let reply = Firmware::new().exchange(&bytes);
    c.handle_bytes(ms(1), &reply);
    let expected = Handshake::VersionMismatch {
        host: PROTOCOL_VERSION + 41,
        robot: PROTOCOL_VERSION,
    };
    assert_eq!(c.handshake(), Some(expected));
    // And a robot of another version that accepts anyway is refused too.
    let mut c = Client::new(ms(0), opts());
    c.hello(ms(0));
    c.handle_bytes(ms(1), &wire(&[hello_reply(PROTOCOL_VERSION + 1, true)]));
    assert_eq!(
        c.handshake(),
        Some(Handshake::VersionMismatch {
            host: PROTOCOL_VERSION,
            robot: PROTOCOL_VERSION + 1
        })
    );
}

#[test]
fn a_foreign_hello_reply_is_read_for_its_version() {
    /// A future protocol's reply: same variant 0 and first field, different fields after.
    #[derive(serde::Serialize)]
    enum FutureMsg {
        HelloReply {
            protocol: u16,
            accepted: bool,
            serial: u64,
        },
    }
    let mut c = Client::new(ms(0), opts());
    c.hello(ms(0));
    let mut buf = [0u8; MAX_FRAME];
    let msg = FutureMsg::HelloReply {
        protocol: 9,
        accepted: false,
        serial: u64::MAX,
    };
    let n = encode_frame(&msg, &mut buf).unwrap();
    c.handle_bytes(ms(1), &buf[..n]);
    assert_eq!(c.stats().frames_rejected, 1);
    assert_eq!(
        c.handshake(),
        Some(Handshake::VersionMismatch {
            host: PROTOCOL_VERSION,
            robot: 9
        })
    );
    assert!(events(&mut c).contains(&Event::VersionMismatch {
        host: PROTOCOL_VERSION,
        robot: 9
    }));
}

#[test]
fn an_unanswered_hello_is_resent_until_the_hello_timeout() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.hello(ms(0));
    c.pause_heartbeats(true);
    // 1.5 s / 150 ms: 10 attempts.
    for i in 1..=10u64 {
        c.handle_timeout(ms(150 * i));
    }
    let frames = sent(&mut c, ms(1500)).1;
    assert_eq!(frames.len(), 10);
    assert!(frames.iter().all(|f| f.seq == seq));
    assert_eq!(
        c.handshake(),
        Some(Handshake::NoAnswer {
            attempts: 10,
            heard: Heard::Nothing
        })
    );
}

#[test]
fn a_hello_taken_for_a_retry_is_sent_again_with_the_next_seq() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.hello(ms(0));
    sent(&mut c, ms(0));
    c.handle_bytes(ms(1), &wire(&[RobotMsg::Ack { seq }]));
    let frames = sent(&mut c, ms(1)).1;
    assert_eq!(frames.len(), 1);
    assert_eq!(frames[0].seq, seq.wrapping_add(1));
    assert!(matches!(frames[0].cmd, Command::Hello { .. }));
    c.handle_bytes(ms(2), &wire(&[hello_reply(PROTOCOL_VERSION, true)]));
    assert!(matches!(c.handshake(), Some(Handshake::Connected(_))));
}

#[test]
fn heartbeats_are_paced_by_robot_time() {
    let mut c = Client::new(ms(0), opts());
    // Robot time runs 20x faster than host time: 20 ms of robot time per host millisecond.
    let mut beats = Vec::new();
    for k in 0..60u64 {
        let robot_us = 1_000_000 + k * 20_000;
        c.handle_bytes(ms(k), &wire(&[telemetry(robot_us, None, None)]));
        if sent(&mut c, ms(k))
            .1
            .iter()
            .any(|f| f.cmd == Command::Heartbeat)
        {
            beats.push(robot_us);
        }
    }
    // A quarter of the 200 ms watchdog is 50 ms of robot time: every third telemetry (60 ms),
    // the first at once. Paced by host time, there would be one in 60 ms.
    assert_eq!(beats.len(), 20, "{beats:?}");
    assert!(beats.windows(2).all(|w| w[1] - w[0] == 60_000), "{beats:?}");
    assert_eq!(c.stats().heartbeats_sent, 20);
    // A new watchdog period re-paces them: 1 s → every 250 ms of robot time.
    c.set_watchdog_ms(1000);
    let mut n = 0;
    for k in 60..120u64 {
        c.handle_bytes(
            ms(k),
            &wire(&[telemetry(1_000_000 + k * 20_000, None, None)]),
        );
        n += sent(&mut c, ms(k)).1.len();
    }
    // The last one went at k = 57; then every 13th telemetry (260 ms): k = 70, 83, 96, 109.
    assert_eq!(n, 4);
    // Paused: none at all.
    c.pause_heartbeats(true);
    for k in 120..200u64 {
        c.handle_bytes(
            ms(k),
            &wire(&[telemetry(1_000_000 + k * 20_000, None, None)]),
        );
        c.handle_timeout(ms(k));
    }
    assert!(sent(&mut c, ms(200)).1.is_empty());
}

#[test]
fn without_telemetry_heartbeats_fall_back_to_host_time() {
    let mut c = Client::new(ms(0), opts());
    assert_eq!(c.poll_timeout(), Some(ms(50)));
    c.handle_timeout(HostTime::from_micros(49_999));
    assert!(sent(&mut c, ms(49)).1.is_empty());
    c.handle_timeout(ms(50));
    let frames = sent(&mut c, ms(50)).1;
    assert_eq!(
        frames,
        [HostFrame {
            seq: 0,
            cmd: Command::Heartbeat
        }]
    );
    assert_eq!(c.poll_timeout(), Some(ms(100)));
}

#[test]
fn heartbeat_due_rules() {
    let wd = 200; // quarter period: 50 ms
    let host = Duration::from_millis(1);
    assert!(!heartbeat_due(Some(1_049_999), Some(1_000_000), host, wd));
    assert!(heartbeat_due(Some(1_050_000), Some(1_000_000), host, wd));
    // First telemetry after opening: nothing sent in robot time yet.
    assert!(heartbeat_due(Some(5), None, host, wd));
    // The robot restarted: its clock went back.
    assert!(heartbeat_due(Some(10), Some(1_000_000), host, wd));
    // No telemetry: host time only.
    assert!(!heartbeat_due(None, None, Duration::from_millis(49), wd));
    assert!(heartbeat_due(None, None, Duration::from_millis(50), wd));
}

#[test]
fn corrupted_bytes_are_rejected_frames_and_the_stream_goes_on() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.command(ms(0), Command::Stop);
    let mut corrupted = wire(&[RobotMsg::Ack { seq }]);
    corrupted[2] ^= 0x10;
    let mut bytes = vec![0xff; 300]; // overflow
    bytes.push(0);
    bytes.extend([0x13, 0x37, 0x00]); // not COBS / too short
    bytes.extend(&corrupted); // CRC mismatch
    bytes.extend(wire(&[RobotMsg::Ack { seq }]));
    // Split anywhere: the decoder keeps its state between calls.
    let (a, b) = bytes.split_at(150);
    c.handle_bytes(ms(1), a);
    c.handle_bytes(ms(1), b);
    assert_eq!(c.stats().frames_rejected, 3);
    assert_eq!(c.stats().frames_ok, 1);
    assert_eq!(c.stats().bytes_received, bytes.len() as u64);
    assert_eq!(c.take_answer(seq), Some(Answer::Ack { at_us: None }));
}

#[test]
fn a_motion_ends_with_its_done_once() {
    let mut c = Client::new(ms(0), opts());
    c.handle_bytes(ms(0), &wire(&[telemetry(500, None, None)]));
    let cmd = Command::Spin {
        angle: 1.0,
        rate: 1.0,
    };
    let seq = c.motion(ms(1), cmd, 6_000_000);
    let done = Done {
        seq,
        outcome: Outcome::Completed,
        pose: Pose::default(),
        time_us: 900_500,
    };
    c.handle_bytes(
        ms(2),
        &wire(&[
            RobotMsg::Ack { seq },
            RobotMsg::Done(done),
            RobotMsg::Done(done),
        ]),
    );
    assert_eq!(c.take_answer(seq), Some(Answer::Ack { at_us: Some(500) }));
    assert_eq!(
        c.take_motion_end(seq),
        Some(MotionEnd::Done {
            done,
            recovered: false,
            started_us: Some(500)
        })
    );
    let dones = events(&mut c)
        .iter()
        .filter(|e| matches!(e, Event::Done { .. }))
        .count();
    assert_eq!(dones, 1, "a repeated Done is ignored");
}

#[test]
fn a_lost_done_is_read_from_the_telemetry() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.motion(ms(0), Command::Stop, 1_000_000);
    c.handle_bytes(ms(1), &wire(&[RobotMsg::Ack { seq }]));
    c.handle_bytes(ms(2), &wire(&[telemetry(10_000, Some(seq), None)]));
    assert_eq!(c.take_motion_end(seq), None);
    c.handle_bytes(
        ms(3),
        &wire(&[telemetry(30_000, None, Some((seq, Outcome::Contact)))]),
    );
    let Some(MotionEnd::Done {
        done,
        recovered: true,
        started_us: Some(10_000),
    }) = c.take_motion_end(seq)
    else {
        panic!("not recovered");
    };
    assert_eq!(done.outcome, Outcome::Contact);
    assert_eq!(done.time_us, 30_000);
}

#[test]
fn a_motion_times_out_in_robot_time() {
    let mut c = Client::new(ms(0), opts());
    let seq = c.motion(ms(0), Command::Stop, 1_000_000);
    c.handle_bytes(ms(1), &wire(&[RobotMsg::Ack { seq }]));
    // Host time hardly moves; robot time decides.
    for (k, t) in [0u64, 500_000, 1_000_000].into_iter().enumerate() {
        c.handle_bytes(ms(2 + k as u64), &wire(&[telemetry(t, Some(seq), None)]));
        assert_eq!(c.take_motion_end(seq), None);
    }
    c.handle_bytes(ms(5), &wire(&[telemetry(1_000_001, Some(seq), None)]));
    assert_eq!(
        c.take_motion_end(seq),
        Some(MotionEnd::TimedOut {
            budget_us: 1_000_000
        })
    );
    assert!(events(&mut c).contains(&Event::MotionTimedOut {
        seq,
        budget_us: 1_000_000
    }));
}

#[test]
fn silence_is_a_dead_link_once() {
    let mut c = Client::new(ms(0), opts());
    c.pause_heartbeats(true);
    c.handle_bytes(ms(100), &wire(&[telemetry(1, None, None)]));
    assert_eq!(c.poll_timeout(), Some(HostTime::from_micros(3_100_001)));
    c.handle_timeout(ms(3100));
    assert_eq!(c.link_dead(ms(3100)), None);
    c.handle_timeout(HostTime::from_micros(3_100_001));
    c.handle_timeout(ms(4000));
    let dead: Vec<_> = events(&mut c)
        .into_iter()
        .filter(|e| matches!(e, Event::LinkDead { .. }))
        .collect();
    assert_eq!(
        dead,
        [Event::LinkDead {
            silent: Duration::from_micros(3_000_001)
        }]
    );
    assert!(c.link_dead(ms(4000)).is_some());
    c.handle_bytes(ms(4001), &wire(&[telemetry(2, None, None)]));
    assert_eq!(c.link_dead(ms(4001)), None);
}

#[test]
fn configure_goes_through_the_firmware() {
    let (mut c, mut fw) = connected();
    let update = ConfigUpdate {
        watchdog_ms: Some(1000),
        ..ConfigUpdate::default()
    };
    let seq = c.command(ms(10), Command::Configure(update));
    let (bytes, _) = sent(&mut c, ms(10));
    let reply = fw.exchange(&bytes);
    c.handle_bytes(ms(11), &reply);
    assert!(matches!(c.take_answer(seq), Some(Answer::Ack { .. })));
}

#[test]
fn a_noisy_wire_tightens_the_policy() {
    let mut c = Client::new(ms(0), opts());
    // A steady telemetry on a clean wire: the plain policy.
    c.handle_bytes(ms(1), &wire(&[telemetry(1_000_000, None, None)]));
    c.handle_bytes(ms(2), &wire(&[telemetry(1_020_000, None, None)]));
    assert!(!c.noisy(ms(2)));
    // A frame with a bad CRC: noisy for five seconds.
    c.handle_bytes(ms(3), &[1, 2, 3, 4, 5, 6, 0]);
    assert_eq!(c.stats().frames_rejected, 1);
    assert!(c.noisy(ms(3)) && c.noisy(ms(5002)) && !c.noisy(ms(5003)));
    sent(&mut c, ms(3));
    // Heartbeats every eighth of the 200 ms watchdog (host-time fallback: 25 ms).
    c.handle_timeout(ms(28));
    assert_eq!(sent(&mut c, ms(28)).1.len(), 1);
    assert_eq!(c.poll_timeout(), Some(ms(53)));

    // A motion whose Ack is lost is accepted when the telemetry shows it running.
    let mv = Command::Move {
        distance: 0.1,
        speed: 0.2,
        stop_on_contact: false,
    };
    let seq = c.motion(ms(30), mv, 10_000_000);
    sent(&mut c, ms(30));
    c.handle_bytes(ms(31), &wire(&[telemetry(1_040_000, Some(seq), None)]));
    assert_eq!(
        c.take_answer(seq),
        Some(Answer::Ack {
            at_us: Some(1_040_000)
        })
    );
    c.handle_timeout(ms(200));
    assert!(
        !sent(&mut c, ms(200)).1.iter().any(|f| f.cmd == mv),
        "not resent once seen running"
    );

    // Twice the attempts while the wire stays noisy.
    let stop = c.command(ms(300), Command::Stop);
    let is_stop = |f: &&HostFrame| f.seq == stop && f.cmd == Command::Stop;
    let mut sends = sent(&mut c, ms(300)).1.iter().filter(is_stop).count();
    let mut now = 300;
    while c.take_answer(stop).is_none() {
        now += 150;
        c.handle_bytes(ms(now), &[9, 9, 9, 0]); // more noise
        c.handle_timeout(ms(now));
        sends += sent(&mut c, ms(now)).1.iter().filter(is_stop).count();
        assert!(now < 5000);
    }
    assert_eq!(sends, 10);
}

#[test]
fn the_emergency_stop_goes_ahead_of_a_command_in_flight_which_is_never_resent() {
    let (mut c, mut fw) = connected();
    let drive = Command::Velocity {
        v: 0.1,
        omega: 0.0,
        timeout_ms: 500,
    };
    let a = c.motion(ms(2), drive, 1_000_000);
    sent(&mut c, ms(2)); // on the wire, unanswered (the answer is lost)
    let b = c.command(ms(3), Command::ClearFaults); // queued, not yet written
    let e = c.emergency_stop(ms(4));
    let (bytes, frames) = sent(&mut c, ms(4));
    assert_eq!(
        frames,
        [HostFrame {
            seq: e,
            cmd: Command::EmergencyStop
        }]
    );
    assert_eq!(c.take_answer(a), Some(Answer::Preempted));
    assert_eq!(c.take_answer(b), Some(Answer::Preempted));
    c.handle_bytes(ms(5), &fw.exchange(&bytes));
    assert!(matches!(c.take_answer(e), Some(Answer::Ack { .. })));
    // Past every ack timeout: nothing withdrawn goes out again.
    c.handle_timeout(ms(2000));
    let (_, later) = sent(&mut c, ms(2000));
    assert!(later.iter().all(|f| f.seq != a && f.seq != b), "{later:?}");
    for k in 0..100 {
        let out = fw.exchange(&[]);
        c.handle_bytes(ms(2001 + k), &out);
    }
    let t = c.telemetry().expect("telemetry");
    assert!(t.faults.contains(pushbot_protocol::Faults::EMERGENCY_STOP) && t.active.is_none());
}
