//! The robot hides a marker from the overhead camera (`exec::occlusion`): with the rendered
//! camera in the loop, a robot standing against Lau et al.'s wire cutter covers the jaws'
//! marker, which overhangs their 2.6 cm with its own robot marker. Before the object counts
//! as lost the robot backs away, looks, and comes back (not after it only turned on the spot,
//! which cannot move the object); a body that stays unseen is lost, every
//! motion after fails with [`BodyLost`], and an evaluation counts the trial as failed
//! (`marker-lost`) instead of stopping.

use std::f64::consts::FRAC_PI_2;

use pushbot::exec::deliver::DeliveryParams;
use pushbot::exec::io::RobotIo;
use pushbot::exec::occlusion::{BACK_OFF, is_lost};
use pushbot::experiments::strategy_eval::{Method, TrialSetup, run_start};
use pushbot::sim::robot::{SimCamera, SimRobot, SimRobotOptions};
use pushbot::strategy::regression::KernelParams;
use pushbot_world::Scene;
use pushbot_world::scene::Occluder;

fn rendered() -> SimRobotOptions {
    SimRobotOptions {
        camera: SimCamera::Rendered,
        ..SimRobotOptions::default()
    }
}

/// The wire cutter at start A (its jaws' marker at (0.48, 0.95)) and the robot against the
/// jaws from below, facing them: the two markers' centres 5.5 cm apart.
fn robot_against_the_jaws() -> Scene {
    let mut scene = Scene::preset("lau-wire-cutter").unwrap();
    // A robot with its marker in its middle (the lau presets put it at the rear, where it
    // hides this marker only from other poses).
    scene.camera.robot_marker.x = 0.0;
    scene.robot.start = pushbot_world::Pose::new(0.48, 0.95 - 0.0135 - 0.04 - 0.0015, FRAC_PI_2);
    scene
}

#[test]
fn a_robot_that_hides_the_object_backs_away_looks_and_comes_back() {
    let scene = robot_against_the_jaws();
    // The premise: from where the robot stands the camera cannot see the jaws' marker.
    let mut r = SimRobot::new(scene.clone(), None, None, rendered()).unwrap();
    let start = r.true_robot_pose();
    let robot = r.robot_pose();
    assert!(
        (robot.position() - start.position()).norm() < 0.01,
        "{robot:?}"
    );
    let object = r.object_pose();
    let truth = r.true_object_pose();
    assert_eq!(r.relooks(), 1, "the object was seen without backing away");
    assert!(
        (object.position() - truth.position()).norm() < 0.005,
        "seen {object:?}, truly {truth:?}"
    );
    // Back where it stood, and the pose reported is from after coming back.
    let end = r.true_robot_pose();
    assert!(
        (end.position() - start.position()).norm() < 0.01,
        "the robot did not come back: {start:?} → {end:?}"
    );
    let seen = r.robot_pose();
    assert!(
        (seen.position() - end.position()).norm() < 0.005,
        "{seen:?} vs {end:?}"
    );
    // It went BACK_OFF away and back: 2 × BACK_OFF of driving, at the robot's speed.
    assert!(r.time() > 2.0 * BACK_OFF / SimRobotOptions::default().speed);
    // Turning on the spot presses on nothing: the object, hidden again, did not move, and the
    // robot does not move to look for it (its last pose stands).
    let before = r.true_object_pose();
    r.spin(0.5).unwrap();
    let kept = r.object_pose();
    assert_eq!(r.relooks(), 1, "the robot moved to look after only turning");
    assert_eq!(kept, object, "the object's pose was measured again");
    assert!((r.true_object_pose().position() - before.position()).norm() < 1e-3);
    assert!((r.true_robot_pose().position() - end.position()).norm() < 0.005);
    // The next look needs no backing away when the robot stands off the object.
    r.forward(-0.1).unwrap();
    r.object_pose();
    assert_eq!(r.relooks(), 1);
}

/// The same scene with a hand held over the object, for ever.
fn object_under_a_hand() -> Scene {
    let mut scene = robot_against_the_jaws();
    scene.robot.start = pushbot_world::Pose::new(0.2, 0.6, 0.0);
    scene.camera.occluders = vec![Occluder {
        outline: vec![[0.36, 0.86], [0.6, 0.86], [0.6, 1.04], [0.36, 1.04]],
        z: 0.3,
        from: 0.0,
        until: f64::INFINITY,
    }];
    scene
}

#[test]
fn a_body_that_stays_unseen_is_lost_and_every_motion_after_fails() {
    let mut r = SimRobot::new(object_under_a_hand(), None, None, rendered()).unwrap();
    r.object_pose();
    assert_eq!(r.relooks(), 0);
    let e = r
        .forward(0.05)
        .expect_err("a motion after the object was lost");
    assert!(is_lost(&e), "{e:#}");
    assert!(format!("{e:#}").contains("object is lost"), "{e:#}");
    let e = r.spin(0.3).expect_err("and the next one");
    assert!(is_lost(&e), "{e:#}");
}

#[test]
fn an_evaluation_counts_a_lost_object_as_a_failed_trial_and_goes_on() {
    let setup = TrialSetup {
        scene: object_under_a_hand(),
        object: None,
        sim: rendered(),
        delivery: DeliveryParams::default(),
        kernel: KernelParams::default(),
    };
    let (res, runs) = run_start(&setup, Method::Dipole, &[], "A", 2).unwrap();
    assert_eq!((res.trials, res.successes), (2, 0));
    assert_eq!(
        res.failures.get("marker-lost"),
        Some(&2),
        "{:?}",
        res.failures
    );
    assert!(runs.iter().all(|d| !d.success && d.final_distance > 0.5));
}
