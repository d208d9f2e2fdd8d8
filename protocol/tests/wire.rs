//! Wire-level tests: every message round-trips, corrupted frames are rejected, arbitrary input
//! never panics the decoder and it resynchronises.

use proptest::prelude::*;
use pushbot_protocol::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn f() -> impl Strategy<Value = f32> {
    prop_oneof![
        -1.0e6f32..1.0e6,
        Just(0.0f32),
        Just(f32::MAX),
        Just(f32::MIN_POSITIVE)
    ]
}

fn pose() -> impl Strategy<Value = Pose> {
    (f(), f(), f()).prop_map(|(x, y, theta)| Pose { x, y, theta })
}

fn faults() -> impl Strategy<Value = Faults> {
    any::<u16>().prop_map(Faults)
}

fn outcome() -> impl Strategy<Value = Outcome> {
    prop_oneof![
        Just(Outcome::Completed),
        Just(Outcome::Contact),
        Just(Outcome::Aborted),
        faults().prop_map(Outcome::Fault),
        Just(Outcome::Timeout),
    ]
}

fn config() -> impl Strategy<Value = ConfigUpdate> {
    (
        proptest::option::of((f(), f(), f()).prop_map(|(kp, ki, kff)| WheelGains { kp, ki, kff })),
        proptest::option::of(f()),
        proptest::option::of(f()),
        proptest::option::of(f()),
        proptest::option::of(f()),
        proptest::option::of(any::<u16>()),
        proptest::option::of(any::<u16>()),
    )
        .prop_map(
            |(
                wheel_gains,
                max_speed,
                max_accel,
                max_omega,
                max_alpha,
                watchdog_ms,
                telemetry_hz,
            )| {
                ConfigUpdate {
                    wheel_gains,
                    max_speed,
                    max_accel,
                    max_omega,
                    max_alpha,
                    watchdog_ms,
                    telemetry_hz,
                }
            },
        )
}

fn command() -> impl Strategy<Value = Command> {
    prop_oneof![
        any::<u16>().prop_map(|protocol| Command::Hello { protocol }),
        Just(Command::Heartbeat),
        (f(), f(), any::<u16>()).prop_map(|(v, omega, timeout_ms)| Command::Velocity {
            v,
            omega,
            timeout_ms
        }),
        (f(), f(), any::<bool>()).prop_map(|(distance, speed, stop_on_contact)| Command::Move {
            distance,
            speed,
            stop_on_contact
        }),
        (f(), f()).prop_map(|(angle, rate)| Command::Spin { angle, rate }),
        (f(), f()).prop_map(|(max_distance, speed)| Command::AdvanceUntilContact {
            max_distance,
            speed
        }),
        Just(Command::Stop),
        Just(Command::EmergencyStop),
        Just(Command::ClearFaults),
        config().prop_map(Command::Configure),
        pose().prop_map(Command::ResetOdometry),
    ]
}

fn host_frame() -> impl Strategy<Value = HostFrame> {
    (any::<u16>(), command()).prop_map(|(seq, cmd)| HostFrame { seq, cmd })
}

fn robot_msg() -> impl Strategy<Value = RobotMsg> {
    let hello = (
        any::<u16>(),
        any::<bool>(),
        any::<(u8, u8, u8)>(),
        (f(), f(), f(), any::<u32>(), any::<u16>()),
    )
        .prop_map(|(protocol, accepted, (major, minor, patch), g)| {
            RobotMsg::HelloReply(HelloReply {
                protocol,
                accepted,
                firmware: FirmwareVersion {
                    major,
                    minor,
                    patch,
                },
                geometry: Geometry {
                    wheel_base: g.0,
                    wheel_radius: g.1,
                    bumper_radius: g.2,
                    encoder_cpr: g.3,
                    control_hz: g.4,
                },
            })
        });
    let nack = prop_oneof![
        any::<u16>().prop_map(|robot| NackReason::VersionMismatch { robot }),
        Just(NackReason::NoSession),
        Just(NackReason::OutOfRange),
        faults().prop_map(NackReason::Faulted),
    ];
    let mode = prop_oneof![
        Just(Mode::Idle),
        Just(Mode::Velocity),
        Just(Mode::Move),
        Just(Mode::Spin),
        Just(Mode::Advance),
        Just(Mode::Braking),
        Just(Mode::Faulted),
    ];
    let telemetry = (
        any::<u64>(),
        pose(),
        (f(), f()),
        any::<u8>(),
        mode,
        faults(),
        proptest::option::of(any::<u16>()),
        proptest::option::of((any::<u16>(), outcome())),
    )
        .prop_map(
            |(time_us, pose, (l, r), bumper, mode, faults, active, last_done)| {
                RobotMsg::Telemetry(Telemetry {
                    time_us,
                    pose,
                    wheel_speed: [l, r],
                    bumper,
                    mode,
                    faults,
                    active,
                    last_done,
                })
            },
        );
    prop_oneof![
        hello,
        any::<u16>().prop_map(|seq| RobotMsg::Ack { seq }),
        (any::<u16>(), nack).prop_map(|(seq, reason)| RobotMsg::Nack { seq, reason }),
        (any::<u16>(), outcome(), pose(), any::<u64>()).prop_map(
            |(seq, outcome, pose, time_us)| {
                RobotMsg::Done(Done {
                    seq,
                    outcome,
                    pose,
                    time_us,
                })
            }
        ),
        telemetry,
        (any::<u64>(), any::<u8>(), pose()).prop_map(|(time_us, bumper, pose)| {
            RobotMsg::Contact(ContactEvent {
                time_us,
                bumper,
                pose,
            })
        }),
    ]
}

/// Index of each variant; the exhaustive match makes a new variant a compile error here,
/// so the coverage assertions below cannot silently miss it.
fn command_index(c: &Command) -> usize {
    match c {
        Command::Hello { .. } => 0,
        Command::Heartbeat => 1,
        Command::Velocity { .. } => 2,
        Command::Move { .. } => 3,
        Command::Spin { .. } => 4,
        Command::AdvanceUntilContact { .. } => 5,
        Command::Stop => 6,
        Command::EmergencyStop => 7,
        Command::ClearFaults => 8,
        Command::Configure(_) => 9,
        Command::ResetOdometry(_) => 10,
    }
}
const COMMAND_VARIANTS: usize = 11;

fn robot_index(m: &RobotMsg) -> usize {
    match m {
        RobotMsg::HelloReply(_) => 0,
        RobotMsg::Ack { .. } => 1,
        RobotMsg::Nack { .. } => 2,
        RobotMsg::Done(_) => 3,
        RobotMsg::Telemetry(_) => 4,
        RobotMsg::Contact(_) => 5,
    }
}
const ROBOT_VARIANTS: usize = 6;

fn frame<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(msg, &mut buf).expect("every message fits a frame");
    assert!(n <= MAX_FRAME);
    assert_eq!(buf[n - 1], 0, "frame ends with its delimiter");
    assert!(!buf[..n - 1].contains(&0), "no zero inside a frame");
    buf[..n].to_vec()
}

fn decode_all<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Vec<Result<T, DecodeError>> {
    let mut d = FrameDecoder::new();
    let mut out = Vec::new();
    d.feed(bytes, |r| out.push(r));
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn host_frames_round_trip(msg in host_frame()) {
        let got = decode_all::<HostFrame>(&frame(&msg));
        prop_assert_eq!(got, vec![Ok(msg)]);
    }

    #[test]
    fn robot_messages_round_trip(msg in robot_msg()) {
        let got = decode_all::<RobotMsg>(&frame(&msg));
        prop_assert_eq!(got, vec![Ok(msg)]);
    }

    #[test]
    fn frames_survive_garbage_before_them(garbage in proptest::collection::vec(any::<u8>(), 0..400), msg in host_frame()) {
        let mut bytes = garbage;
        bytes.push(0);
        bytes.extend(frame(&msg));
        let got = decode_all::<HostFrame>(&bytes);
        prop_assert_eq!(got.last(), Some(&Ok(msg)));
    }
}

#[test]
fn strategies_cover_every_variant() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let mut seen_c = [false; COMMAND_VARIANTS];
    let mut seen_r = [false; ROBOT_VARIANTS];
    for _ in 0..2000 {
        seen_c[command_index(&command().new_tree(&mut runner).unwrap().current())] = true;
        seen_r[robot_index(&robot_msg().new_tree(&mut runner).unwrap().current())] = true;
    }
    assert!(seen_c.iter().all(|s| *s), "commands seen: {seen_c:?}");
    assert!(seen_r.iter().all(|s| *s), "robot messages seen: {seen_r:?}");
}

#[test]
fn nan_survives_bit_exact() {
    let msg = HostFrame {
        seq: 7,
        cmd: Command::Velocity {
            v: f32::NAN,
            omega: f32::INFINITY,
            timeout_ms: 5,
        },
    };
    let got = decode_all::<HostFrame>(&frame(&msg));
    match got.as_slice() {
        [
            Ok(HostFrame {
                seq: 7,
                cmd:
                    Command::Velocity {
                        v,
                        omega,
                        timeout_ms: 5,
                    },
            }),
        ] => {
            assert_eq!(v.to_bits(), f32::NAN.to_bits());
            assert_eq!(*omega, f32::INFINITY);
        }
        other => panic!("unexpected {other:?}"),
    }
}

/// The largest value of every variant fits [`MAX_PAYLOAD`].
#[test]
fn worst_case_messages_fit() {
    let big = f32::MAX;
    let pose = Pose {
        x: big,
        y: big,
        theta: big,
    };
    let cmds = [
        Command::Configure(ConfigUpdate {
            wheel_gains: Some(WheelGains {
                kp: big,
                ki: big,
                kff: big,
            }),
            max_speed: Some(big),
            max_accel: Some(big),
            max_omega: Some(big),
            max_alpha: Some(big),
            watchdog_ms: Some(u16::MAX),
            telemetry_hz: Some(u16::MAX),
        }),
        Command::ResetOdometry(pose),
        Command::Velocity {
            v: big,
            omega: big,
            timeout_ms: u16::MAX,
        },
    ];
    for cmd in cmds {
        frame(&HostFrame { seq: u16::MAX, cmd });
    }
    let msgs = [
        RobotMsg::Telemetry(Telemetry {
            time_us: u64::MAX,
            pose,
            wheel_speed: [big, big],
            bumper: u8::MAX,
            mode: Mode::Faulted,
            faults: Faults(u16::MAX),
            active: Some(u16::MAX),
            last_done: Some((u16::MAX, Outcome::Fault(Faults(u16::MAX)))),
        }),
        RobotMsg::HelloReply(HelloReply {
            protocol: u16::MAX,
            accepted: true,
            firmware: FirmwareVersion {
                major: 255,
                minor: 255,
                patch: 255,
            },
            geometry: Geometry {
                wheel_base: big,
                wheel_radius: big,
                bumper_radius: big,
                encoder_cpr: u32::MAX,
                control_hz: u16::MAX,
            },
        }),
        RobotMsg::Done(Done {
            seq: u16::MAX,
            outcome: Outcome::Fault(Faults(u16::MAX)),
            pose,
            time_us: u64::MAX,
        }),
        RobotMsg::Contact(ContactEvent {
            time_us: u64::MAX,
            bumper: 255,
            pose,
        }),
    ];
    for m in msgs {
        frame(&m);
    }
}

fn sample_frames() -> Vec<Vec<u8>> {
    let pose = Pose {
        x: 0.25,
        y: -1.5,
        theta: 3.0,
    };
    let mut v: Vec<Vec<u8>> = [
        Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
        Command::Heartbeat,
        Command::Velocity {
            v: 0.1,
            omega: -0.5,
            timeout_ms: 300,
        },
        Command::Move {
            distance: 0.3,
            speed: 0.2,
            stop_on_contact: true,
        },
        Command::Spin {
            angle: 1.57,
            rate: 2.0,
        },
        Command::AdvanceUntilContact {
            max_distance: 1.0,
            speed: 0.1,
        },
        Command::Stop,
        Command::EmergencyStop,
        Command::ClearFaults,
        Command::Configure(ConfigUpdate {
            max_speed: Some(0.3),
            watchdog_ms: Some(200),
            ..Default::default()
        }),
        Command::ResetOdometry(pose),
    ]
    .iter()
    .enumerate()
    .map(|(i, cmd)| {
        frame(&HostFrame {
            seq: 1000 + i as u16,
            cmd: *cmd,
        })
    })
    .collect();
    for m in [
        RobotMsg::Ack { seq: 3 },
        RobotMsg::Nack {
            seq: 4,
            reason: NackReason::Faulted(Faults::STALL_LEFT),
        },
        RobotMsg::Done(Done {
            seq: 5,
            outcome: Outcome::Contact,
            pose,
            time_us: 123_456_789,
        }),
        RobotMsg::Telemetry(Telemetry {
            time_us: 99_000_000,
            pose,
            wheel_speed: [3.0, -3.0],
            bumper: 2,
            mode: Mode::Move,
            faults: Faults::NONE,
            active: Some(6),
            last_done: Some((5, Outcome::Completed)),
        }),
        RobotMsg::Contact(ContactEvent {
            time_us: 5,
            bumper: 1,
            pose,
        }),
    ] {
        v.push(frame(&m));
    }
    v
}

/// Flip every single bit of every sample frame: no flipped frame may decode to any message.
#[test]
fn every_single_bit_flip_is_rejected() {
    let mut checked = 0;
    for f in sample_frames() {
        for bit in 0..f.len() * 8 {
            let mut g = f.clone();
            g[bit / 8] ^= 1 << (bit % 8);
            // A trailing delimiter flushes a frame whose own delimiter the flip destroyed.
            g.push(0);
            let host: Vec<_> = decode_all::<HostFrame>(&g)
                .into_iter()
                .filter(Result::is_ok)
                .collect();
            let robot: Vec<_> = decode_all::<RobotMsg>(&g)
                .into_iter()
                .filter(Result::is_ok)
                .collect();
            assert!(
                host.is_empty() && robot.is_empty(),
                "bit {bit} of {f:02x?} accepted: {host:?} {robot:?}"
            );
            checked += 1;
        }
    }
    assert!(checked > 2000, "only {checked} flips checked");
}

/// 100 000+ random and mutated inputs: no panic, and the decoder still decodes a valid frame
/// afterwards (resynchronisation).
#[test]
fn decoder_survives_random_and_mutated_input() {
    let samples = sample_frames();
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let mut d = FrameDecoder::new();
    let mut inputs = 0usize;
    let mut accepted = 0usize;
    let probe = frame(&HostFrame {
        seq: 42,
        cmd: Command::Stop,
    });
    while inputs < 120_000 {
        let mut input: Vec<u8> = match rng.random_range(0..6) {
            // Pure noise, with and without zeros.
            0 => (0..rng.random_range(0..300))
                .map(|_| rng.random())
                .collect(),
            1 => (0..rng.random_range(0..300))
                .map(|_| rng.random_range(1..=255))
                .collect(),
            // A valid frame with random bytes replaced.
            2 => {
                let mut g = samples[rng.random_range(0..samples.len())].clone();
                for _ in 0..rng.random_range(1..4) {
                    let i = rng.random_range(0..g.len());
                    g[i] = rng.random();
                }
                g
            }
            // Truncated.
            3 => {
                let g = &samples[rng.random_range(0..samples.len())];
                g[..rng.random_range(0..g.len())].to_vec()
            }
            // Bytes inserted or deleted.
            4 => {
                let mut g = samples[rng.random_range(0..samples.len())].clone();
                let i = rng.random_range(0..g.len());
                if rng.random() {
                    g.insert(i, rng.random());
                } else {
                    g.remove(i);
                }
                g
            }
            // Two frames spliced.
            _ => {
                let a = &samples[rng.random_range(0..samples.len())];
                let b = &samples[rng.random_range(0..samples.len())];
                let mut g = a[..rng.random_range(0..a.len())].to_vec();
                g.extend_from_slice(&b[rng.random_range(0..b.len())..]);
                g
            }
        };
        if rng.random_range(0..4) == 0 {
            input.extend(std::iter::repeat_n(0x55, MAX_FRAME + 3));
        }
        d.feed::<HostFrame>(&input, |r| accepted += r.is_ok() as usize);
        d.feed::<RobotMsg>(&input, |_| {});
        inputs += 1;
        if inputs.is_multiple_of(1000) {
            // Resynchronise: a delimiter, then a good frame, must decode.
            let mut got = None;
            d.feed::<HostFrame>(&[0], |_| {});
            d.feed::<HostFrame>(&probe, |r| got = Some(r));
            assert_eq!(
                got,
                Some(Ok(HostFrame {
                    seq: 42,
                    cmd: Command::Stop
                }))
            );
        }
    }
    // Mutations that hit only the payload or CRC must be caught; a few may still be valid
    // (e.g. a splice that happens to reproduce a whole frame), but never most.
    assert!(
        accepted < inputs / 10,
        "{accepted} of {inputs} mutated inputs accepted"
    );
}

#[test]
fn overlong_frames_are_dropped_then_recovered() {
    let mut bytes = vec![7u8; MAX_FRAME * 3];
    bytes.push(0);
    bytes.extend(frame(&HostFrame {
        seq: 1,
        cmd: Command::Heartbeat,
    }));
    let got = decode_all::<HostFrame>(&bytes);
    assert_eq!(
        got,
        vec![
            Err(DecodeError::Overflow),
            Ok(HostFrame {
                seq: 1,
                cmd: Command::Heartbeat
            })
        ]
    );
}

#[test]
fn wrong_direction_is_not_a_message() {
    // A robot message fed to a host decoder must not decode as a command with all bytes used.
    let t = frame(&RobotMsg::Telemetry(Telemetry {
        time_us: 1,
        pose: Pose::default(),
        wheel_speed: [0.0, 0.0],
        bumper: 0,
        mode: Mode::Idle,
        faults: Faults::NONE,
        active: None,
        last_done: None,
    }));
    let got = decode_all::<HostFrame>(&t);
    assert!(matches!(got.as_slice(), [Err(_)]), "{got:?}");
}

#[test]
fn encode_reports_small_buffers() {
    let mut small = [0u8; 4];
    assert_eq!(
        encode_frame(
            &HostFrame {
                seq: 1,
                cmd: Command::Spin {
                    angle: 1.0,
                    rate: 1.0
                }
            },
            &mut small
        ),
        Err(EncodeError::BufferTooSmall)
    );
}

#[test]
fn error_messages_read_well() {
    assert_eq!(DecodeError::Crc.to_string(), "CRC mismatch");
    assert!(
        EncodeError::TooLarge
            .to_string()
            .contains(&MAX_PAYLOAD.to_string())
    );
}
