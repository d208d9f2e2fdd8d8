//! HIL: Lau, Mitani & Igarashi's collection (Algorithm 1) and delivery (Algorithm 2) through
//! `pushbot eval delivery --hil`: the real serial link on the simulated target's pty and the
//! real vision pipeline on its camera socket, judged by the simulator's ground truth.

use clap::Parser;
use pushbot::cli::{Cli, Status, run};
use pushbot::sim::SimTarget;
use pushbot_sim::Scene;
use pushbot_tests::SIM_SPEED;

#[test]
fn collect_and_deliver_one_object_through_the_port_and_the_camera() {
    pushbot_tests::init_logging();
    // About 2 min on a 2-core machine; a run that stops making progress fails instead of
    // holding up the suite. 50 samples: what is tested here is collecting and delivering
    // through the port and the camera, as an operator does on a real robot (`pushbot collect`,
    // then `pushbot run deliver`); how good a strategy gets with how many samples is measured
    // in process (`strategy_sim`, `strategy_active`, `eval delivery --figure 7`).
    let _limit = pushbot_tests::WallLimit::arm(
        "collect_and_deliver_one_object_through_the_port_and_the_camera",
        std::time::Duration::from_secs(15 * 60),
    );
    let scene = Scene::preset("lau-irregular").expect("preset");
    let goal = scene.goals[0].pose;
    let t =
        SimTarget::start(&scene, 21, SIM_SPEED, None, None).expect("start the simulated target");
    let dir = tempfile::tempdir().expect("temp dir");
    let strategy = dir.path().join("object.strategy");
    let strategy = strategy.to_str().expect("utf-8 path");
    let collect_dir = dir.path().join("collect");
    let argv = [
        "pushbot",
        "--json",
        "collect",
        "--object",
        "object",
        "--scene",
        "lau-irregular",
        "--port",
        t.port(),
        "--camera",
        t.camera(),
        "--out",
        strategy,
        "--initial",
        "50",
        "--streak",
        "0",
        "--run-dir",
        collect_dir.to_str().expect("utf-8 path"),
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("collects");
    assert_eq!(st, Status::Success);
    assert!(
        std::path::Path::new(strategy).is_file(),
        "no strategy written"
    );
    let goal_arg = format!("{},{}", goal.x, goal.y);
    let deliver_dir = dir.path().join("deliver");
    let argv = [
        "pushbot",
        "--json",
        "run",
        "deliver",
        "--object",
        "object",
        "--scene",
        "lau-irregular",
        "--goal",
        &goal_arg,
        "--strategy",
        strategy,
        "--port",
        t.port(),
        "--camera",
        t.camera(),
        "--out",
        deliver_dir.to_str().expect("utf-8 path"),
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("runs");
    // Ground truth: the object's marker (at the object's origin) within 2.2 cm of the goal.
    let o = t.sim().objects()[0].1;
    let d = (o.x - goal.x).hypot(o.y - goal.y);
    assert_eq!(st, Status::Success, "object ended {d:.3} m from the goal");
    assert!(d < 0.03, "object ended {d:.3} m from the goal");
    for f in ["run.mcap", "report.html", "run.log", "summary.json"] {
        assert!(deliver_dir.join(f).is_file(), "the run's folder has no {f}");
    }
    t.shutdown().expect("sim ran cleanly");
}

/// The camera as it is: a webcam lens (k1 = −0.08, given as the scene's intrinsics
/// file), the robot's marker 6 cm and the object's 3 cm above the table. A strategy collected in
/// process delivers the object through the serial port and this camera from Lau et al.'s start C.
#[test]
fn a_delivery_through_a_distorting_lens_with_raised_markers_reaches_the_goal() {
    pushbot_tests::init_logging();
    let _limit = pushbot_tests::WallLimit::arm(
        "a_delivery_through_a_distorting_lens_with_raised_markers_reaches_the_goal",
        std::time::Duration::from_secs(10 * 60),
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let strategy = dir.path().join("irregular.strategy.json");
    let argv = [
        "pushbot",
        "--json",
        "collect",
        "--scene",
        "lau-irregular",
        "--object",
        "object",
        "--initial",
        "150",
        "--streak",
        "0",
        "--out",
        strategy.to_str().expect("utf-8 path"),
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("collects");
    assert_eq!(st, Status::Success);

    // The lens as a ROS camera_info file beside the scene, the heights in the scene.
    std::fs::write(
        dir.path().join("webcam.yaml"),
        "image_width: 960\nimage_height: 720\ncamera_name: webcam\ncamera_matrix:\n  rows: 3\n  \
         cols: 3\n  data: [700.0, 0.0, 479.5, 0.0, 700.0, 359.5, 0.0, 0.0, 1.0]\n\
         distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  \
         data: [-0.08, 0.0, 0.0, 0.0, 0.0]\n",
    )
    .expect("write the lens");
    let text = pushbot_world::presets::text("lau-irregular")
        .expect("preset")
        .replace(
            "pose = { x = 0.45, y = 0.95, theta = 0.0 }\nmass",
            "pose = { x = 0.45, y = 0.25, theta = 3.1416 }\nmass",
        )
        .replace(
            "marker = { id = 1, x = 0, y = 0, size = 0.05 }",
            "marker = { id = 1, x = 0, y = 0, size = 0.05, z = 0.03 }",
        )
        .replace("[camera]\n", "[camera]\nintrinsics = \"webcam.yaml\"\n")
        .replace(
            "robot_marker = { id = 0, x = -0.03, y = 0.0, size = 0.05 }",
            "robot_marker = { id = 0, x = -0.03, y = 0.0, size = 0.05, z = 0.06 }",
        );
    let path = dir.path().join("irregular-real.toml");
    std::fs::write(&path, text).expect("write the scene");
    let scene = Scene::load(&path).expect("the scene loads");
    assert!(
        scene.camera.lens.is_some(),
        "the lens is read with the scene"
    );
    assert_eq!(
        scene.objects[0].marker.map(|m| m.z),
        Some(0.03),
        "the object's marker is raised"
    );
    assert_eq!(
        scene.camera.robot_marker.z, 0.06,
        "the robot's marker is raised"
    );
    assert!((scene.objects[0].pose.y - 0.25).abs() < 1e-9, "start C");
    let goal = scene.goals[0].pose;
    let t =
        SimTarget::start(&scene, 22, SIM_SPEED, None, None).expect("start the simulated target");
    let watchdog = ((1000.0 * SIM_SPEED) as u16).to_string();
    let argv = [
        "pushbot",
        "--json",
        "eval",
        "delivery",
        "--hil",
        "--port",
        t.port(),
        "--camera",
        t.camera(),
        "--scene",
        path.to_str().expect("utf-8 path"),
        "--method",
        "learned",
        "--strategy",
        strategy.to_str().expect("utf-8 path"),
        "--trials",
        "1",
        "--time-limit",
        "480",
        "--watchdog-ms",
        &watchdog,
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("runs");
    let o = t.sim().objects()[0].1;
    let d = (o.x - goal.x).hypot(o.y - goal.y);
    assert_eq!(st, Status::Success, "object ended {d:.3} m from the goal");
    assert!(d < 0.03, "object ended {d:.3} m from the goal");
    t.shutdown().expect("sim ran cleanly");
}
