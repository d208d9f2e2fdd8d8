//! HIL: the `pushbot robot …` command line against a simulated robot on a pty given with
//! `--port`, judged by ground truth, and its exit-code classes.

use clap::Parser;
use pushbot::cli::{Cli, CliError, Status, run};
use pushbot_tests::{dist, sim_at};

fn cli(args: &[&str]) -> Result<Status, CliError> {
    let mut argv = vec!["pushbot"];
    argv.extend_from_slice(args);
    run(Cli::try_parse_from(argv).expect("arguments parse"))
}

#[test]
fn robot_move_and_spin_over_a_given_port() {
    let sim = sim_at(11, 0.4, 0.45, 0.0);
    let port = sim.serial_path().to_string();
    let start = sim.truth().pose;
    let st = cli(&["robot", "move", "--distance", "0.2", "--port", &port]).unwrap();
    assert_eq!(st, Status::Success);
    let moved = dist(&start, &sim.truth().pose);
    assert!((moved - 0.2).abs() < 0.01, "moved {moved} m");
    // Negative angles parse; degrees on the command line.
    let before = sim.truth().pose.theta;
    let st = cli(&["--json", "robot", "spin", "--angle", "-45", "--port", &port]).unwrap();
    assert_eq!(st, Status::Success);
    let turned = pushbot_tests::angle_diff(sim.truth().pose.theta, before).to_degrees();
    assert!((turned + 45.0).abs() < 3.0, "turned {turned}°");
    let st = cli(&["robot", "estop", "--port", &port]).unwrap();
    assert_eq!(st, Status::Success);
    // Faulted: motion refused (exit 1), clear-faults releases it.
    let err = cli(&["robot", "move", "--distance", "0.1", "--port", &port]).unwrap_err();
    assert!(matches!(err, CliError::Failed(_)), "{err}");
    assert!(err.to_string().contains("EMERGENCY_STOP"), "{err}");
    assert_eq!(
        cli(&["robot", "clear-faults", "--port", &port]).unwrap(),
        Status::Success
    );
    assert_eq!(
        cli(&["robot", "move", "--distance", "0.05", "--port", &port]).unwrap(),
        Status::Success
    );
}

#[test]
fn bad_ports_and_values_are_bad_input() {
    for port in ["/nonexistent/ttyX", "/dev/null"] {
        let err = cli(&["robot", "info", "--port", port]).unwrap_err();
        assert!(matches!(err, CliError::BadInput(_)), "{port}: {err}");
        assert!(err.to_string().contains(port), "{err}");
    }
    let err = cli(&["robot", "move", "--distance", "inf"]).unwrap_err();
    assert!(matches!(err, CliError::BadInput(_)), "{err}");
    // Beyond the robot's limits: refused by the (built-in simulated) robot, still bad input.
    let err = cli(&["robot", "move", "--distance", "0.1", "--speed", "5"]).unwrap_err();
    assert!(matches!(err, CliError::BadInput(_)), "{err}");
}
