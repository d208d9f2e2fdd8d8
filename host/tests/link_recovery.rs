//! Recovery of a broken link, in process: after a cut the host opens
//! a new session, reads the robot's state, clears only the link's own fault and goes on; the
//! interrupted command's outcome is what the robot reports, or unknown — and a command lost in
//! the cut is never sent again. Faults that are not the link's are never cleared.
#![cfg(feature = "sim")]

use pushbot::experiments::link_bench::{LinkBenchOptions, run};
use pushbot::link::LinkError;
use pushbot::robot::{LinkOptions, Robot};
use pushbot::sim::inprocess::InProcess;
use pushbot_protocol::{Command, Faults, Outcome};
use pushbot_sim::faults::LinkFaults;
use pushbot_sim::{Pose, Sim, SimOptions};

const CLEAN: LinkFaults = LinkFaults::NONE;

fn robot(seed: u64) -> Robot<InProcess> {
    let sim = Sim::new(&SimOptions {
        seed,
        speed: 0.0,
        table: (6.0, 6.0),
        start: Pose::new(3.0, 3.0, 0.0),
        ..SimOptions::default()
    })
    .unwrap();
    let link = LinkOptions::default();
    let driver = InProcess::with_faults(sim, link.client_options(100), CLEAN, seed);
    Robot::over(driver, link).unwrap()
}

fn move_cmd(distance: f32) -> Command {
    Command::Move {
        distance,
        speed: 0.2,
        stop_on_contact: false,
    }
}

#[test]
fn a_cut_mid_move_is_recovered_and_its_outcome_read_back() {
    let mut robot = robot(3);
    let m = robot.start(move_cmd(0.5)).unwrap();
    robot.driver().run_for(0.5);
    robot.driver().cut_for(1_000_000);
    // The watchdog stops the robot; when the wire is back the end is read from the telemetry.
    let done = robot.wait(&m).unwrap();
    assert!(
        matches!(done.outcome, Outcome::Fault(f) if f.contains(Faults::LINK_LOST)),
        "{done:?}"
    );
    let seq_before = robot.last_seq();
    let rec = robot
        .recover("test cut", Some((m.seq, "Move")))
        .expect("recovered");
    let interrupted = rec.interrupted.expect("the move was interrupted");
    assert_eq!(interrupted.seq, m.seq);
    assert_eq!(interrupted.outcome.as_deref(), Some("fault (LINK_LOST)"));
    assert!(!rec.was_moving);
    // A new session: the robot holds no fault, moves again, and numbering went on.
    let t = robot.wait_telemetry(None).unwrap();
    assert_eq!(t.faults, Faults::NONE);
    let again = robot.move_distance(-0.2, 0.2, false).unwrap();
    assert_eq!(again.outcome, Outcome::Completed);
    assert!(
        again.seq.wrapping_sub(seq_before) < 100,
        "numbering goes on"
    );
    let starts = robot.driver().sim().starts_since_boot().clone();
    assert_eq!(starts.get(&m.seq), Some(&1), "{starts:?}");
    assert_eq!(starts.get(&again.seq), Some(&1), "{starts:?}");
    assert_eq!(robot.recoveries().len(), 1);
}

#[test]
fn a_command_lost_in_a_cut_is_unknown_and_never_sent_again() {
    let mut robot = robot(4);
    robot.driver().cut_for(2_000_000);
    let err = robot
        .start(move_cmd(0.3))
        .expect_err("no answer through the cut");
    assert!(matches!(err, LinkError::NoAnswer { .. }), "{err}");
    let lost = robot.last_seq();
    let rec = robot
        .recover(&err.to_string(), Some((lost, "Move")))
        .expect("recovered once the wire is back");
    assert_eq!(
        rec.interrupted.unwrap().outcome,
        None,
        "unknown, not guessed"
    );
    // The lost move never ran, and the new session does not send it again.
    robot.driver().run_for(2.0);
    let starts = robot.driver().sim().starts_since_boot().clone();
    assert!(!starts.contains_key(&lost), "{starts:?}");
    assert!(starts.is_empty(), "nothing moved: {starts:?}");
    let done = robot.move_distance(0.1, 0.2, false).unwrap();
    assert_eq!(done.outcome, Outcome::Completed);
    assert_ne!(done.seq, lost);
    let starts = robot.driver().sim().starts_since_boot().clone();
    assert_eq!(starts.len(), 1, "{starts:?}");
}

#[test]
fn a_cut_shorter_than_the_watchdog_finds_the_robot_moving_and_stops_it() {
    let mut robot = robot(5);
    // A long watchdog: the cut does not stop the robot by itself.
    robot
        .configure(pushbot_protocol::ConfigUpdate {
            watchdog_ms: Some(3000),
            ..Default::default()
        })
        .unwrap();
    let m = robot.start(move_cmd(1.0)).unwrap();
    robot.driver().run_for(0.3);
    robot.driver().cut_for(1_000_000);
    robot.driver().run_for(1.2);
    let rec = robot.recover("test cut", Some((m.seq, "Move"))).unwrap();
    assert!(rec.was_moving, "{rec:?}");
    assert_eq!(
        rec.interrupted.as_ref().unwrap().outcome.as_deref(),
        Some("aborted"),
        "the host's Stop ended it"
    );
    assert!(rec.cleared.is_empty(), "no fault latched: {rec:?}");
    let truth = robot.driver().sim().truth();
    assert!(truth.duty.iter().all(|&u| u == 0.0), "stopped: {truth:?}");
}

#[test]
fn recovery_never_clears_a_fault_that_is_not_the_links() {
    let mut robot = robot(6);
    robot.emergency_stop().unwrap();
    robot.driver().cut_for(500_000);
    robot.driver().run_for(1.0);
    let err = robot.recover("test cut", None).expect_err("refused");
    assert!(
        matches!(err, LinkError::RecoveryRefused { faults, .. } if faults.contains(Faults::EMERGENCY_STOP)),
        "{err}"
    );
    assert!(
        err.to_string().contains("pushbot robot clear-faults"),
        "{err}"
    );
    let t = robot.wait_telemetry(None).unwrap();
    assert!(t.faults.contains(Faults::EMERGENCY_STOP), "still latched");
    assert!(robot.recoveries().is_empty());
}

#[test]
fn the_link_bench_recovers_every_cut_and_runs_nothing_twice() {
    let r = run(&LinkBenchOptions {
        commands: 300,
        corrupt: 0.01,
        frame_loss: 0.05,
        cut_every_s: 5.0,
        cut_for_s: 1.0,
        seed: 9,
        ..LinkBenchOptions::default()
    })
    .unwrap();
    eprintln!("{r:?}");
    let cuts = (r.robot_time_s / 5.0).floor() as usize;
    assert!(cuts >= 5, "the run saw cuts: {r:?}");
    assert!(r.recoveries >= cuts / 2, "recovered: {r:?}");
    assert!(r.watchdog_trips >= 1, "{r:?}");
    assert_eq!(r.executed_twice, 0, "{r:?}");
    assert_eq!(r.unasked_motions, 0, "{r:?}");
    assert_eq!(r.sent, r.completed + r.refused + r.failed + r.unknown);
    assert!(r.completed_share() >= 0.9, "{r:?}");
}
