//! HIL with link faults: the real host link against the simulated robot whose serial line
//! drops, corrupts and delays bytes and is cut now and then (`pushbot_sim::faults`). The
//! handshake completes, a square of moves ends where it should, and the link's statistics show
//! the frames it rejected and the commands it had to send again.

use std::f64::consts::FRAC_PI_2;
use std::time::Duration;

use pushbot::robot::{LinkOptions, Robot};
use pushbot_protocol::Outcome;
use pushbot_sim::faults::LinkFaults;
use pushbot_sim::{Pose, PtySim, SimOptions};
use pushbot_tests::{SIM_SPEED, angle_diff, dist, wait_truth};

/// Faults far worse than the `--faults` profile, with cuts shorter than the robot's link
/// watchdog (set to 3 s of robot time below), so that a healthy host keeps the robot going.
const FAULTS: LinkFaults = LinkFaults {
    drop: 0.005,
    corrupt: 0.005,
    garbage: 0.0,
    frame_loss: 0.0,
    duplicate: 0.0,
    max_delay_us: 5_000,
    cut_every_us: 2_000_000,
    cut_for_us: 150_000,
};

#[test]
fn moves_complete_despite_drops_corruption_and_cuts() {
    let sim = PtySim::start(SimOptions {
        seed: 11,
        speed: SIM_SPEED,
        start: Pose::new(0.45, 0.3, 0.0),
        faults: Some(FAULTS),
        ..SimOptions::default()
    })
    .expect("start the simulated robot");
    // Generous attempts: losing a command and its answers is the point here.
    let opts = LinkOptions {
        attempts: 12,
        hello_timeout: Duration::from_secs(10),
        ..LinkOptions::default()
    };
    let robot = Robot::connect(sim.serial_path(), opts).expect("handshake through a faulty link");
    // A generous link watchdog (3 s of robot time, 600 ms of wall time): at five times real
    // time on a loaded machine, lost heartbeats plus a cut plus a host thread waiting for a
    // core must not stop the robot (with 1 s, a run beside a 50-trial evaluation once ended a
    // move with LINK_LOST); the cuts (150 ms) stay far shorter. The watchdog's own behaviour
    // has its own test (`watchdog.rs`), and this file's CLI test runs the firmware's 200 ms.
    robot
        .configure(pushbot_protocol::ConfigUpdate {
            watchdog_ms: Some(3000),
            ..Default::default()
        })
        .expect("configure through a faulty link");

    // A square of 0.2 m sides; each turn by the odometry, like the clean HIL square.
    let start = sim.truth().pose;
    let mut corners = Vec::new();
    for k in 1..=4 {
        let done = robot.move_distance(0.2, 0.15, false).expect("move");
        assert_eq!(done.outcome, Outcome::Completed, "leg {k}: {done:?}");
        corners.push(sim.truth().pose);
        let odom = robot.telemetry().expect("telemetry").pose;
        let target = f64::from(k as u8) * FRAC_PI_2;
        let done = robot
            .spin(angle_diff(target, f64::from(odom.theta)) as f32, 2.0)
            .expect("spin");
        assert_eq!(done.outcome, Outcome::Completed, "turn {k}: {done:?}");
    }
    assert!(
        (dist(&corners[0], &start) - 0.2).abs() < 0.01,
        "{corners:?}"
    );
    let miss = dist(&sim.truth().pose, &start);
    assert!(miss < 0.015, "ended {miss} m from the start");

    // Ask for something while the link is cut: the request or its answer is lost and the
    // host must send it again.
    let cut_start = wait_truth(&sim, Duration::from_secs(10), |t| {
        let us = (t.t * 1e6) as u64;
        FAULTS.cut(us) && us % FAULTS.cut_every_us < FAULTS.cut_every_us - FAULTS.cut_for_us / 2
    });
    assert!(cut_start.is_some(), "no cut seen");
    let before = robot.stats().retries;
    robot.clear_faults().expect("answered after the cut");
    let stats = robot.stats();
    eprintln!("faulty link: {stats:?}");
    assert!(stats.retries > before, "resent during the cut: {stats:?}");
    assert!(
        stats.frames_rejected > 0,
        "corrupted frames rejected: {stats:?}"
    );
    assert!(stats.frames_ok > 100, "{stats:?}");
}

/// `pushbot-sim --faults --fault-drop 0.01 --fault-corrupt 0.01` — the `--faults`
/// profile's 20 ms delays and 300 ms cut every 10 s included — and 30 `pushbot robot move` in a
/// row, each its own session: all 30 complete. A cut longer than the robot's 200 ms watchdog
/// stops a move; the host recovers the link and sends the rest of the move anew.
#[test]
fn thirty_cli_moves_complete_on_a_one_percent_wire() {
    use clap::Parser;
    use pushbot::cli::{Cli, Status, run};
    let faults = LinkFaults {
        drop: 0.01,
        corrupt: 0.01,
        ..LinkFaults::default()
    };
    let sim = PtySim::start(SimOptions {
        seed: 12,
        // Twice real time: the firmware's own 200 ms watchdog is 100 ms of wall time here.
        speed: 2.0,
        start: Pose::new(0.6, 0.45, 0.0),
        faults: Some(faults),
        ..SimOptions::default()
    })
    .expect("start the simulated robot");
    let port = sim.serial_path().to_string();
    let start = sim.truth().pose;
    for i in 0..30 {
        let d = if i % 2 == 0 { "0.05" } else { "-0.05" };
        let argv = [
            "pushbot",
            "--json",
            "robot",
            "move",
            "--distance",
            d,
            "--port",
            &port,
        ];
        let st = run(Cli::try_parse_from(argv).expect("arguments parse"));
        assert!(matches!(st, Ok(Status::Success)), "move {i}: {st:?}");
    }
    // Back and forth, each move done exactly once: the robot is back where it started.
    let miss = dist(&sim.truth().pose, &start);
    assert!(miss < 0.02, "ended {miss} m from the start");
}
