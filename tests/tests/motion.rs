//! HIL: motion primitives judged by ground truth — a square returns to its start, a drive into
//! the wall ends `Done(Contact)`.

use std::f64::consts::FRAC_PI_2;

use pushbot_protocol::Outcome;
use pushbot_tests::{angle_diff, connect, dist, sim_at};

#[test]
fn square_of_0_3_m_ends_within_1_cm_of_its_start() {
    let sim = sim_at(3, 0.45, 0.3, 0.0);
    let robot = connect(&sim);
    let start = sim.truth().pose;
    let mut corners = Vec::new();
    for k in 1..=4 {
        let done = robot.move_distance(0.3, 0.15, false).unwrap();
        assert_eq!(done.outcome, Outcome::Completed, "leg {k}");
        corners.push(sim.truth().pose);
        // Spin to the next side's heading by the odometry, so spin tolerances do not add up.
        let odom = robot.telemetry().unwrap().pose;
        let target = f64::from(k as u8) * FRAC_PI_2;
        let angle = angle_diff(target, f64::from(odom.theta));
        let done = robot.spin(angle as f32, 2.0).unwrap();
        assert_eq!(done.outcome, Outcome::Completed, "turn {k}");
    }
    let end = sim.truth().pose;
    // It did drive a square: the first corner is 0.3 m away, the opposite one 0.42 m.
    assert!(
        (dist(&corners[0], &start) - 0.3).abs() < 0.01,
        "{corners:?}"
    );
    assert!(
        (dist(&corners[1], &start) - 0.3 * 2f64.sqrt()).abs() < 0.015,
        "{corners:?}"
    );
    let miss = dist(&end, &start);
    eprintln!("square: ends {:.2} mm from its start", miss * 1e3);
    assert!(
        miss < 0.01,
        "ended {miss} m from the start: {start:?} -> {end:?}"
    );
}

#[test]
fn driving_into_the_wall_ends_with_contact() {
    // Facing +x from the table's centre: the wall is 0.6 m ahead of the axle.
    let sim = sim_at(4, 0.6, 0.45, 0.0);
    let robot = connect(&sim);
    let table_w = pushbot_sim::SimOptions::default().table.0;
    let bumper_r = f64::from(robot.hello().geometry.bumper_radius);
    let done = robot.move_distance(1.0, 0.15, true).unwrap();
    assert_eq!(done.outcome, Outcome::Contact);
    let truth = sim.truth();
    // Stopped at the wall, not through it, and well short of the 1 m asked for.
    let gap = table_w - truth.pose.x - bumper_r;
    assert!(gap.abs() < 0.01, "bumper {gap} m from the wall");
    assert!(f64::from(done.pose.x) < 0.7, "odometry {:?}", done.pose);
    let contacts = robot.contacts();
    assert!(!contacts.is_empty(), "a contact event was reported");
    assert_ne!(contacts[0].bumper, 0);
}
