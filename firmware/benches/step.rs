//! Cost of one control step of the core on the host, idle and while running a move (with
//! telemetry encoding and draining), and of receiving one command frame.

use criterion::{Criterion, criterion_group, criterion_main};
use pushbot_firmware::{Core, Inputs, RobotParams};
use pushbot_protocol::{Command, HostFrame, PROTOCOL_VERSION, encode_frame};

fn frame(seq: u16, cmd: Command) -> Vec<u8> {
    let mut buf = [0u8; 256];
    let n = encode_frame(&HostFrame { seq, cmd }, &mut buf).expect("encode");
    buf[..n].to_vec()
}

fn bench(c: &mut Criterion) {
    let hello = frame(
        1,
        Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    );
    let mv2 = frame(
        3,
        Command::Velocity {
            v: 0.2,
            omega: 1.0,
            timeout_ms: 1000,
        },
    );
    let mv = frame(
        2,
        Command::Velocity {
            v: 0.2,
            omega: 1.0,
            timeout_ms: 1000,
        },
    );

    c.bench_function("step_idle", |b| {
        let mut core = Core::new(RobotParams::default());
        let mut now = 0u64;
        let mut out = [0u8; 256];
        b.iter(|| {
            now += 1000;
            let o = core.step(now, &Inputs::default());
            core.transmit(&mut out);
            o
        })
    });

    c.bench_function("step_driving", |b| {
        let mut core = Core::new(RobotParams::default());
        core.receive(0, &hello);
        core.receive(0, &mv);
        let mut now = 0u64;
        let mut enc = [0i32; 2];
        let mut out = [0u8; 256];
        b.iter(|| {
            now += 1000;
            enc[0] = enc[0].wrapping_add(4);
            enc[1] = enc[1].wrapping_add(5);
            // A fresh velocity command every 50 ms keeps it driving (and the watchdog fed).
            if now.is_multiple_of(100_000) {
                core.receive(now, &mv);
            } else if now.is_multiple_of(50_000) {
                core.receive(now, &mv2);
            }
            let o = core.step(
                now,
                &Inputs {
                    encoder: enc,
                    bumper: 0,
                },
            );
            core.transmit(&mut out);
            o
        })
    });

    c.bench_function("receive_command_frame", |b| {
        let mut core = Core::new(RobotParams::default());
        core.receive(0, &hello);
        let mut seq = 10u16;
        let mut out = [0u8; 256];
        b.iter(|| {
            seq = seq.wrapping_add(1);
            let f = frame(
                seq,
                Command::Spin {
                    angle: 1.0,
                    rate: 2.0,
                },
            );
            core.receive(0, &f);
            core.transmit(&mut out)
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
