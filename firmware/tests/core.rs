//! The core driven through its public contract: host frames in through `receive`, a small
//! first-order motor model closing the loop through `step`, replies decoded with the
//! protocol's own `FrameDecoder`.
//!
//! Motion primitives and their limits, telemetry, and random command streams; the link and
//! command checks are in `core_link.rs`, faults and contact in `core_safety.rs`.

use std::f32::consts::PI;

use pushbot_firmware::{Faults, Mode};
use pushbot_protocol::{
    Command, ConfigUpdate, HostFrame, Outcome, PROTOCOL_VERSION, Pose, RobotMsg,
};

mod common;

use common::{Bench, Lcg};

#[test]
fn move_of_0_3_m_completes_with_matching_odometry() {
    let mut b = Bench::connected();
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    assert!(
        b.acked(s) || {
            b.tick();
            b.acked(s)
        }
    );
    assert_eq!(b.core.mode(), Mode::Move);
    let d = b.run_until_done(s, 5_000).expect("move ends");
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((d.pose.x - 0.3).abs() < 0.003, "odometry {:?}", d.pose);
    assert!(
        d.pose.y.abs() < 0.002 && d.pose.theta.abs() < 0.02,
        "{:?}",
        d.pose
    );
    // The wheels really went 0.3 m (odometry agrees with the model up to a count).
    assert!((b.travel() - 0.3).abs() < 0.004, "travel {}", b.travel());
    // Took about the trapezoid's time: 0.3/0.3 + 0.3/0.6 = 1.5 s, plus settling.
    let t = d.time_us as f32 * 1e-6;
    assert!((1.4..2.0).contains(&t), "took {t} s");
    assert_eq!(b.dones(s), 1);
    b.tick();
    assert_eq!(b.core.mode(), Mode::Idle);
    assert_eq!(b.tick().duty, [0.0, 0.0]);
}

#[test]
fn backwards_move() {
    let mut b = Bench::connected();
    let s = b.send(Command::Move {
        distance: -0.1,
        speed: 0.2,
        stop_on_contact: true,
    });
    let d = b.run_until_done(s, 3_000).expect("move ends");
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((d.pose.x + 0.1).abs() < 0.003, "{:?}", d.pose);
}

#[test]
fn spin_of_90_degrees() {
    let mut b = Bench::connected();
    let s = b.send(Command::Spin {
        angle: PI / 2.0,
        rate: 3.0,
    });
    let d = b.run_until_done(s, 3_000).expect("spin ends");
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((d.pose.theta - PI / 2.0).abs() < 0.03, "{:?}", d.pose);
    assert!(
        d.pose.x.abs() < 0.002 && d.pose.y.abs() < 0.002,
        "{:?}",
        d.pose
    );
}

/// The body's true speed and acceleration (in the motor model) stay near the limits: the
/// reference never exceeds them and the wheels follow it closely.
#[test]
fn motion_stays_within_limits() {
    let mut b = Bench::connected();
    let n0 = b.speeds.len();
    let s = b.send(Command::Move {
        distance: 0.5,
        speed: 0.3,
        stop_on_contact: false,
    });
    b.run_until_done(s, 5_000).expect("ends");
    let speeds = &b.speeds[n0..];
    let top = speeds.iter().cloned().fold(0.0f32, f32::max);
    assert!(top <= 0.3 * 1.03, "speed {top}");
    assert!(top >= 0.3 * 0.97, "reaches cruise: {top}");
    // Acceleration over 50 ms windows (the wheels catch up with the reference after the
    // motor's lag, so over a few ms they may briefly accelerate faster).
    for (i, w) in speeds.windows(51).enumerate() {
        let a = (w[50] - w[0]) / 0.050;
        assert!(a.abs() <= 0.6 * 1.2, "accel {a} at {i} ms");
    }
}

#[test]
fn new_motion_preempts_running_one() {
    let mut b = Bench::connected();
    let m = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    b.run_ms(400);
    let s = b.send(Command::Spin {
        angle: -1.0,
        rate: 2.0,
    });
    b.tick();
    assert_eq!(b.done(m).map(|d| d.outcome), Some(Outcome::Aborted));
    let d = b.run_until_done(s, 3_000).expect("spin ends");
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((d.pose.theta + 1.0).abs() < 0.05, "{:?}", d.pose);
    assert_eq!(b.dones(m), 1);
}

#[test]
fn velocity_times_out_then_brakes_to_idle() {
    let mut b = Bench::connected();
    let t0 = b.now;
    let s = b.send(Command::Velocity {
        v: 0.2,
        omega: 1.0,
        timeout_ms: 300,
    });
    let d = b.run_until_done(s, 1_000).expect("timeout");
    assert_eq!(d.outcome, Outcome::Timeout);
    assert!(
        (d.time_us - t0).abs_diff(300_000) <= 1_000,
        "{}",
        d.time_us - t0
    );
    b.tick();
    assert_eq!(b.core.mode(), Mode::Braking);
    b.run_ms(1_000);
    assert_eq!(b.core.mode(), Mode::Idle);
    assert_eq!(b.tick().duty, [0.0, 0.0]);
}

#[test]
fn stop_aborts_and_brakes() {
    let mut b = Bench::connected();
    let m = b.send(Command::Move {
        distance: 1.0,
        speed: 0.3,
        stop_on_contact: false,
    });
    b.run_ms(700);
    let s = b.send(Command::Stop);
    b.tick();
    assert!(b.acked(s));
    assert_eq!(b.done(m).map(|d| d.outcome), Some(Outcome::Aborted));
    assert_eq!(b.core.mode(), Mode::Braking);
    b.run_ms(800);
    assert_eq!(b.core.mode(), Mode::Idle);
}

#[test]
fn slow_primitive_times_out() {
    // Weak motors: the wheels turn (no stall) but at a tenth of the speed.
    let mut b = Bench::connected();
    b.k = 4.0;
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    // Planned 1.5 s: limit 3 × 1.5 + 1 = 5.5 s.
    let d = b.run_until_done(s, 8_000).expect("ends");
    assert_eq!(d.outcome, Outcome::Timeout);
    let t = d.time_us as f32 * 1e-6;
    assert!((5.4..5.7).contains(&t), "at {t}");
    assert_eq!(b.core.faults(), Faults::NONE);
}

#[test]
fn telemetry_at_configured_rate_reports_active_and_last_done() {
    let mut b = Bench::connected();
    let m = b.send(Command::Move {
        distance: 0.05,
        speed: 0.1,
        stop_on_contact: false,
    });
    b.run_ms(1_000);
    let tel: Vec<_> = b
        .msgs
        .iter()
        .filter_map(|(_, m)| match m {
            RobotMsg::Telemetry(t) => Some(*t),
            _ => None,
        })
        .collect();
    assert!((49..=52).contains(&tel.len()), "{} in 1 s", tel.len());
    assert!(
        tel.iter()
            .any(|t| t.active == Some(m) && t.mode == Mode::Move)
    );
    let last = tel.last().unwrap();
    assert_eq!(last.active, None);
    assert_eq!(last.last_done, Some((m, Outcome::Completed)));
    // Reconfigured to 10 Hz.
    let c = b.send(Command::Configure(ConfigUpdate {
        telemetry_hz: Some(10),
        ..Default::default()
    }));
    b.tick();
    assert!(b.acked(c));
    let n0 = b.msgs.len();
    b.run_ms(1_000);
    let n = b.msgs[n0..]
        .iter()
        .filter(|(_, m)| matches!(m, RobotMsg::Telemetry(_)))
        .count();
    assert!((10..=11).contains(&n), "{n}");
}

#[test]
fn reset_odometry_sets_pose() {
    let mut b = Bench::connected();
    let s = b.send(Command::ResetOdometry(Pose {
        x: 1.0,
        y: -2.0,
        theta: 3.5,
    }));
    b.tick();
    assert!(b.acked(s));
    let p = b.core.pose();
    assert_eq!((p.x, p.y), (1.0, -2.0));
    assert!((p.theta - (3.5 - 2.0 * PI)).abs() < 1e-5);
}

/// A random but plausible command: in-range values most of the time, sometimes anything at
/// all (any bit pattern of an f32).
fn random_command(g: &mut Lcg) -> Command {
    let mut f = |lo: f32, hi: f32| -> f32 {
        if g.next() < 20 {
            f32::from_bits(u32::from_le_bytes([g.next(), g.next(), g.next(), g.next()]))
        } else {
            lo + (hi - lo) * (g.next() as f32 / 255.0)
        }
    };
    let pick = f(0.0, 12.0) as i32;
    let flag = f(0.0, 1.0) > 0.5;
    match pick {
        0 => Command::Hello {
            protocol: if flag { PROTOCOL_VERSION } else { 9 },
        },
        1 => Command::Velocity {
            v: f(-0.3, 0.3),
            omega: f(-4.0, 4.0),
            timeout_ms: f(0.0, 500.0) as u16,
        },
        2 | 3 => Command::Move {
            distance: f(-0.2, 0.2),
            speed: f(0.0, 0.3),
            stop_on_contact: flag,
        },
        4 => Command::Spin {
            angle: f(-3.0, 3.0),
            rate: f(0.0, 4.0),
        },
        5 => Command::AdvanceUntilContact {
            max_distance: f(0.0, 0.2),
            speed: f(0.0, 0.3),
        },
        6 => Command::Stop,
        7 => Command::EmergencyStop,
        8 => Command::ClearFaults,
        9 => Command::Configure(ConfigUpdate {
            max_speed: flag.then(|| f(0.0, 0.5)),
            max_accel: (!flag).then(|| f(0.0, 2.0)),
            watchdog_ms: flag.then(|| f(0.0, 500.0) as u16),
            telemetry_hz: (!flag).then(|| f(0.0, 300.0) as u16),
            ..Default::default()
        }),
        10 => Command::ResetOdometry(Pose {
            x: f(-1.0, 1.0),
            y: f(-1.0, 1.0),
            theta: f(-7.0, 7.0),
        }),
        _ => Command::Heartbeat,
    }
}

fn is_motion(c: &Command) -> bool {
    matches!(
        c,
        Command::Velocity { .. }
            | Command::Move { .. }
            | Command::Spin { .. }
            | Command::AdvanceUntilContact { .. }
    )
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    /// Whatever the host sends, with retries, bumps and walls: duties stay finite and in range
    /// and are zero while a fault is latched; every command but a heartbeat gets one answer
    /// (two for a retry, the same); every accepted motion command ends with exactly one Done.
    #[test]
    fn random_command_streams_keep_the_invariants(seed in proptest::prelude::any::<u64>()) {
        let mut g = Lcg(seed);
        let mut b = Bench::new();
        b.wall = (g.next() < 128).then_some(0.15);
        let mut sent: Vec<HostFrame> = Vec::new();
        let mut last: Option<HostFrame> = None;
        let mut retries = 0usize;
        for _ in 0..3_000 {
            let r = g.next();
            if r < 12 {
                let frame = if r < 3 && last.is_some() {
                    retries += 1;
                    last.unwrap()
                } else {
                    b.seq = b.seq.wrapping_add(1);
                    HostFrame { seq: b.seq, cmd: random_command(&mut g) }
                };
                b.send_frame(frame);
                if !matches!(frame.cmd, Command::Heartbeat) {
                    sent.push(frame);
                    last = Some(frame);
                }
            }
            b.bumper_raw = if g.next() < 2 { g.next() } else { b.bumper_raw & 0x7 };
            let out = b.tick();
            for d in out.duty {
                proptest::prop_assert!(d.is_finite() && (-1.0..=1.0).contains(&d));
            }
            if !b.core.faults().is_empty() {
                proptest::prop_assert_eq!(out.duty, [0.0, 0.0]);
            }
        }
        // Let everything end: the host goes quiet and the watchdog stops what still runs.
        b.heartbeat_us = None;
        b.run_ms(6_000);
        proptest::prop_assert_eq!(b.core.tx_dropped(), 0);
        let answers = b.msgs.iter().filter(|(_, m)| matches!(
            m, RobotMsg::Ack { .. } | RobotMsg::Nack { .. } | RobotMsg::HelloReply(_))).count();
        proptest::prop_assert_eq!(answers, sent.len());
        proptest::prop_assert!(retries > 0 || sent.len() < 50);
        let mut seqs: Vec<u16> = sent.iter().filter(|f| is_motion(&f.cmd)).map(|f| f.seq).collect();
        seqs.dedup();
        for s in seqs {
            let acked = b.msgs.iter().any(|(_, m)| *m == RobotMsg::Ack { seq: s });
            proptest::prop_assert_eq!(b.dones(s), usize::from(acked), "seq {}", s);
        }
        proptest::prop_assert!(b.core.active().is_none());
    }
}
