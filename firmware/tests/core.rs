//! The core driven through its public contract: host frames in through `receive`, a small
//! first-order motor model closing the loop through `step`, replies decoded with the
//! protocol's own `FrameDecoder`.

use std::f32::consts::PI;

use pushbot_firmware::{Core, Faults, Inputs, Mode, Outputs, RobotParams};
use pushbot_protocol::{
    Command, ConfigUpdate, Done, FrameDecoder, HelloReply, HostFrame, NackReason, Outcome,
    PROTOCOL_VERSION, Pose, RobotMsg, encode_frame,
};

/// One wheel: ω' = (K·u − ω)/τ; the encoder counts the angle.
#[derive(Clone, Copy)]
struct Motor {
    w: f32,
    angle: f64,
}

/// The robot in its world for the test: two motors, an optional wall, a bumper.
struct Bench {
    core: Core,
    now: u64,
    motors: [Motor; 2],
    /// rad/s per unit duty.
    k: f32,
    tau: f32,
    /// Encoders stop counting (motors absent).
    frozen: bool,
    /// Forward travel (m) at which the bumper touches a wall and the wheels block.
    wall: Option<f32>,
    /// Raw bumper bits forced on top of the wall contact.
    bumper_raw: u8,
    /// Heartbeat every this many µs (None: silent host).
    heartbeat_us: Option<u64>,
    last_heartbeat: u64,
    seq: u16,
    rx: FrameDecoder,
    msgs: Vec<(u64, RobotMsg)>,
    duties: Vec<(u64, Outputs)>,
    /// True body speed of the model after each tick, m/s.
    speeds: Vec<f32>,
    params: RobotParams,
}

impl Bench {
    fn new() -> Self {
        let params = RobotParams::default();
        Bench {
            core: Core::new(params),
            now: 0,
            motors: [Motor { w: 0.0, angle: 0.0 }; 2],
            k: 32.0,
            tau: 0.02,
            frozen: false,
            wall: None,
            bumper_raw: 0,
            heartbeat_us: Some(50_000),
            last_heartbeat: 0,
            seq: 0,
            rx: FrameDecoder::new(),
            msgs: Vec::new(),
            duties: Vec::new(),
            speeds: Vec::new(),
            params,
        }
    }

    /// A bench with an open session.
    fn connected() -> Self {
        let mut b = Bench::new();
        b.tick();
        b.send(Command::Hello {
            protocol: PROTOCOL_VERSION,
        });
        b.tick();
        assert!(b.hello_reply().is_some_and(|r| r.accepted));
        b
    }

    fn hello_reply(&self) -> Option<HelloReply> {
        self.msgs.iter().rev().find_map(|(_, m)| match m {
            RobotMsg::HelloReply(r) => Some(*r),
            _ => None,
        })
    }

    fn send_frame(&mut self, frame: HostFrame) {
        let mut buf = [0u8; 256];
        let n = encode_frame(&frame, &mut buf).expect("encode");
        self.core.receive(self.now, &buf[..n]);
    }

    /// Send a command under a fresh sequence number; returns it.
    fn send(&mut self, cmd: Command) -> u16 {
        self.seq = self.seq.wrapping_add(1);
        self.send_frame(HostFrame { seq: self.seq, cmd });
        self.seq
    }

    fn travel(&self) -> f32 {
        let r = self.params.geometry.wheel_radius as f64;
        (0.5 * (self.motors[0].angle + self.motors[1].angle) * r) as f32
    }

    fn encoder(&self) -> [i32; 2] {
        let cpr = self.params.geometry.encoder_cpr as f64;
        self.motors
            .map(|m| (m.angle * cpr / (2.0 * std::f64::consts::PI)).floor() as i64 as i32)
    }

    /// One control period: step the core, move the motors, collect what the core sent.
    fn tick(&mut self) -> Outputs {
        if let Some(h) = self.heartbeat_us
            && self.now >= self.last_heartbeat + h
        {
            self.last_heartbeat = self.now;
            self.send_frame(HostFrame {
                seq: 0,
                cmd: Command::Heartbeat,
            });
        }
        let at_wall = self.wall.is_some_and(|w| self.travel() >= w);
        let bumper = self.bumper_raw | if at_wall { 0b010 } else { 0 };
        let encoder = self.encoder();
        let out = self.core.step(self.now, &Inputs { encoder, bumper });
        for d in out.duty {
            assert!((-1.0..=1.0).contains(&d), "duty {d}");
        }
        self.duties.push((self.now, out));
        let dt_us = self.core.tick_period_us() as u64;
        let dt = dt_us as f32 * 1e-6;
        for (m, u) in self.motors.iter_mut().zip(out.duty) {
            m.w += (self.k * u - m.w) / self.tau * dt;
            if at_wall && m.w > 0.0 {
                m.w = 0.0; // the wall blocks forward motion
            }
            if !self.frozen {
                m.angle += (m.w * dt) as f64;
            }
        }
        self.now += dt_us;
        let r = self.params.geometry.wheel_radius;
        self.speeds
            .push(0.5 * (self.motors[0].w + self.motors[1].w) * r);
        let mut buf = [0u8; 64];
        loop {
            let n = self.core.transmit(&mut buf);
            if n == 0 {
                break;
            }
            let now = self.now;
            let msgs = &mut self.msgs;
            self.rx.feed::<RobotMsg>(&buf[..n], |r| {
                msgs.push((now, r.expect("robot frames are valid")))
            });
        }
        out
    }

    fn run_ms(&mut self, ms: u64) {
        for _ in 0..ms * 1000 / self.core.tick_period_us() as u64 {
            self.tick();
        }
    }

    /// Tick until `done(seq)` arrives or `max_ms` passes.
    fn run_until_done(&mut self, seq: u16, max_ms: u64) -> Option<Done> {
        let end = self.now + max_ms * 1000;
        while self.now < end {
            self.tick();
            if let Some(d) = self.done(seq) {
                return Some(d);
            }
        }
        None
    }

    fn done(&self, seq: u16) -> Option<Done> {
        self.msgs.iter().find_map(|(_, m)| match m {
            RobotMsg::Done(d) if d.seq == seq => Some(*d),
            _ => None,
        })
    }

    fn dones(&self, seq: u16) -> usize {
        self.msgs
            .iter()
            .filter(|(_, m)| matches!(m, RobotMsg::Done(d) if d.seq == seq))
            .count()
    }

    /// The (first) answer to command `seq`.
    fn reply(&self, seq: u16) -> Option<RobotMsg> {
        self.msgs.iter().find_map(|(_, m)| match m {
            RobotMsg::Ack { seq: s } | RobotMsg::Nack { seq: s, .. } if *s == seq => Some(*m),
            _ => None,
        })
    }

    fn acked(&self, seq: u16) -> bool {
        matches!(self.reply(seq), Some(RobotMsg::Ack { .. }))
    }

    fn any_motion(&self) -> bool {
        self.duties.iter().any(|(_, o)| o.duty != [0.0, 0.0])
    }
}

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

/// A tiny deterministic generator for garbage.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u8 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 56) as u8
    }
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

fn crc32c(bytes: &[u8]) -> u32 {
    // Bitwise CRC-32C (Castagnoli, reflected 0x82F63B78), independent of the protocol crate.
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0x82F6_3B78
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn cobs_encode(raw: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8];
    let mut code_at = 0;
    let mut code = 1u8;
    for &b in raw {
        if b == 0 {
            out[code_at] = code;
            code_at = out.len();
            out.push(0);
            code = 1;
        } else {
            out.push(b);
            code += 1;
            if code == 0xFF {
                out[code_at] = code;
                code_at = out.len();
                out.push(0);
                code = 1;
            }
        }
    }
    out[code_at] = code;
    out
}

#[test]
fn bumper_debounce_ignores_a_1_ms_glitch_and_stops_on_contact() {
    let mut b = Bench::connected();
    let s = b.send(Command::AdvanceUntilContact {
        max_distance: 1.0,
        speed: 0.2,
    });
    b.run_ms(300);
    b.bumper_raw = 0b001;
    b.tick(); // 1 ms glitch
    b.bumper_raw = 0;
    b.run_ms(50);
    assert!(b.done(s).is_none(), "a glitch is not a contact");
    assert!(
        !b.msgs
            .iter()
            .any(|(_, m)| matches!(m, RobotMsg::Contact(_)))
    );
    assert_eq!(b.core.mode(), Mode::Advance);
    // A real contact.
    let closed_at = b.now;
    b.bumper_raw = 0b100;
    let d = b.run_until_done(s, 100).expect("contact ends the advance");
    assert_eq!(d.outcome, Outcome::Contact);
    let contact = b
        .msgs
        .iter()
        .find_map(|(_, m)| match m {
            RobotMsg::Contact(c) => Some(*c),
            _ => None,
        })
        .expect("contact event");
    assert_eq!(contact.bumper, 0b100);
    // Debounced edge: 5 ms after the raw edge.
    assert_eq!(contact.time_us, closed_at + 5_000);
    assert_eq!(d.time_us, contact.time_us);
    // Duty 0 at that very step.
    let out = b
        .duties
        .iter()
        .find(|(t, _)| *t == contact.time_us)
        .expect("step");
    assert_eq!(out.1.duty, [0.0, 0.0]);
}

#[test]
fn move_with_stop_on_contact_stops_at_wall() {
    let mut b = Bench::connected();
    b.wall = Some(0.1);
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.2,
        stop_on_contact: true,
    });
    let d = b.run_until_done(s, 3_000).expect("ends");
    assert_eq!(d.outcome, Outcome::Contact);
    assert!((d.pose.x - 0.1).abs() < 0.01, "{:?}", d.pose);
    assert_eq!(b.core.faults(), Faults::NONE);
}

#[test]
fn move_into_wall_without_stop_on_contact_ends_in_stall() {
    let mut b = Bench::connected();
    b.wall = Some(0.1);
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.2,
        stop_on_contact: false,
    });
    let d = b.run_until_done(s, 3_000).expect("ends");
    match d.outcome {
        Outcome::Fault(f) => assert!(
            f.contains(Faults::STALL_LEFT) || f.contains(Faults::STALL_RIGHT),
            "{f:?}"
        ),
        o => panic!("outcome {o:?}"),
    }
    assert!(
        b.msgs
            .iter()
            .any(|(_, m)| matches!(m, RobotMsg::Contact(_))),
        "contact still reported"
    );
    b.tick();
    assert_eq!(b.tick().duty, [0.0, 0.0]);
}

#[test]
fn frozen_encoders_end_in_stall_fault_quickly() {
    let mut b = Bench::connected();
    b.frozen = true;
    let t0 = b.now;
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    let d = b.run_until_done(s, 1_000).expect("does not hang");
    assert!(
        matches!(d.outcome, Outcome::Fault(f) if f.contains(Faults::STALL_LEFT) || f.contains(Faults::STALL_RIGHT)),
        "{:?}",
        d.outcome
    );
    assert!(d.time_us - t0 < 500_000, "took {} µs", d.time_us - t0);
    // Motion is refused while the fault is latched, accepted once cleared.
    b.frozen = false;
    let m = b.send(Command::Spin {
        angle: 1.0,
        rate: 1.0,
    });
    b.tick();
    assert!(
        matches!(b.reply(m), Some(RobotMsg::Nack { reason: NackReason::Faulted(f), .. }) if !f.is_empty())
    );
    let c = b.send(Command::ClearFaults);
    b.tick();
    assert!(b.acked(c));
    assert_eq!(b.core.faults(), Faults::NONE);
    let m = b.send(Command::Spin {
        angle: 1.0,
        rate: 1.0,
    });
    b.tick();
    assert!(b.acked(m));
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
fn emergency_stop_cuts_at_once_and_latches() {
    let mut b = Bench::connected();
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    b.run_ms(300);
    assert_ne!(b.tick().duty, [0.0, 0.0]);
    let e = b.send(Command::EmergencyStop);
    assert_eq!(b.tick().duty, [0.0, 0.0]);
    assert!(b.acked(e));
    assert_eq!(
        b.done(s).map(|d| d.outcome),
        Some(Outcome::Fault(Faults::EMERGENCY_STOP))
    );
    assert_eq!(b.core.faults(), Faults::EMERGENCY_STOP);
    let m = b.send(Command::Move {
        distance: 0.1,
        speed: 0.1,
        stop_on_contact: false,
    });
    b.tick();
    assert_eq!(
        b.reply(m),
        Some(RobotMsg::Nack {
            seq: m,
            reason: NackReason::Faulted(Faults::EMERGENCY_STOP)
        })
    );
    b.send(Command::ClearFaults);
    b.tick();
    assert_eq!(b.core.mode(), Mode::Idle);
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
fn encoder_jump_latches_encoder_fault() {
    let mut b = Bench::connected();
    let s = b.send(Command::Velocity {
        v: 0.1,
        omega: 0.0,
        timeout_ms: 1_000,
    });
    b.run_ms(100);
    b.motors[0].angle += 50.0; // thousands of counts in one step
    b.tick();
    assert!(b.core.faults().contains(Faults::ENCODER));
    b.tick();
    assert_eq!(
        b.done(s).map(|d| d.outcome),
        Some(Outcome::Fault(Faults::ENCODER))
    );
    // Cleared only once it has been quiet for a while.
    b.send(Command::ClearFaults);
    assert!(b.core.faults().contains(Faults::ENCODER));
    b.run_ms(150);
    b.send(Command::ClearFaults);
    assert_eq!(b.core.faults(), Faults::NONE);
}

#[test]
fn late_control_step_latches_overrun() {
    let mut b = Bench::connected();
    let s = b.send(Command::Velocity {
        v: 0.1,
        omega: 0.0,
        timeout_ms: 1_000,
    });
    b.run_ms(50);
    b.now += 5_000; // the loop missed five periods
    b.tick();
    assert!(b.core.faults().contains(Faults::CONTROL_OVERRUN));
    assert_eq!(
        b.done(s).map(|d| d.outcome),
        Some(Outcome::Fault(Faults::CONTROL_OVERRUN))
    );
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

#[test]
fn clear_faults_without_faults_leaves_motion_alone() {
    let mut b = Bench::connected();
    let m = b.send(Command::Move {
        distance: 0.2,
        speed: 0.2,
        stop_on_contact: false,
    });
    b.run_ms(300);
    let c = b.send(Command::ClearFaults);
    b.tick();
    assert!(b.acked(c));
    assert_eq!(b.core.mode(), Mode::Move);
    let d = b.run_until_done(m, 3_000).expect("ends");
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((d.pose.x - 0.2).abs() < 0.003);
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
