//! Ben-Shahar & Rivlin's test case A1 executed end to end as on hardware: the grid plan's
//! primitives go over the real serial link to the simulated target's pty, and the executor
//! observes the boxes through the real vision pipeline on the sim's camera
//! ([`pushbot::exec::LiveRobot`]); the simulator's ground truth judges where the boxes ended.

use pushbot::exec::rearrange::{ExecOptions, ExecReport, execute, execute_practical};
use pushbot::exec::{LiveOptions, LiveRobot};
use pushbot::planner::rearrange::costmap::CostMap;
use pushbot::planner::rearrange::frame::GridFrame;
use pushbot::planner::rearrange::practical::Options;
use pushbot::planner::rearrange::to_scene::{SceneOptions, scene_for};
use pushbot::planner::rearrange::{Model, Problem, cases::load_scene, cost_map};
use pushbot::sim::SimTarget;
use pushbot_tests::SIM_SPEED;
use pushbot_world::Scene;

/// Case A1: the problem, its model and cost map, the grid's scene options and its scene.
fn case_a1() -> (Problem, Model, CostMap, SceneOptions, Scene) {
    let p = load_scene("A1").expect("preset");
    let model = Model::new(&p).expect("model");
    let map = cost_map(&model).expect("map");
    let so = SceneOptions::default();
    let scene = scene_for(&p, &so).expect("scene");
    (p, model, map, so, scene)
}

/// The executor's robot for a target at [`SIM_SPEED`]: a one-second watchdog in wall time.
fn live_options() -> LiveOptions {
    LiveOptions {
        watchdog_ms: (1000.0 * SIM_SPEED) as u16,
        boundary_inset: 0.0,
        ..LiveOptions::default()
    }
}

/// Ground truth: every box inside its goal cell.
fn boxes_home(p: &Problem, so: &SceneOptions, t: &SimTarget) {
    let frame = GridFrame {
        cell: so.cell,
        h: p.grid.h,
    };
    let truth = t.sim().objects();
    for (m, g) in p.movables.iter().zip(&p.goal_movables) {
        let g = g.expect("A1 gives every box a goal");
        let (_, pose) = truth
            .iter()
            .find(|(id, _)| *id == m.name)
            .expect("box in the sim");
        let want = frame.centre(g.x, g.y);
        let (dx, dy) = (pose.x - want.x, pose.y - want.y);
        assert!(
            dx.abs().max(dy.abs()) < 0.5 * so.cell,
            "box `{}` at ({:.3}, {:.3}), goal cell centre ({:.3}, {:.3})",
            m.name,
            pose.x,
            pose.y,
            want.x,
            want.y
        );
    }
}

#[test]
fn case_a1_is_executed_over_the_serial_port_with_camera_feedback() {
    pushbot_tests::init_logging();
    // About 20 s; a run that stops making progress fails instead of holding up the suite.
    let _limit = pushbot_tests::WallLimit::arm(
        "case_a1_is_executed_over_the_serial_port_with_camera_feedback",
        std::time::Duration::from_secs(10 * 60),
    );
    let (p, model, map, so, scene) = case_a1();
    let t =
        SimTarget::start(&scene, 11, SIM_SPEED, None, None).expect("start the simulated target");
    let mut robot =
        LiveRobot::connect(t.port(), t.camera(), &scene, live_options()).expect("connect");
    let report = execute(&model, &map, &mut robot, &ExecOptions::default()).expect("execute");
    eprintln!("{report:?}");
    assert!(report.reached, "{report:?}");
    assert!(report.pushes > 0);
    boxes_home(&p, &so, &t);
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
}

/// A box moved by hand mid-run (the simulator's disturbance: box `b` put down 10 cm off its
/// row): the executor sees it off the cell the plan had put it in, re-plans from where it is,
/// says so in its report, and still brings both boxes home. Returns the report.
fn disturbed_a1(
    test: &str,
    seed: u64,
    run: impl FnOnce(&Problem, &Model, &CostMap, &mut LiveRobot) -> ExecReport,
) -> ExecReport {
    use pushbot::sim::target::Disturbance;
    pushbot_tests::init_logging();
    let _limit = pushbot_tests::WallLimit::arm(test, std::time::Duration::from_secs(10 * 60));
    let (p, model, map, so, scene) = case_a1();
    let disturb: Disturbance = "25:b:0:0.1".parse().expect("a disturbance");
    let t = SimTarget::start_with(&scene, seed, SIM_SPEED, None, None, vec![disturb])
        .expect("start the simulated target");
    let mut robot =
        LiveRobot::connect(t.port(), t.camera(), &scene, live_options()).expect("connect");
    assert!(t.sim().truth().t < 25.0, "connecting took 5 s of wall time");
    let report = run(&p, &model, &map, &mut robot);
    eprintln!("{report:?}");
    assert!(report.reached, "{report:?}");
    assert!(
        t.sim().truth().t > 25.0,
        "the run ended before the hand came"
    );
    let moved_b = report.replans.iter().find(|r| {
        r.moved
            .iter()
            .any(|m| m.name == "b" && m.expected.1 != m.observed.1)
    });
    assert!(
        moved_b.is_some(),
        "no re-plan saw box b off its row: {:?}",
        report.replans
    );
    boxes_home(&p, &so, &t);
    drop(robot);
    t.shutdown().expect("sim ran cleanly");
    report
}

/// The exact mode re-plans by a lookup in the same cost map.
#[test]
fn a_box_moved_by_hand_mid_run_is_replanned_from_where_it_is() {
    let report = disturbed_a1(
        "a_box_moved_by_hand_mid_run_is_replanned_from_where_it_is",
        12,
        |_, model, map, robot| {
            execute(model, map, robot, &ExecOptions::default()).expect("execute")
        },
    );
    assert_eq!(report.mode, "exact");
}

/// The practical mode (no cost map) follows its plan while the camera agrees, and plans again
/// from the observation when box `b` is not where the plan had put it.
#[test]
fn the_practical_mode_replans_a_box_moved_by_hand() {
    let report = disturbed_a1(
        "the_practical_mode_replans_a_box_moved_by_hand",
        12,
        |p, _, _, robot| {
            let opts = Options::for_problem(p);
            execute_practical(p, opts, robot, &ExecOptions::default()).expect("execute")
        },
    );
    assert_eq!(report.mode, "practical");
    // Plans made: the first, and one per observation that was not where the plan had put things.
    assert!(report.plans >= 2, "{report:?}");
}
