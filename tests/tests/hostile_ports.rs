//! `pushbot robot …` against ports that are not a pushbot robot, each on a real pseudo-terminal
//! whose other end behaves as the case says: silence, garbage at a serial line's pace, zero
//! bytes, a flood, an echo of what the host sends, a port that vanishes mid-handshake, and a
//! robot that speaks another protocol version. Every command exits 1 within 2.0 s of wall time,
//! with the message for its case, and never panics.

use std::io::{Read, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use pushbot_protocol::{
    FirmwareVersion, FrameDecoder, Geometry, HelloReply, HostFrame, MAX_FRAME, PROTOCOL_VERSION,
    RobotMsg, encode_frame,
};
use pushbot_tests::{Run, run_bin};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serialport::{SerialPort, TTYPort};

/// How the other end of the port behaves.
#[derive(Debug, Clone, Copy)]
enum Peer {
    Silence,
    Garbage,
    Zeros,
    Flood,
    Echo,
    Closed,
    OtherVersion,
}

/// The other end of a pty, behaving as `peer` until the host has gone.
fn serve(peer: Peer, mut master: TTYPort, stop: &AtomicBool) {
    let mut rng = ChaCha8Rng::seed_from_u64(peer as u64);
    let mut buf = [0u8; 512];
    let mut dec = FrameDecoder::new();
    let _ = master.set_timeout(Duration::from_millis(10));
    let (t0, mut sent) = (Instant::now(), 0u64);
    while !stop.load(Ordering::Relaxed) {
        // Until the host opens its end (and after it closed it) a read fails: keep going.
        let n = match master.read(&mut buf) {
            Ok(n) => n,
            Err(_) => {
                std::thread::sleep(Duration::from_millis(2));
                0
            }
        };
        let out: Vec<u8> = match peer {
            Peer::Silence => Vec::new(),
            // 5 000 bytes a second by the clock: a device on a serial line, well below a flood.
            Peer::Garbage => {
                let due = (t0.elapsed().as_secs_f64() * 5000.0) as u64;
                let n = due.saturating_sub(sent);
                sent += n;
                (0..n).map(|_| rng.random()).collect()
            }
            Peer::Zeros => vec![0; 100],
            Peer::Flood => (0..4096).map(|_| rng.random()).collect(),
            Peer::Echo => buf[..n].to_vec(),
            Peer::Closed if n > 0 => return, // drops the master: the port vanishes
            Peer::Closed => Vec::new(),
            Peer::OtherVersion => {
                let mut out = Vec::new();
                for &b in &buf[..n] {
                    if let Some(Ok(_)) = dec.push::<HostFrame>(b) {
                        out.extend(foreign_hello_reply());
                    }
                }
                out
            }
        };
        if !out.is_empty() {
            // A full buffer (nobody reading) times out: drop what did not fit.
            let _ = master.write_all(&out);
        }
    }
}

/// A `HelloReply` of the next protocol version.
fn foreign_hello_reply() -> Vec<u8> {
    let msg = RobotMsg::HelloReply(HelloReply {
        protocol: PROTOCOL_VERSION + 1,
        accepted: false,
        firmware: FirmwareVersion {
            major: 9,
            minor: 0,
            patch: 0,
        },
        geometry: Geometry {
            wheel_base: 0.1,
            wheel_radius: 0.02,
            bumper_radius: 0.05,
            encoder_cpr: 1000,
            control_hz: 1000,
        },
    });
    let mut frame = [0u8; MAX_FRAME];
    let n = encode_frame(&msg, &mut frame).expect("frame the reply");
    frame[..n].to_vec()
}

/// Run `pushbot <args> --port P` against a fresh port whose other end is `peer`; the run and
/// its wall time.
fn against(peer: Peer, args: &[&str]) -> (Run, Duration) {
    let (original_master, original_slave) = TTYPort::pair().expect("a pty pair");
    // Close-on-exec copies in place of the originals: a copy of the master inherited by the
    // command would keep the port alive after the peer closed it.
    let master = original_master
        .try_clone_native()
        .expect("a copy of the master");
    let slave = original_slave
        .try_clone_native()
        .expect("a copy of the port's end");
    drop((original_master, original_slave));
    let path = slave.name().expect("the pty's path");
    // The test keeps its own handle on the port's end open, so that the pty stays while the
    // host opens, closes and reopens it.
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let server = std::thread::spawn(move || serve(peer, master, &flag));
    let mut argv = args.to_vec();
    argv.extend(["--port", &path]);
    let t0 = Instant::now();
    let run = run_bin("pushbot", &argv);
    let took = t0.elapsed();
    stop.store(true, Ordering::Relaxed);
    let _ = server.join();
    drop(slave);
    (run, took)
}

#[test]
fn every_hostile_port_gets_its_own_message_within_two_seconds() {
    let cases: [(Peer, &str); 7] = [
        (Peer::Silence, "no answer from the robot"),
        (Peer::Garbage, "wrong baud rate or another device?"),
        (Peer::Zeros, "only zero bytes arrive"),
        (Peer::Flood, "a flood of bytes"),
        (Peer::Echo, "echoes back what the host sends"),
        (Peer::Closed, "disappeared"),
        (Peer::OtherVersion, "protocol version mismatch"),
    ];
    let commands: [&[&str]; 2] = [&["robot", "info"], &["robot", "move", "--distance", "0.1"]];
    // Build the binary before the clock runs.
    let _ = pushbot_tests::bin("pushbot");
    let mut failures = Vec::new();
    for (peer, expected) in cases {
        // One at a time: a pty opened while another command starts would be inherited by it.
        let runs: Vec<_> = commands
            .iter()
            .map(|args| (args, against(peer, args)))
            .collect();
        for (args, (run, took)) in runs {
            let what = format!("{peer:?}, `pushbot {}`", args.join(" "));
            eprintln!(
                "{what}: exit {:?} in {:.2} s: {}",
                run.code,
                took.as_secs_f64(),
                run.stderr.trim()
            );
            if run.code != Some(1) {
                failures.push(format!("{what}: exit {:?}, not 1", run.code));
            }
            if took > Duration::from_secs(2) {
                failures.push(format!("{what}: took {:.2} s", took.as_secs_f64()));
            }
            if !run.stderr.contains(expected) {
                failures.push(format!("{what}: no {expected:?} in {:?}", run.stderr));
            }
            if run.stderr.contains("panicked") {
                failures.push(format!("{what}: panicked"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
