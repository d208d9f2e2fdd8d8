//! Hostile bytes into the robot core, through its real byte input ([`Core::receive`]):
//! valid host frames of every command with random fields, mutated (see `hostile_gen`) and fed
//! in random chunks, seeded. After every chunk:
//!
//! * the core's rejected-frame counter equals that of a reference `FrameDecoder` fed the same
//!   bytes, and is at least the number of frames known to be corrupt;
//! * a motion that started came from a frame that arrived whole with a right CRC in this case,
//!   of the same sequence number and kind, and each such frame starts at most one motion
//!   (a duplicated frame is a retry, never a second start);
//! * the core answers with frames that decode.
//!
//! Frame count: `CASES` × 1..=6 frames, 520 000 generated frames in all (with
//! `host/tests/hostile_link.rs`, over 10⁶). About 1 s at the test profile (opt-level 1).

use pushbot_firmware::{Core, Inputs, Mode, RobotParams};
use pushbot_protocol::{
    Command, ConfigUpdate, FrameDecoder, HostFrame, MAX_FRAME, PROTOCOL_VERSION, Pose, RobotMsg,
    WheelGains, decode_payload, encode_frame,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod hostile_gen;

use hostile_gen::{MUTATIONS, chunks, frame_with_crc, mutate, payload_of};

/// Frames generated for the core.
const FRAMES: u64 = 520_000;

/// A float that is mostly within `lo..=hi`, sometimes outside, sometimes not finite.
fn float(rng: &mut impl Rng, lo: f32, hi: f32) -> f32 {
    match rng.random_range(0..20) {
        0 => f32::NAN,
        1 => f32::INFINITY,
        2 => -f32::INFINITY,
        3 => f32::from_bits(rng.random()),
        4 => rng.random_range(-1e3..1e3),
        _ => rng.random_range(lo..=hi),
    }
}

/// A host frame of a random command with random fields; sequence numbers mostly small so
/// retries and reused numbers happen.
pub fn host_frame(rng: &mut impl Rng) -> HostFrame {
    let seq = if rng.random_bool(0.9) {
        rng.random_range(0..12)
    } else {
        rng.random()
    };
    let cmd = match rng.random_range(0..16) {
        0..=1 => Command::Hello {
            protocol: if rng.random_bool(0.9) {
                PROTOCOL_VERSION
            } else {
                rng.random()
            },
        },
        2 => Command::Heartbeat,
        3..=4 => Command::Velocity {
            v: float(rng, -0.3, 0.3),
            omega: float(rng, -4.0, 4.0),
            timeout_ms: rng.random_range(0..500),
        },
        5..=6 => Command::Move {
            distance: float(rng, -1.0, 1.0),
            speed: float(rng, 0.01, 0.3),
            stop_on_contact: rng.random(),
        },
        7 => Command::Spin {
            angle: float(rng, -6.0, 6.0),
            rate: float(rng, 0.1, 4.0),
        },
        8 => Command::AdvanceUntilContact {
            max_distance: float(rng, 0.01, 1.0),
            speed: float(rng, 0.01, 0.3),
        },
        9 => Command::Stop,
        10 => Command::EmergencyStop,
        11..=12 => Command::ClearFaults,
        13 => {
            let mut c = || rng.random_bool(0.3);
            let (g, s, a, o, al, w, t) = (c(), c(), c(), c(), c(), c(), c());
            Command::Configure(ConfigUpdate {
                wheel_gains: g.then(|| WheelGains {
                    kp: float(rng, 0.0, 2.0),
                    ki: float(rng, 0.0, 2.0),
                    kff: float(rng, 0.0, 2.0),
                }),
                max_speed: s.then(|| float(rng, 0.05, 0.45)),
                max_accel: a.then(|| float(rng, 0.1, 2.0)),
                max_omega: o.then(|| float(rng, 0.5, 8.0)),
                max_alpha: al.then(|| float(rng, 1.0, 40.0)),
                // Never so short that the watchdog trips between two cases.
                watchdog_ms: w.then(|| rng.random_range(150..6000)),
                telemetry_hz: t.then(|| rng.random_range(0..300)),
            })
        }
        _ => Command::ResetOdometry(Pose {
            x: float(rng, -5.0, 5.0),
            y: float(rng, -5.0, 5.0),
            theta: float(rng, -7.0, 7.0),
        }),
    };
    HostFrame { seq, cmd }
}

/// The mode a motion command runs in.
fn motion_mode(cmd: &Command) -> Option<Mode> {
    match cmd {
        Command::Velocity { .. } => Some(Mode::Velocity),
        Command::Move { .. } => Some(Mode::Move),
        Command::Spin { .. } => Some(Mode::Spin),
        Command::AdvanceUntilContact { .. } => Some(Mode::Advance),
        _ => None,
    }
}

fn encoded(f: &HostFrame) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(f, &mut buf).expect("every host frame fits");
    buf[..n].to_vec()
}

#[test]
fn framing_helpers_match_the_protocol() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for _ in 0..10_000 {
        let f = host_frame(&mut rng);
        let bytes = encoded(&f);
        let p = payload_of(&bytes);
        let back = decode_payload::<HostFrame>(&p).expect("decodes");
        assert_eq!(encoded(&back), bytes); // (bitwise: NaN fields compare unequal)
        assert_eq!(frame_with_crc(&p, hostile_gen::crc32c(&p)), bytes);
    }
}

/// Summary of a run, for the report line and the checks at the end.
#[derive(Default, Debug)]
struct Tally {
    frames: u64,
    bytes: u64,
    starts: u64,
    known_bad: u64,
    by_kind: [u64; MUTATIONS.len()],
}

fn run(seed: u64, frames: u64) -> Tally {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut core = Core::new(RobotParams::default());
    let tick = u64::from(core.tick_period_us());
    let mut reference = FrameDecoder::new();
    let mut replies = FrameDecoder::new();
    let mut ref_rejected: u64 = 0;
    let mut t = Tally::default();
    let mut now: u64 = 0;
    let mut encoder = [0i32; 2];
    let mut stream = Vec::new();
    let mut tx = [0u8; 4096];
    // Motions that may start: (seq, mode, from the case's last piece).
    let mut allowed: Vec<(u16, Mode, bool)> = Vec::new();
    while t.frames < frames {
        // One case: a few frames, mutated, fed in random chunks, then one control step.
        stream.clear();
        // The last frame of the previous case may be completed by this case's first zero.
        allowed.retain(|a| a.2);
        for a in &mut allowed {
            a.2 = false;
        }
        let mut case_bad = 0u64;
        let pieces = rng.random_range(1..=6);
        for piece in 0..pieces {
            let f = host_frame(&mut rng);
            let other = host_frame(&mut rng);
            let m = mutate(&mut rng, &encoded(&f), &encoded(&other), &mut stream);
            t.frames += 1;
            t.by_kind[m.kind] += 1;
            case_bad += u64::from(m.known_bad);
            for p in &m.valid {
                match decode_payload::<HostFrame>(p) {
                    Ok(hf) => {
                        if let Some(mode) = motion_mode(&hf.cmd) {
                            allowed.push((hf.seq, mode, piece + 1 == pieces));
                        }
                    }
                    // Garbage under a right CRC is certainly rejected when it is no message.
                    Err(_) if m.kind == 10 => case_bad += 1,
                    Err(_) => unreachable!("a valid frame that does not decode"),
                }
            }
        }
        t.known_bad += case_bad;
        t.bytes += stream.len() as u64;
        let mut from = 0;
        for end in chunks(&mut rng, stream.len(), 48) {
            let chunk = &stream[from..end];
            from = end;
            let before = (core.active(), core.last_done());
            core.receive(now, chunk);
            reference.feed::<HostFrame>(chunk, |r| ref_rejected += u64::from(r.is_err()));
            assert_eq!(
                u64::from(core.rx_rejected()),
                ref_rejected,
                "seed {seed}: rejected-frame counter disagrees with the reference decoder"
            );
            let after = (core.active(), core.last_done());
            if let Some(seq) = after.0
                && after != before
            {
                // A motion started in this chunk: from a frame that arrived whole, once.
                let started = (seq, core.mode());
                let Some(i) = allowed.iter().position(|a| (a.0, a.1) == started) else {
                    panic!(
                        "seed {seed}: motion {started:?} started from no valid frame \
                         (may start: {allowed:?}); chunk {chunk:02x?}"
                    );
                };
                allowed.swap_remove(i);
                t.starts += 1;
            }
            let n = core.transmit(&mut tx);
            replies.feed::<RobotMsg>(&tx[..n], |r| {
                assert!(r.is_ok(), "seed {seed}: the core sent a bad frame: {r:?}");
            });
        }
        assert!(
            u64::from(core.rx_rejected()) >= t.known_bad,
            "seed {seed}: {} frames rejected, {} known corrupt",
            core.rx_rejected(),
            t.known_bad
        );
        now += tick;
        let duty = core.outputs().duty;
        for (e, d) in encoder.iter_mut().zip(duty) {
            *e = e.wrapping_add((d * 8.0) as i32);
        }
        core.step(now, &Inputs { encoder, bumper: 0 });
        let n = core.transmit(&mut tx);
        replies.feed::<RobotMsg>(&tx[..n], |r| assert!(r.is_ok(), "bad reply frame {r:?}"));
    }
    t
}

#[test]
fn hostile_frames_into_the_core() {
    let t0 = std::time::Instant::now();
    let t = run(0x5eed_0019, FRAMES);
    eprintln!("{t:?} in {:?}", t0.elapsed());
    assert!(t.frames >= FRAMES);
    // The run exercised what it claims: motions started, every mutation happened.
    assert!(t.starts > 1000, "{t:?}");
    assert!(t.by_kind.iter().all(|&k| k > 1000), "{t:?}");
}
