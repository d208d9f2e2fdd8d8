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
    // About 2.5 min on a 2-core machine; a run that stops making progress fails instead of
    // holding up the suite.
    let _limit = pushbot_tests::WallLimit::arm(
        "collect_and_deliver_one_object_through_the_port_and_the_camera",
        std::time::Duration::from_secs(15 * 60),
    );
    let scene = Scene::preset("lau-irregular").expect("preset");
    let goal = scene.goals[0].pose;
    let t =
        SimTarget::start(&scene, 21, SIM_SPEED, None, None).expect("start the simulated target");
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
        "lau-irregular",
        "--method",
        "learned",
        "--initial",
        "120",
        "--streak",
        "0",
        "--trials",
        "1",
        "--time-limit",
        "480",
        "--watchdog-ms",
        &watchdog,
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("runs");
    // Ground truth: the object's marker (at the object's origin) within 2.2 cm of the goal.
    let o = t.sim().objects()[0].1;
    let d = (o.x - goal.x).hypot(o.y - goal.y);
    assert_eq!(st, Status::Success, "object ended {d:.3} m from the goal");
    assert!(d < 0.03, "object ended {d:.3} m from the goal");
    t.shutdown().expect("sim ran cleanly");
}
