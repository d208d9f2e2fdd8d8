//! A port that disappears and comes back, over a real pty: the simulator keeps
//! a stable link path to its pty (as udev keeps `/dev/serial/by-id/…`), drops the pty and serves
//! a new one behind the same path. With a reconnect time the host waits for it, opens a new
//! session and goes on; without one it fails at once with an error that says what to do.

use std::time::Duration;

use pushbot::link::LinkError;
use pushbot::robot::{LinkOptions, Robot};
use pushbot_protocol::{Command, Faults, Outcome};
use pushbot_sim::{PtySim, SimOptions};
use pushbot_tests::SIM_SPEED;

fn linked_sim(seed: u64, link: &std::path::Path) -> PtySim {
    PtySim::start(SimOptions {
        seed,
        speed: SIM_SPEED,
        link: Some(link.to_path_buf()),
        ..SimOptions::default()
    })
    .expect("start the simulated robot")
}

fn connect(path: &std::path::Path, reconnect: Duration) -> Robot {
    let opts = LinkOptions {
        reconnect_timeout: reconnect,
        ..LinkOptions::default()
    };
    let robot = Robot::connect(path.to_str().expect("utf-8"), opts).expect("connect");
    // 1 s of robot time (200 ms of wall time at 5×): a loaded test machine does not trip it.
    robot
        .configure(pushbot_protocol::ConfigUpdate {
            watchdog_ms: Some(1000),
            ..Default::default()
        })
        .expect("configure");
    robot
}

/// Once the robot has gone 2 cm from where it is now, unplug the port for `gap` of robot time.
/// Waiting on the robot's own progress rather than on the wall clock keeps the unplug inside
/// the move however loaded the machine is (a 0.3 m move has 2.8 s of robot time left then).
fn unplug_once_moving(sim: &PtySim, gap: Duration) {
    let from = sim.truth().pose;
    pushbot_tests::wait_truth(sim, Duration::from_secs(60), |t| {
        pushbot_tests::dist(&t.pose, &from) >= 0.02
    })
    .expect("the move starts");
    sim.unplug(gap).expect("unplug");
}

/// Wait (up to 10 s of wall time) until the simulator has taken `n` unplugs: a request is
/// served at its next step, which may come after the host has already given up.
fn unplugs_reach(sim: &PtySim, n: u32) -> (u32, u32) {
    let end = std::time::Instant::now() + Duration::from_secs(10);
    while sim.unplugs().0 < n && std::time::Instant::now() < end {
        std::thread::sleep(Duration::from_millis(5));
    }
    sim.unplugs()
}

/// Start a long move, unplug the port for `gap` of robot time, and return the move's end.
fn unplug_during_a_move(sim: &PtySim, robot: &Robot, gap: Duration) -> (u16, LinkError) {
    let m = robot
        .start(Command::Move {
            distance: 0.3,
            speed: 0.1,
            stop_on_contact: false,
        })
        .expect("move accepted");
    unplug_once_moving(sim, gap);
    let err = robot
        .wait(&m)
        .expect_err("the port went away under the move");
    (m.seq, err)
}

#[test]
fn with_reconnect_the_host_waits_for_the_port_and_goes_on() {
    let dir = tempfile::tempdir().expect("tempdir");
    let link = dir.path().join("ttyPUSHBOT");
    let sim = linked_sim(31, &link);
    let mut robot = connect(&link, Duration::from_secs(20));
    let (seq, err) = unplug_during_a_move(&sim, &robot, Duration::from_secs(3));
    assert!(pushbot::robot::link_broke(&err), "{err}");
    let rec = robot
        .recover(&err.to_string(), Some((seq, "Move")))
        .expect("the port came back");
    assert!(rec.reopen_attempts > 1, "it had to wait: {rec:?}");
    let out = rec.interrupted.expect("interrupted").outcome;
    assert_eq!(
        out.as_deref(),
        Some("fault (LINK_LOST)"),
        "the watchdog ended it"
    );
    assert_eq!(sim.unplugs(), (1, 1));
    let done = robot.move_distance(-0.1, 0.1, false).expect("moves again");
    assert_eq!(done.outcome, Outcome::Completed);
    let t = robot.wait_telemetry(None).expect("telemetry");
    assert_eq!(t.faults, Faults::NONE);
    assert_eq!(robot.recoveries().len(), 1);
}

#[test]
fn without_reconnect_a_vanished_port_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let link = dir.path().join("ttyPUSHBOT");
    let sim = linked_sim(32, &link);
    let mut robot = connect(&link, Duration::ZERO);
    let (seq, err) = unplug_during_a_move(&sim, &robot, Duration::from_secs(30));
    let failed = robot
        .recover(&err.to_string(), Some((seq, "Move")))
        .expect_err("the port is away");
    assert!(matches!(failed, LinkError::Vanished { .. }), "{failed}");
    let msg = failed.to_string();
    assert!(msg.contains("--reconnect SECONDS"), "{msg}");
    assert!(msg.contains("ttyPUSHBOT"), "{msg}");
    assert!(robot.recoveries().is_empty());
}

/// The same through the command line: `pushbot robot move --reconnect 20` rides out the unplug
/// and completes the move (the rest sent anew); without `--reconnect` it fails and says why.
#[test]
fn the_cli_move_waits_for_the_port_with_reconnect_and_fails_clearly_without() {
    use clap::Parser;
    use pushbot::cli::{Cli, CliError, Status, run};
    for (seed, reconnect) in [(33, Some("20")), (34, None)] {
        let dir = tempfile::tempdir().expect("tempdir");
        let link = dir.path().join("ttyPUSHBOT");
        let sim = linked_sim(seed, &link);
        let start = sim.truth().pose;
        let port = link.to_str().expect("utf-8").to_string();
        let mut argv = vec!["pushbot", "--json"];
        if let Some(s) = reconnect {
            argv.extend(["--reconnect", s]);
        }
        argv.extend([
            "robot",
            "move",
            "--distance",
            "0.3",
            "--speed",
            "0.1",
            "--port",
            &port,
        ]);
        let cli = Cli::try_parse_from(&argv).expect("arguments parse");
        let result = std::thread::scope(|s| {
            // 2 cm into the move, the port goes for 2 s of robot time.
            s.spawn(|| unplug_once_moving(&sim, Duration::from_secs(2)));
            run(cli)
        });
        assert_eq!(unplugs_reach(&sim, 1).0, 1, "unplugged once");
        match reconnect {
            Some(_) => {
                assert!(matches!(result, Ok(Status::Success)), "{result:?}");
                let moved = pushbot_tests::dist(&sim.truth().pose, &start);
                assert!((moved - 0.3).abs() < 0.01, "moved {moved} m, not 0.3");
            }
            None => match result {
                Err(CliError::Failed(e)) => {
                    let msg = format!("{e:#}");
                    assert!(msg.contains("--reconnect"), "{msg}");
                }
                other => panic!("without --reconnect: {other:?}"),
            },
        }
    }
}
