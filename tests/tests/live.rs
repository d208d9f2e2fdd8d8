//! The host's closed loop against the simulated target exactly as against hardware: the real
//! serial link on the sim's pty and the real vision pipeline on the sim's camera socket
//! ([`pushbot::exec::LiveRobot`]), judged by the simulator's ground truth.

use pushbot::exec::io::RobotIo;
use pushbot::exec::{LiveOptions, LiveRobot};
use pushbot::sim::SimTarget;
use pushbot_sim::Scene;
use pushbot_tests::{SIM_SPEED, angle_diff};

fn target(scene: &Scene, seed: u64) -> SimTarget {
    SimTarget::start(scene, seed, SIM_SPEED, None, None).expect("start the simulated target")
}

/// Options for a target running [`SIM_SPEED`] times faster than real time: a one-second
/// watchdog in wall time.
fn options() -> LiveOptions {
    LiveOptions {
        watchdog_ms: (1000.0 * SIM_SPEED) as u16,
        ..LiveOptions::default()
    }
}

/// Camera pose against ground truth: within `mm` millimetres and `deg` degrees.
fn close(seen: pushbot::strategy::sample::Pose2, truth: pushbot_sim::Pose, mm: f64, deg: f64) {
    let d = (seen.x - truth.x).hypot(seen.y - truth.y) * 1e3;
    let a = angle_diff(seen.theta, truth.theta).abs().to_degrees();
    assert!(
        d <= mm && a <= deg,
        "camera says ({:.4}, {:.4}, {:.2}°), truth ({:.4}, {:.4}, {:.2}°): {d:.2} mm, {a:.2}°",
        seen.x,
        seen.y,
        seen.theta.to_degrees(),
        truth.x,
        truth.y,
        truth.theta.to_degrees()
    );
}

#[test]
fn primitives_and_poses_through_the_serial_port_and_the_camera() {
    let scene = Scene::preset("lau-irregular").expect("preset");
    let t = target(&scene, 3);
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    assert!(
        robot.calibration().rms_px < 0.5,
        "calibration RMS {:.3} px",
        robot.calibration().rms_px
    );
    let start = t.sim().truth().pose;
    close(robot.robot_pose(), start, 3.0, 1.0);

    robot.forward(0.2).expect("forward");
    let after = t.sim().truth().pose;
    assert!(
        ((after.x - start.x).hypot(after.y - start.y) - 0.2).abs() < 0.01,
        "drove {:.4} m, asked 0.2",
        (after.x - start.x).hypot(after.y - start.y)
    );
    close(robot.robot_pose(), after, 3.0, 1.0);

    robot.spin(std::f64::consts::FRAC_PI_2).expect("spin");
    let turned = t.sim().truth().pose;
    assert!(angle_diff(turned.theta, after.theta - std::f64::consts::FRAC_PI_2).abs() > 1.0);
    close(robot.robot_pose(), turned, 3.0, 1.0);

    // The object's body pose and its marker pose, as the scene places the marker.
    let truth = t.sim().objects()[0].1;
    let body = robot.body_pose("object").expect("object seen");
    close(body, truth, 3.0, 1.5);
    let m = scene.objects[0].marker.expect("marker");
    let marker = robot.object_pose();
    let (s, c) = truth.theta.sin_cos();
    let expect = pushbot_sim::Pose::new(
        truth.x + c * m.x - s * m.y,
        truth.y + s * m.x + c * m.y,
        truth.theta,
    );
    close(marker, expect, 3.0, 1.5);
    assert!(robot.time() > 1.0, "robot time {}", robot.time());
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

#[test]
fn a_push_moves_the_object_and_the_camera_sees_where() {
    let scene = Scene::preset("lau-irregular").expect("preset");
    let t = target(&scene, 4);
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    let before = t.sim().objects()[0].1;
    // Face the object's centre and drive through it.
    let r = robot.robot_pose();
    let o = robot.body_pose("object").expect("object seen");
    let heading = (o.y - r.y).atan2(o.x - r.x);
    robot.spin(heading - r.theta).expect("spin");
    let gap = (o.x - r.x).hypot(o.y - r.y);
    robot.forward(gap + 0.1).expect("push");
    let after = t.sim().objects()[0].1;
    let moved = (after.x - before.x).hypot(after.y - before.y);
    assert!(moved > 0.06, "the object moved only {moved:.4} m");
    close(
        robot.body_pose("object").expect("object seen"),
        after,
        3.0,
        1.5,
    );
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

#[test]
fn a_missing_camera_is_a_clear_error() {
    let scene = Scene::preset("empty").expect("preset");
    let t = target(&scene, 5);
    let err = LiveRobot::connect(t.port(), "sim:127.0.0.1:1", &scene, options())
        .expect_err("no camera there");
    let msg = format!("{err:#}");
    assert!(
        msg.contains("camera") && msg.contains("127.0.0.1:1"),
        "{msg}"
    );
}

#[test]
fn a_png_frame_of_the_lau_layout_shows_every_marker() {
    use pushbot::vision::detect::{DetectorKind, make_detector};
    use pushbot::vision::layout::MarkerLayout;
    use pushbot::vision::source::open_source;

    let scene = Scene::preset("lau-scissors").expect("preset");
    let dir = tempfile::tempdir().expect("temp dir");
    let t = SimTarget::start(&scene, 6, SIM_SPEED, Some(dir.path().to_path_buf()), None)
        .expect("start the simulated target");
    let png = dir.path().join("frame-000001.png");
    let end = std::time::Instant::now() + std::time::Duration::from_secs(30);
    while !png.exists() && std::time::Instant::now() < end {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    t.shutdown().expect("sim ran cleanly");
    // Keep only the first frame (complete: the second exists) and read it as a camera would.
    for e in std::fs::read_dir(dir.path()).expect("frames") {
        let p = e.expect("entry").path();
        if !p.ends_with("frame-000000.png") {
            std::fs::remove_file(p).expect("remove");
        }
    }
    let mut src = open_source(dir.path().to_str().expect("utf-8"), 30.0).expect("folder");
    let frame = src.next_frame().expect("read").expect("one frame");
    let layout = MarkerLayout::from_scene(&scene);
    let mut det = make_detector(DetectorKind::ApriltagC, &layout.families()).expect("detector");
    let mut found: Vec<u32> = det
        .detect(&frame)
        .expect("detect")
        .iter()
        .map(|d| d.id)
        .collect();
    found.sort_unstable();
    let mut expected: Vec<u32> = layout
        .calibration
        .iter()
        .map(|m| m.id)
        .chain(layout.bodies.iter().map(|b| b.id))
        .collect();
    expected.sort_unstable();
    assert_eq!(found, expected, "markers in the PNG frame");
}

/// Mission time (what a delivery's time limit counts): the robot's clock while a primitive
/// runs, the wall clock while the host works. On a target SIM_SPEED times faster than real
/// time, a second of host work costs one second, not SIM_SPEED.
#[test]
fn mission_time_counts_host_work_at_wall_clock_rate() {
    let scene = Scene::preset("empty").expect("preset");
    let t = target(&scene, 6);
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    let (m0, r0) = (robot.time(), robot.robot_clock());
    std::thread::sleep(std::time::Duration::from_secs(1));
    let (m1, r1) = (robot.time(), robot.robot_clock());
    assert!(
        (0.95..1.6).contains(&(m1 - m0)),
        "idle mission time {:.2} s",
        m1 - m0
    );
    assert!(
        r1 - r0 > 0.6 * SIM_SPEED,
        "idle robot time {:.2} s",
        r1 - r0
    );
    // While moving, mission time is robot time: 0.12 m at 0.12 m/s is a second or so.
    robot.forward(0.12).expect("forward");
    let (m2, r2) = (robot.time(), robot.robot_clock());
    let moving_robot = r2 - r1;
    let moving_mission = m2 - m1;
    assert!(
        moving_robot > 0.9,
        "the move took {moving_robot:.2} s of robot time"
    );
    assert!(
        moving_mission > 0.8 * moving_robot && moving_mission < moving_robot + 1.0,
        "mission {moving_mission:.2} s for {moving_robot:.2} s of robot time"
    );
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

/// The simulated camera sees the table through a webcam's lens (k1 = −0.08, f =
/// 700 px), given as the scene's intrinsics. The host, knowing the lens, places the robot near a
/// corner of the image within 2 mm; told nothing of it, the same frames put it ~10 mm off.
#[test]
fn a_distorting_lens_is_undistorted_with_the_scenes_intrinsics() {
    use pushbot_world::lens::{Distortion, Intrinsics};
    let mut scene = Scene::preset("empty").expect("preset");
    scene.camera.lens = Some(Intrinsics {
        width: scene.camera.width,
        height: scene.camera.height,
        fx: 700.0,
        fy: 700.0,
        cx: f64::from(scene.camera.width) / 2.0,
        cy: f64::from(scene.camera.height) / 2.0,
        distortion: Distortion {
            k1: -0.08,
            ..Distortion::NONE
        },
    });
    // Near a corner of the image, where the lens moves things most.
    scene.robot.start = pushbot_world::Pose::new(0.22, 0.2, 0.5);
    let t = target(&scene, 8);
    let truth = t.sim().truth().pose;
    let mut knowing = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    close(knowing.robot_pose(), truth, 2.0, 1.0);
    drop(knowing);
    let mut pinhole = scene.clone();
    pinhole.camera.lens = None;
    let mut naive = LiveRobot::connect(t.port(), t.camera(), &pinhole, options()).expect("connect");
    let seen = naive.robot_pose();
    let off = (seen.x - truth.x).hypot(seen.y - truth.y) * 1e3;
    assert!(off > 4.0, "without the lens the robot is {off:.2} mm off");
}

/// A square hand 30 cm above the table over the robot's start, shown from `from` to `until`
/// seconds of simulated time.
fn hand_over_start(scene: &Scene, from: f64, until: f64) -> Scene {
    let mut s = scene.clone();
    let p = s.robot.start;
    let h = 0.09;
    s.camera.occluders = vec![pushbot_world::scene::Occluder {
        outline: vec![
            [p.x - h, p.y - h],
            [p.x + h, p.y - h],
            [p.x + h, p.y + h],
            [p.x - h, p.y + h],
        ],
        z: 0.3,
        from,
        until,
    }];
    s
}

/// A hand over the robot when the executor looks: it waits, frame by frame, and goes on with
/// the robot's true pose once the hand is gone — not with a pose from before.
#[test]
fn an_occluded_robot_is_waited_for_then_seen_again() {
    let scene = hand_over_start(&Scene::preset("lau-irregular").expect("preset"), 0.0, 6.0);
    let t = target(&scene, 8);
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    let seen = robot.robot_pose();
    assert!(
        t.sim().truth().t >= 6.0,
        "the pose came before the hand went (sim time {:.2} s)",
        t.sim().truth().t
    );
    close(seen, t.sim().truth().pose, 3.0, 1.0);
    robot.forward(0.05).expect("moves on");
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

/// A hand that comes and stays: the robot is lost, and the task stops with that error before
/// the next primitive instead of acting on an old pose.
#[test]
fn a_robot_lost_for_good_stops_the_task() {
    let scene = hand_over_start(
        &Scene::preset("lau-irregular").expect("preset"),
        20.0,
        f64::INFINITY,
    );
    let t = target(&scene, 9);
    let opts = LiveOptions {
        reacquire_frames: 20,
        ..options()
    };
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, opts).expect("connect");
    let _ = robot.robot_pose();
    // Wait for the hand, then move a little under it and look.
    assert!(t.sim().truth().t < 20.0, "connecting took 4 s of wall time");
    while t.sim().truth().t < 20.2 {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    robot.forward(0.03).expect("moves under the hand");
    let _ = robot.robot_pose();
    let before = t.sim().truth().pose;
    let err = robot.forward(0.05).expect_err("the robot is lost");
    let msg = format!("{err:#}");
    assert!(msg.contains("robot is lost"), "{msg}");
    let now = t.sim().truth().pose;
    assert!(
        (now.x - before.x).hypot(now.y - before.y) < 1e-3,
        "the robot did not move"
    );
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

/// The robot against the wire cutter's jaws covers their marker (which overhangs them) with its
/// own: the live robot backs away, sees the object, comes back, and reports both poses from
/// after it (`exec::occlusion`), as the in-process robot does.
#[test]
fn a_robot_that_hides_the_object_backs_away_looks_and_comes_back() {
    let mut scene = Scene::preset("lau-wire-cutter").expect("preset");
    // A robot with its marker in its middle (the lau presets put it at the rear).
    scene.camera.robot_marker.x = 0.0;
    // The object lies along x: its jaws' marker is 3 cm ahead of its origin.
    let o = scene.objects[0].pose;
    assert_eq!(o.theta, 0.0);
    scene.robot.start = pushbot_sim::Pose::new(
        o.x + 0.03,
        o.y - 0.0135 - 0.04 - 0.0015,
        std::f64::consts::FRAC_PI_2,
    );
    let t = target(&scene, 10);
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    let start = t.sim().truth().pose;
    let seen = robot.object_pose();
    let (_, b) = t.sim().objects()[0].clone();
    let marker = pushbot_sim::Pose::new(
        b.x + 0.03 * b.theta.cos(),
        b.y + 0.03 * b.theta.sin(),
        b.theta,
    );
    close(seen, marker, 3.0, 1.5);
    let end = t.sim().truth().pose;
    assert!(
        (end.x - start.x).hypot(end.y - start.y) < 0.01,
        "the robot did not come back: {start:?} → {end:?}"
    );
    close(robot.robot_pose(), end, 3.0, 1.5);
    assert_eq!(
        robot.relooks(),
        1,
        "the object was seen without backing away"
    );
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

/// The whole pipeline through the serial port and the camera socket on a camera as it is: a
/// webcam lens, tilted 35° from straight down at the table's near edge, the robot's marker 6 cm
/// and the object's 3 cm above the table. Each primitive's end is seen within 3 mm and 1.5°.
#[test]
fn a_tilted_distorting_camera_with_raised_markers_sees_the_robot_move() {
    use pushbot_world::camera_pose::CameraPlacement;
    use pushbot_world::lens::{Distortion, Intrinsics};
    let mut scene = Scene::preset("lau-irregular").expect("preset");
    scene.camera.lens = Some(Intrinsics {
        distortion: Distortion {
            k1: -0.08,
            ..Distortion::NONE
        },
        ..Intrinsics::pinhole(960, 720, 700.0)
    });
    let (cx, cy) = (scene.table.width / 2.0, scene.table.height / 2.0);
    let (tilt, dist) = (35f64.to_radians(), 1.35);
    scene.camera.pose = Some(CameraPlacement {
        eye: [cx, cy - dist * tilt.sin(), dist * tilt.cos()],
        look_at: [cx, cy, 0.0],
    });
    let mut fid = scene
        .camera
        .fiducials_on(scene.table.width, scene.table.height);
    for m in &mut fid {
        m.size = 0.08;
    }
    scene.camera.fiducials = Some(fid);
    scene.camera.robot_marker.z = 0.06;
    if let Some(m) = scene.objects[0].marker.as_mut() {
        m.z = 0.03;
    }
    scene.robot.start = pushbot_world::Pose::new(0.5, 0.5, 0.3);
    let t = target(&scene, 10);
    let mut robot = LiveRobot::connect(t.port(), t.camera(), &scene, options()).expect("connect");
    close(robot.robot_pose(), t.sim().truth().pose, 3.0, 1.5);
    robot.forward(0.25).expect("forward");
    close(robot.robot_pose(), t.sim().truth().pose, 3.0, 1.5);
    robot.spin(2.5).expect("spin");
    close(robot.robot_pose(), t.sim().truth().pose, 3.0, 1.5);
    let object = robot.body_pose("object").expect("object seen");
    close(object, t.sim().objects()[0].1, 3.0, 1.5);
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}
