//! The core's link and command checks through its public contract: session and version
//! handshake, retries, the watchdog, garbage on the wire, out-of-range values and
//! configuration within the hard bounds.

use pushbot_firmware::{Faults, Mode, RobotParams};
use pushbot_protocol::{
    Command, ConfigUpdate, HostFrame, NackReason, Outcome, PROTOCOL_VERSION, Pose, RobotMsg,
};

mod common;
/// The framing written apart from the protocol crate (CRC-32C, COBS), shared with the hostile
/// tests.
mod hostile_gen;

use common::{Bench, Lcg};
use hostile_gen::{cobs_encode, crc32c};

#[test]
fn watchdog_cuts_duty_within_one_tick() {
    let mut b = Bench::connected();
    let s = b.send(Command::Velocity {
        v: 0.1,
        omega: 0.0,
        timeout_ms: 10_000,
    });
    b.run_ms(100);
    // The host falls silent.
    b.heartbeat_us = None;
    let last_frame = b.last_heartbeat.max(b.now - 100_000 + 1000);
    let _ = last_frame;
    let silent_from = b.now;
    let mut cut_at = None;
    for _ in 0..400 {
        let t = b.now;
        let out = b.tick();
        if out.duty == [0.0, 0.0] {
            cut_at = Some(t);
            break;
        }
    }
    let cut_at = cut_at.expect("watchdog cut the motors");
    // The last valid frame was the heartbeat at `last_heartbeat`: the cut comes at the first
    // step at or after last_heartbeat + 200 ms.
    let deadline = b.last_heartbeat + 200_000;
    assert!(cut_at >= deadline, "cut too early: {cut_at} < {deadline}");
    assert!(
        cut_at < deadline + b.core.tick_period_us() as u64,
        "cut late: {cut_at}"
    );
    assert!(cut_at > silent_from);
    assert!(b.core.faults().contains(Faults::LINK_LOST));
    assert_eq!(b.core.mode(), Mode::Faulted);
    b.tick();
    let d = b.done(s).expect("done sent");
    assert_eq!(d.outcome, Outcome::Fault(Faults::LINK_LOST));
    // Motors stay off; a new hello clears LINK_LOST.
    b.run_ms(50);
    assert!(
        b.duties
            .iter()
            .rev()
            .take(50)
            .all(|(_, o)| o.duty == [0.0, 0.0])
    );
    b.heartbeat_us = Some(50_000);
    let n0 = b.msgs.len();
    b.send(Command::Hello {
        protocol: PROTOCOL_VERSION,
    });
    b.tick();
    assert!(
        b.msgs[n0..]
            .iter()
            .any(|(_, m)| matches!(m, RobotMsg::HelloReply(r) if r.accepted))
    );
    assert_eq!(b.core.faults(), Faults::NONE);
}

#[test]
fn retry_with_same_seq_executes_once() {
    let mut b = Bench::connected();
    let frame = HostFrame {
        seq: 77,
        cmd: Command::Move {
            distance: 0.1,
            speed: 0.2,
            stop_on_contact: false,
        },
    };
    b.send_frame(frame);
    b.run_ms(100);
    let x_before = b.core.pose().x;
    b.send_frame(frame); // the host missed the ack and retries
    b.run_ms(1);
    let acks = b
        .msgs
        .iter()
        .filter(|(_, m)| *m == RobotMsg::Ack { seq: 77 })
        .count();
    assert_eq!(acks, 2, "the cached answer is sent again");
    let d = b.run_until_done(77, 3_000).expect("done");
    assert_eq!(d.outcome, Outcome::Completed, "not aborted and restarted");
    assert_eq!(b.dones(77), 1);
    assert!(x_before > 0.0);
    assert!((d.pose.x - 0.1).abs() < 0.003, "moved once: {:?}", d.pose);
}

/// A new session (a restarted host's `Hello`) replaces the retry cache: a command of the new
/// session that happens to repeat the old session's last number and command is a new command,
/// executed — and within a session the same frame is a retry, executed once.
#[test]
fn a_new_session_is_never_answered_from_the_old_sessions_cache() {
    let mut b = Bench::connected();
    let frame = HostFrame {
        seq: 500,
        cmd: Command::Move {
            distance: 0.05,
            speed: 0.2,
            stop_on_contact: false,
        },
    };
    b.send_frame(frame);
    assert_eq!(
        b.run_until_done(500, 3_000).expect("done").outcome,
        Outcome::Completed
    );
    let after_first = b.travel();
    // The host restarts: a new Hello (numbered 499), then the same number and command again.
    b.send_frame(HostFrame {
        seq: 499,
        cmd: Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    });
    b.run_ms(5);
    b.send_frame(frame);
    b.run_ms(100);
    assert!(
        b.travel() > after_first + 1e-3,
        "the new session's command runs"
    );
    b.run_ms(1_000);
    assert_eq!(b.dones(500), 2, "two commands, two ends");
    assert!(
        (b.travel() - 2.0 * after_first).abs() < 0.006,
        "driven twice, once per session: {} then {}",
        after_first,
        b.travel()
    );
    // Within the session, the same frame again is a retry: answered, not driven.
    let before = b.travel();
    b.send_frame(frame);
    b.run_ms(500);
    assert_eq!(b.dones(500), 2, "no third end");
    assert!((b.travel() - before).abs() < 1e-4, "not driven again");
}

#[test]
fn version_mismatch_is_refused() {
    let mut b = Bench::new();
    b.tick();
    b.send_frame(HostFrame {
        seq: 1,
        cmd: Command::Hello {
            protocol: PROTOCOL_VERSION + 1,
        },
    });
    b.send_frame(HostFrame {
        seq: 2,
        cmd: Command::Move {
            distance: 0.1,
            speed: 0.1,
            stop_on_contact: false,
        },
    });
    b.run_ms(100);
    let hello = b.msgs.iter().find_map(|(_, m)| match m {
        RobotMsg::HelloReply(r) => Some(*r),
        _ => None,
    });
    let hello = hello.expect("hello reply");
    assert!(!hello.accepted);
    assert_eq!(hello.protocol, PROTOCOL_VERSION);
    assert!(b.msgs.iter().any(|(_, m)| *m
        == RobotMsg::Nack {
            seq: 2,
            reason: NackReason::NoSession
        }));
    assert!(!b.core.has_session());
    assert!(!b.any_motion());
    // No telemetry without a session.
    assert!(
        !b.msgs
            .iter()
            .any(|(_, m)| matches!(m, RobotMsg::Telemetry(_)))
    );
}

#[test]
fn garbage_bytes_never_cause_motion() {
    // Without a session, anything at all, even well-framed random payloads.
    let mut b = Bench::new();
    let mut g = Lcg(7);
    for i in 0..3000 {
        let len = (g.next() % 40) as usize;
        let mut bytes: Vec<u8> = (0..len).map(|_| g.next()).collect();
        if i % 3 == 0 {
            // A frame with a valid CRC around random bytes.
            let payload: Vec<u8> = (0..(g.next() % 20)).map(|_| g.next()).collect();
            let mut raw = payload.clone();
            raw.extend_from_slice(&crc32c(&payload).to_le_bytes());
            bytes = cobs_encode(&raw);
            bytes.push(0);
        }
        b.core.receive(b.now, &bytes);
        b.tick();
    }
    assert!(!b.any_motion());
    // With a session, corrupted bytes (no valid CRC) do nothing either.
    let mut b = Bench::connected();
    for _ in 0..3000 {
        let bytes: Vec<u8> = (0..(g.next() % 40)).map(|_| g.next()).collect();
        b.core.receive(b.now, &bytes);
        b.tick();
    }
    assert!(!b.any_motion());
    assert!(b.core.rx_rejected() > 0);
}

#[test]
fn out_of_range_values_are_nacked() {
    let mut b = Bench::connected();
    let p = RobotParams::default();
    let bad = [
        Command::Velocity {
            v: 0.31,
            omega: 0.0,
            timeout_ms: 100,
        },
        Command::Velocity {
            v: f32::NAN,
            omega: 0.0,
            timeout_ms: 100,
        },
        Command::Velocity {
            v: 0.1,
            omega: f32::INFINITY,
            timeout_ms: 100,
        },
        Command::Velocity {
            v: 0.1,
            omega: -4.5,
            timeout_ms: 100,
        },
        Command::Velocity {
            v: 0.1,
            omega: 0.0,
            timeout_ms: 0,
        },
        Command::Move {
            distance: 0.1,
            speed: 0.0,
            stop_on_contact: false,
        },
        Command::Move {
            distance: 0.1,
            speed: -0.1,
            stop_on_contact: false,
        },
        Command::Move {
            distance: 0.1,
            speed: p.limits.max_speed * 1.01,
            stop_on_contact: false,
        },
        Command::Move {
            distance: 1e9,
            speed: 0.1,
            stop_on_contact: false,
        },
        Command::Move {
            distance: f32::NEG_INFINITY,
            speed: 0.1,
            stop_on_contact: false,
        },
        Command::Spin {
            angle: 1.0,
            rate: 4.1,
        },
        Command::Spin {
            angle: f32::NAN,
            rate: 1.0,
        },
        Command::Spin {
            angle: 100.0,
            rate: 1.0,
        },
        Command::AdvanceUntilContact {
            max_distance: -1.0,
            speed: 0.1,
        },
        Command::AdvanceUntilContact {
            max_distance: 0.5,
            speed: 0.5,
        },
        Command::Configure(ConfigUpdate {
            max_speed: Some(10.0),
            ..Default::default()
        }),
        Command::Configure(ConfigUpdate {
            max_accel: Some(-1.0),
            ..Default::default()
        }),
        Command::Configure(ConfigUpdate {
            watchdog_ms: Some(0),
            ..Default::default()
        }),
        Command::Configure(ConfigUpdate {
            telemetry_hz: Some(60_000),
            ..Default::default()
        }),
        Command::Configure(ConfigUpdate {
            max_speed: Some(0.2), // valid, but the update is all or nothing
            max_omega: Some(f32::NAN),
            ..Default::default()
        }),
        Command::ResetOdometry(Pose {
            x: f32::NAN,
            y: 0.0,
            theta: 0.0,
        }),
    ];
    for cmd in bad {
        let s = b.send(cmd);
        b.tick();
        assert_eq!(
            b.reply(s),
            Some(RobotMsg::Nack {
                seq: s,
                reason: NackReason::OutOfRange
            }),
            "{cmd:?}"
        );
    }
    b.run_ms(20);
    assert!(!b.any_motion());
    assert_eq!(b.core.limits(), p.limits, "nothing half-applied");
    // The edges of the ranges are accepted.
    let s = b.send(Command::Velocity {
        v: p.limits.max_speed,
        omega: -p.limits.max_omega,
        timeout_ms: 10,
    });
    b.tick();
    assert!(b.acked(s));
}

#[test]
fn commands_before_hello_get_no_session() {
    let mut b = Bench::new();
    b.tick();
    let s = b.send(Command::ResetOdometry(Pose::default()));
    b.tick();
    assert_eq!(
        b.reply(s),
        Some(RobotMsg::Nack {
            seq: s,
            reason: NackReason::NoSession
        })
    );
}

#[test]
fn configure_changes_limits_within_hard_bounds() {
    let mut b = Bench::connected();
    let c = b.send(Command::Configure(ConfigUpdate {
        max_speed: Some(0.1),
        watchdog_ms: Some(500),
        ..Default::default()
    }));
    b.tick();
    assert!(b.acked(c));
    assert_eq!(b.core.limits().max_speed, 0.1);
    let m = b.send(Command::Move {
        distance: 0.1,
        speed: 0.2,
        stop_on_contact: false,
    });
    b.tick();
    assert_eq!(
        b.reply(m),
        Some(RobotMsg::Nack {
            seq: m,
            reason: NackReason::OutOfRange
        })
    );
    // The longer watchdog is in force: 300 ms of silence is fine now.
    let v = b.send(Command::Velocity {
        v: 0.05,
        omega: 0.0,
        timeout_ms: 2_000,
    });
    b.heartbeat_us = None;
    b.run_ms(300);
    assert_eq!(b.core.faults(), Faults::NONE);
    assert_eq!(b.core.active(), Some(v));
    b.run_ms(250);
    assert_eq!(b.core.faults(), Faults::LINK_LOST);
}
