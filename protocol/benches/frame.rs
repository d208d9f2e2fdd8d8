//! Encode + decode time per frame.
use criterion::{Criterion, criterion_group, criterion_main};
use pushbot_protocol::*;
use std::hint::black_box;

fn telemetry() -> RobotMsg {
    RobotMsg::Telemetry(Telemetry {
        time_us: 12_345_678,
        pose: Pose {
            x: 0.31,
            y: -0.12,
            theta: 1.2,
        },
        wheel_speed: [4.2, 3.9],
        bumper: 0,
        mode: Mode::Move,
        faults: Faults::NONE,
        active: Some(17),
        last_done: Some((16, Outcome::Completed)),
    })
}

fn bench(c: &mut Criterion) {
    let mut buf = [0u8; MAX_FRAME];
    let msg = telemetry();
    c.bench_function("telemetry encode+decode", |b| {
        b.iter(|| {
            let n = encode_frame(black_box(&msg), &mut buf).unwrap();
            let mut d = FrameDecoder::new();
            let mut out = None;
            d.feed::<RobotMsg>(&buf[..n], |r| out = Some(r));
            black_box(out)
        })
    });
    let cmd = HostFrame {
        seq: 9,
        cmd: Command::Move {
            distance: 0.3,
            speed: 0.2,
            stop_on_contact: true,
        },
    };
    c.bench_function("move command encode+decode", |b| {
        b.iter(|| {
            let n = encode_frame(black_box(&cmd), &mut buf).unwrap();
            let mut d = FrameDecoder::new();
            let mut out = None;
            d.feed::<HostFrame>(&buf[..n], |r| out = Some(r));
            black_box(out)
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
