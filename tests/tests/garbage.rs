//! HIL: garbage and corrupted frames injected into the link never cause a motion, and the link
//! recovers: a real command afterwards still works.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pushbot_protocol::{Command, HostFrame, MAX_FRAME, Outcome, encode_frame};
use pushbot_tests::{connect, dist, sim_at};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A valid frame of a 0.2 m move under a sequence number the robot has not seen.
fn move_frame(seq: u16) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(
        &HostFrame {
            seq,
            cmd: Command::Move {
                distance: 0.2,
                speed: 0.2,
                stop_on_contact: false,
            },
        },
        &mut buf,
    )
    .unwrap();
    buf[..n].to_vec()
}

#[test]
fn garbage_and_corrupted_frames_never_cause_a_motion() {
    let sim = Arc::new(sim_at(7, 0.6, 0.45, 0.0));
    let robot = connect(&sim);
    let t0 = robot.wait_telemetry(None).unwrap();
    let start = sim.truth().pose;

    // Watch the true duties throughout the injection.
    let stop = Arc::new(AtomicBool::new(false));
    let watcher = {
        let (sim, stop) = (Arc::clone(&sim), Arc::clone(&stop));
        std::thread::spawn(move || {
            let mut worst = 0.0f32;
            while !stop.load(Ordering::Relaxed) {
                let d = sim.truth().duty;
                worst = worst.max(d[0].abs()).max(d[1].abs());
                std::thread::sleep(Duration::from_micros(200));
            }
            worst
        })
    };

    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let good = move_frame(40_000);
    let body = &good[..good.len() - 1]; // without the delimiter
    let mut injected = 0usize;
    // 1. Every single-bit corruption of a valid Move frame, each closed by a delimiter.
    for i in 0..body.len() {
        for bit in 0..8 {
            let mut f = body.to_vec();
            f[i] ^= 1 << bit;
            f.push(0);
            robot.send_raw(&f).unwrap();
            injected += 1;
        }
    }
    // 2. Truncated frames, and a frame with bytes swapped.
    for cut in 1..body.len() {
        let mut f = body[..cut].to_vec();
        f.push(0);
        robot.send_raw(&f).unwrap();
        injected += 1;
    }
    let mut swapped = body.to_vec();
    swapped.swap(1, body.len() - 2);
    swapped.push(0);
    robot.send_raw(&swapped).unwrap();
    // 3. Random garbage with the occasional delimiter, and an overlong run without one.
    for _ in 0..64 {
        let len = rng.random_range(1..200);
        let chunk: Vec<u8> = (0..len)
            .map(|_| {
                if rng.random_bool(0.05) {
                    0
                } else {
                    rng.random()
                }
            })
            .collect();
        robot.send_raw(&chunk).unwrap();
        injected += 1;
    }
    robot.send_raw(&[0x5a; 4 * MAX_FRAME]).unwrap();
    robot.send_raw(&[0]).unwrap();

    // Let the robot chew on it for half a second of robot time.
    let t1 = robot.wait_telemetry(Some(t0.time_us + 500_000)).unwrap();
    stop.store(true, Ordering::Relaxed);
    let worst_duty = watcher.join().unwrap();
    let after = sim.truth().pose;
    eprintln!("garbage: {injected} bad frames/chunks injected, largest duty {worst_duty}");
    assert_eq!(worst_duty, 0.0, "the motors were driven");
    assert!(dist(&start, &after) < 1e-4, "moved: {start:?} -> {after:?}");
    assert!(t1.active.is_none() && t1.last_done.is_none(), "{t1:?}");
    assert!(t1.faults.is_empty(), "{t1:?}");

    // The link recovered: a real command is executed, once.
    let done = robot.move_distance(0.1, 0.1, false).unwrap();
    assert_eq!(done.outcome, Outcome::Completed);
    let moved = dist(&start, &sim.truth().pose);
    assert!((moved - 0.1).abs() < 0.01, "moved {moved} m");
}
