//! What the client says when its `Hello` goes unanswered, by what the line carried instead:
//! nothing, zeros, its own frames echoed, garbage (slow or a flood), or pushbot frames that are
//! not a reply. Driven byte by byte with no I/O; host time is what each test says.

use pushbot_protocol::{
    Command, FrameDecoder, HostFrame, MAX_FRAME, Pose, RobotMsg, Telemetry, encode_frame,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::client::{Client, ClientOptions, Handshake, Heard, HostTime};
use super::error::LinkError;

fn ms(v: u64) -> HostTime {
    HostTime::from_micros(v * 1000)
}

/// Run a handshake for 2 s of host time in 10 ms steps; `line` gives the bytes that arrive in
/// each step from what the host sent in it. Returns the outcome, when it came (ms) and how
/// many `Hello`s were sent.
fn handshake(mut line: impl FnMut(u64, &[u8]) -> Vec<u8>) -> (Handshake, u64, u32) {
    let mut c = Client::new(ms(0), ClientOptions::default());
    c.hello(ms(0));
    let mut hellos = 0;
    let mut dec = FrameDecoder::new();
    for t in (0..=2000u64).step_by(10) {
        let now = ms(t);
        if c.poll_timeout().is_some_and(|d| d <= now) {
            c.handle_timeout(now);
        }
        let mut out = Vec::new();
        while let Some(b) = c.poll_transmit(now) {
            out.extend(b);
        }
        dec.feed::<HostFrame>(&out, |f| {
            if f.is_ok_and(|f| matches!(f.cmd, Command::Hello { .. })) {
                hellos += 1;
            }
        });
        let back = line(t, &out);
        c.handle_bytes(now, &back);
        if let Some(h) = c.handshake() {
            return (h, t, hellos);
        }
    }
    panic!("the handshake did not end within 2 s");
}

fn heard(h: Handshake) -> Heard {
    match h {
        Handshake::NoAnswer { heard, .. } => heard,
        other => panic!("expected no answer, got {other:?}"),
    }
}

fn message(h: Handshake) -> String {
    let Handshake::NoAnswer { attempts, heard } = h else {
        panic!("expected no answer, got {h:?}");
    };
    LinkError::HelloUnanswered {
        path: "/dev/ttyX".into(),
        attempts,
        heard,
    }
    .to_string()
}

#[test]
fn silence_is_nothing_heard_within_the_hello_timeout() {
    let (h, t, _) = handshake(|_, _| Vec::new());
    assert_eq!(heard(h), Heard::Nothing);
    assert!(t <= 1500, "gave up at {t} ms");
    assert!(
        message(h).contains("no answer from the robot"),
        "{}",
        message(h)
    );
}

#[test]
fn zeros_are_told_from_garbage() {
    let (h, _, _) = handshake(|_, _| vec![0; 12]);
    assert!(
        matches!(heard(h), Heard::Zeros { bytes } if bytes > 1000),
        "{h:?}"
    );
    assert!(message(h).contains("only zero bytes"), "{}", message(h));
}

#[test]
fn an_echo_is_recognised_and_not_taken_for_a_robot() {
    let (h, _, _) = handshake(|_, out| out.to_vec());
    assert!(matches!(heard(h), Heard::Echo { .. }), "{h:?}");
    assert!(message(h).contains("echoes back"), "{}", message(h));
}

#[test]
fn garbage_is_not_a_noisy_wire_and_costs_no_extra_attempts() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    // About 9.6 kB/s: a device at 115 200 baud, or a wrong baud rate.
    let (h, t, hellos) = handshake(|_, _| (0..96).map(|_| rng.random::<u8>()).collect());
    let Heard::Garbage { bytes, secs } = heard(h) else {
        panic!("{h:?}");
    };
    assert!(bytes > 10_000 && secs > 1.0, "{bytes} bytes in {secs} s");
    assert!(t <= 1500, "gave up at {t} ms after {hellos} hellos");
    assert!(hellos <= 10, "{hellos} hellos");
    let m = message(h);
    assert!(m.contains("wrong baud rate or another device?"), "{m}");
    assert!(!m.contains("flood"), "{m}");
}

#[test]
fn a_flood_is_named_as_one() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let (h, _, _) = handshake(|_, _| (0..4096).map(|_| rng.random::<u8>()).collect());
    let m = message(h);
    assert!(m.contains("a flood of bytes"), "{m}");
}

#[test]
fn pushbot_frames_without_a_reply_are_told_apart() {
    let mut buf = [0u8; MAX_FRAME];
    let (h, _, _) = handshake(|t, _| {
        let msg = RobotMsg::Telemetry(Telemetry {
            time_us: t * 1000,
            pose: Pose::default(),
            wheel_speed: [0.0; 2],
            bumper: 0,
            mode: pushbot_protocol::Mode::Idle,
            faults: pushbot_protocol::Faults::NONE,
            active: None,
            last_done: None,
        });
        let n = encode_frame(&msg, &mut buf).unwrap();
        buf[..n].to_vec()
    });
    assert!(
        matches!(heard(h), Heard::Frames { frames } if frames > 100),
        "{h:?}"
    );
    assert!(
        message(h).contains("does not answer Hello"),
        "{}",
        message(h)
    );
}
