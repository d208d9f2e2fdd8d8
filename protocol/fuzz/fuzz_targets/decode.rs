//! Fuzz the frame decoder: arbitrary bytes, fed whole and byte by byte, as both message
//! directions. It must never panic, and a good frame after a delimiter must always decode.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pushbot_protocol::{Command, FrameDecoder, HostFrame, MAX_FRAME, RobotMsg, encode_frame};

fuzz_target!(|data: &[u8]| {
    let mut host = FrameDecoder::new();
    let mut robot = FrameDecoder::new();
    host.feed::<HostFrame>(data, |_| {});
    robot.feed::<RobotMsg>(data, |_| {});

    // Resynchronisation: a delimiter and a valid frame decode whatever came before.
    let probe = HostFrame { seq: 7, cmd: Command::Stop };
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(&probe, &mut buf).expect("probe fits");
    let mut got = None;
    host.feed::<HostFrame>(&[0], |_| {});
    host.feed::<HostFrame>(&buf[..n], |r| got = Some(r));
    assert_eq!(got, Some(Ok(probe)));
});
