//! Fuzz the robot core through its real byte input, with a fake clock: after a valid `Hello`
//! (so commands get past the session check), the input is cut into chunks, each led by a
//! control byte (chunk length, whether a control step runs, how far the clock moves). The core
//! must never panic, its duties stay finite within -1..=1, every byte it sends decodes, it
//! rejects at most one frame per delimiter, and after a delimiter a valid `Stop` is answered.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pushbot_firmware::{Core, Inputs, RobotParams};
use pushbot_protocol::{
    Command, FrameDecoder, HostFrame, MAX_FRAME, PROTOCOL_VERSION, RobotMsg, encode_frame,
};

fn frame(f: &HostFrame) -> ([u8; MAX_FRAME], usize) {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(f, &mut buf).expect("fits");
    (buf, n)
}

fuzz_target!(|data: &[u8]| {
    let mut core = Core::new(RobotParams::default());
    let mut replies = FrameDecoder::new();
    let mut tx = [0u8; 4096];
    let mut now: u64 = 0;
    let mut encoder = [0i32; 2];
    let mut check = |core: &mut Core, replies: &mut FrameDecoder| -> Vec<RobotMsg> {
        let d = core.outputs().duty;
        assert!(d.iter().all(|x| x.is_finite() && x.abs() <= 1.0), "duty {d:?}");
        let n = core.transmit(&mut tx);
        let mut msgs = Vec::new();
        replies.feed::<RobotMsg>(&tx[..n], |r| msgs.push(r.expect("the core sends valid frames")));
        msgs
    };

    let hello = HostFrame {
        seq: 0xfff0,
        cmd: Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    };
    let (buf, n) = frame(&hello);
    core.receive(now, &buf[..n]);
    check(&mut core, &mut replies);

    let mut zeros = 0u64;
    let mut rest = data;
    while let Some((&ctl, tail)) = rest.split_first() {
        let len = usize::from(ctl & 0x3f).min(tail.len());
        let (chunk, after) = tail.split_at(len);
        rest = after;
        zeros += chunk.iter().filter(|&&b| b == 0).count() as u64;
        core.receive(now, chunk);
        assert!(u64::from(core.rx_rejected()) <= zeros);
        check(&mut core, &mut replies);
        if ctl & 0x40 != 0 {
            now += u64::from(core.tick_period_us()) * u64::from(1 + (ctl >> 7) * 50);
            let d = core.outputs().duty;
            for (e, x) in encoder.iter_mut().zip(d) {
                *e = e.wrapping_add((x * 8.0) as i32);
            }
            core.step(now, &Inputs { encoder, bumper: 0 });
            check(&mut core, &mut replies);
        }
    }

    // Resynchronisation: after a delimiter, a valid command is executed and answered.
    let stop = HostFrame {
        seq: 0xfff1,
        cmd: Command::Stop,
    };
    let (buf, n) = frame(&stop);
    core.receive(now, &[0]);
    core.receive(now, &buf[..n]);
    let msgs = check(&mut core, &mut replies);
    assert!(
        msgs.iter().any(|m| matches!(
            m,
            RobotMsg::Ack { seq: 0xfff1 } | RobotMsg::Nack { seq: 0xfff1, .. }
        )),
        "no answer to a valid frame after a delimiter: {msgs:?}"
    );
});
