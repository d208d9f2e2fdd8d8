//! HIL: heartbeats paced by robot time keep an accelerated robot driving; when the host goes
//! silent the robot's watchdog stops the motors within 250 ms of simulated time; a reconnect
//! clears the latched `LINK_LOST`.

use std::time::Duration;

use pushbot::link::LinkError;
use pushbot_protocol::{Faults, NackReason, Outcome};
use pushbot_tests::{connect_strict, sim_at, wait_truth};

#[test]
fn motors_stop_within_250_ms_after_the_host_goes_silent() {
    let sim = sim_at(5, 0.3, 0.45, 0.0);
    let mut robot = connect_strict(&sim);
    let motion = robot.velocity(0.05, 0.0, Duration::from_secs(20)).unwrap();
    let moving = wait_truth(&sim, Duration::from_secs(5), |t| t.duty[0].abs() > 0.05)
        .expect("the robot starts driving");
    // With heartbeats, 1.5 s of robot time at 10x pass without the watchdog firing.
    let t_alive = moving.t + 1.5;
    let alive = wait_truth(&sim, Duration::from_secs(10), |t| {
        t.t >= t_alive || !t.faults.is_empty() || t.duty == [0.0; 2]
    })
    .unwrap();
    assert!(alive.t >= t_alive, "stopped early: {alive:?}");
    assert!(alive.faults.is_empty(), "{alive:?}");

    robot.pause_heartbeats(true);
    let silent_at = sim.truth().t;
    let stopped =
        wait_truth(&sim, Duration::from_secs(5), |t| t.duty == [0.0; 2]).expect("the motors stop");
    let after = stopped.t - silent_at;
    eprintln!(
        "watchdog: motors off {:.1} ms of sim time after the host went silent",
        after * 1e3
    );
    assert!(
        after <= 0.25,
        "motors ran {after} s after the host went silent"
    );
    assert!(stopped.faults.contains(Faults::LINK_LOST), "{stopped:?}");
    let done = robot.wait(&motion).unwrap();
    assert_eq!(done.outcome, Outcome::Fault(Faults::LINK_LOST));

    // Talking again is not enough: motion is refused until a new handshake…
    robot.pause_heartbeats(false);
    let err = robot.move_distance(0.05, 0.1, false).unwrap_err();
    assert!(
        matches!(err, LinkError::Refused { reason, .. } if reason.0 == NackReason::Faulted(Faults::LINK_LOST)),
        "{err}"
    );
    assert!(err.to_string().contains("LINK_LOST"), "{err}");
    // …which reconnect performs, clearing LINK_LOST.
    robot.reconnect().unwrap();
    let done = robot.move_distance(0.05, 0.1, false).unwrap();
    assert_eq!(done.outcome, Outcome::Completed);
}

#[test]
fn vanished_port_is_a_clean_error() {
    let sim = sim_at(6, 0.6, 0.45, 0.0);
    let path = sim.serial_path().to_string();
    let robot = connect_strict(&sim);
    robot.wait_telemetry(None).unwrap();
    sim.shutdown().unwrap();
    let err = robot.wait_telemetry(Some(u64::MAX - 1)).unwrap_err();
    assert!(matches!(err, LinkError::Disconnected { .. }), "{err}");
    assert!(err.to_string().contains(&path), "{err}");
    let err = robot.move_distance(0.1, 0.1, false).unwrap_err();
    assert!(matches!(err, LinkError::Disconnected { .. }), "{err}");
}
