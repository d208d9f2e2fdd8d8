//! HIL: the handshake against the simulated robot, and a protocol-version mismatch refused.

use pushbot::link::LinkError;
use pushbot::robot::{LinkOptions, Robot};
use pushbot_protocol::{Faults, Mode, PROTOCOL_VERSION};
use pushbot_tests::{connect, sim_at};

#[test]
fn handshake_opens_a_session_with_telemetry() {
    let sim = sim_at(1, 0.6, 0.45, 0.0);
    let robot = connect(&sim);
    let h = *robot.hello();
    assert!(h.accepted);
    assert_eq!(h.protocol, PROTOCOL_VERSION);
    // The geometry is the simulated robot's firmware's.
    let reference = pushbot_firmware::RobotParams::default().geometry;
    assert_eq!(h.geometry, reference);
    // Telemetry flows, robot time advances, the robot stands idle at its odometry origin.
    let info = robot.info().unwrap();
    let later = robot
        .wait_telemetry(Some(info.telemetry.time_us + 200_000))
        .unwrap();
    assert!(later.time_us > info.telemetry.time_us + 200_000);
    assert_eq!(later.mode, Mode::Idle);
    assert_eq!(later.faults, Faults::NONE);
    assert!(later.pose.x.abs() < 1e-3 && later.pose.y.abs() < 1e-3);
    // Robot time in the telemetry is the simulator's clock.
    let truth_t = sim.truth().t;
    assert!(
        (truth_t - later.time_us as f64 / 1e6).abs() < 0.5,
        "{truth_t}"
    );
}

#[test]
fn protocol_version_mismatch_is_refused() {
    let sim = sim_at(2, 0.6, 0.45, 0.0);
    let offered = PROTOCOL_VERSION + 7;
    let err = Robot::connect(
        sim.serial_path(),
        LinkOptions {
            protocol_version_override: Some(offered),
            ..LinkOptions::default()
        },
    )
    .err()
    .expect("a mismatched version must be refused");
    let msg = err.to_string();
    assert!(
        matches!(err, LinkError::VersionMismatch { host, robot, .. } if host == offered && robot == PROTOCOL_VERSION),
        "{msg}"
    );
    assert!(msg.contains(&format!("v{offered}")), "{msg}");
    assert!(msg.contains(&format!("v{PROTOCOL_VERSION}")), "{msg}");
    assert!(msg.contains(sim.serial_path()), "{msg}");
    // The robot opened no session for it (no telemetry went out), and the right version still
    // gets in afterwards.
    let robot = connect(&sim);
    assert!(robot.hello().accepted);
    robot.wait_telemetry(None).unwrap();
}
