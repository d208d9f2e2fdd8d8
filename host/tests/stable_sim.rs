//! Validation of stable pushing in the simulated world (Lynch & Mason 1996
//! §4): a plan for the differential-drive robot with a flat front plate is executed open loop on
//! the simulated robot, through the firmware protocol in process (`SimRobot`, `Velocity` arcs),
//! and the slider must stay fixed to the plate during every stable push (drift < 1 mm per
//! 100 mm pushed and < 1°) and end in the goal neighbourhood. This checks the planner's STABLE
//! against the sim's quasi-static physics (ellipsoidal limit surface, Coulomb line contact).
//!
//! The preset's pusher is replaced by the sim robot (a differential drive with its plate). The
//! first checks use edge 0 only; the last lets the robot change contact between two edges: at
//! each change it drives the plan's transit path around the slider (§4.6's open problem;
//! closed loop between primitives, aimed from the observed poses) and comes back flush onto the
//! new edge, and the pushes on both edges must keep the slider on the plate.

use pushbot::exec::io::RobotIo;
use pushbot::exec::stable::{PushRecord, contact_changes, execute as run_plan};
use pushbot::mechanics::V3;
use pushbot::planner::stable::exact::finish_exactly;
use pushbot::planner::stable::robot::{
    SPEED, robot_in_slider, robot_problem, robot_problem_edges, robot_start, sim_scene,
};
use pushbot::planner::stable::{Plan, Pose, Problem, angle_diff, plan};
use pushbot::sim::robot::{SimRobot, SimRobotOptions};

/// The preset `name` for the plated robot (edge 0 only) with the goal heading tolerance of
/// `goal_theta_deg`.
fn problem(name: &str, goal_theta_deg: f64) -> (pushbot::planner::stable::presets::Scene, Problem) {
    robot_problem(name, Some(goal_theta_deg)).unwrap()
}

/// The simulated robot in the problem's scene, its plate flush at `start`, exact camera.
fn sim_robot(
    s: &pushbot::planner::stable::presets::Scene,
    p: &Problem,
    start: [f64; 3],
) -> SimRobot {
    let scene = sim_scene(s, p, start, 1).unwrap();
    let opts = SimRobotOptions {
        seed: 3,
        position_noise: 0.0,
        heading_noise: 0.0,
        speed: SPEED,
        boundary_inset: 0.01,
        table_margin: 0.0,
        ..SimRobotOptions::default()
    };
    SimRobot::new(scene, Some("slider"), None, opts).unwrap()
}

/// The slider pose in the robot frame.
fn relative(robot: Pose, slider: Pose) -> Pose {
    let (s, c) = robot.theta.sin_cos();
    let (dx, dy) = (slider.x - robot.x, slider.y - robot.y);
    Pose::new(
        c * dx + s * dy,
        -s * dx + c * dy,
        slider.theta - robot.theta,
    )
}

struct Outcome {
    pushes: Vec<PushRecord>,
    end: Pose,
}

/// Plan the problem `s, p` and execute the plan on the sim robot.
fn plan_and_run(
    name: &str,
    s: &pushbot::planner::stable::presets::Scene,
    p: &Problem,
) -> (Plan, Outcome) {
    let pl = plan(p);
    assert!(
        pl.found,
        "{name}: no plan for the sim robot ({} nodes, controls {:?})",
        pl.nodes_expanded,
        p.contacts
            .iter()
            .map(|c| c.usable.controls.clone())
            .collect::<Vec<_>>()
    );
    let start = robot_start(p, &pl).unwrap();
    let mut robot = sim_robot(s, p, start);
    let (pushes, end) = run_plan(p, &pl, &mut robot).unwrap();
    (pl, Outcome { pushes, end })
}

fn execute(name: &str, goal_theta_deg: f64) -> (Problem, Outcome) {
    let (s, p) = problem(name, goal_theta_deg);
    let (pl, o) = plan_and_run(name, &s, &p);
    assert_eq!(pl.contact_changes, 0, "{name}: one edge only");
    (p, o)
}

fn check(name: &str, goal_theta_deg: f64) {
    let (p, o) = execute(name, goal_theta_deg);
    check_outcome(name, &p, &o);
}

/// Every push kept the slider on the plate (< 1 mm per 100 mm, < 1°), more than 0.3 m were
/// pushed in all, and the slider ended in the goal neighbourhood.
fn check_outcome(name: &str, p: &Problem, o: &Outcome) {
    check_pushes(name, o);
    assert!(
        p.in_goal(&o.end),
        "{name}: the slider ended at {:?}, outside the goal neighbourhood of {:?}",
        o.end,
        p.goal
    );
}

/// Every push kept the slider on the plate (< 1 mm per 100 mm, < 1°) and more than 0.3 m were
/// pushed in all.
fn check_pushes(name: &str, o: &Outcome) {
    let total: f64 = o.pushes.iter().map(|x| x.pushed).sum();
    for (i, r) in o.pushes.iter().enumerate() {
        let (len, dpos, dth) = (&r.pushed, &r.drift, &r.drift_angle);
        eprintln!(
            "{name} push {i} (contact {}): {:.1} mm pushed, drift {:.3} mm, {:.3}°",
            r.contact,
            len * 1e3,
            dpos * 1e3,
            dth.to_degrees()
        );
        assert!(
            *dpos < 0.01 * len.max(0.01) && *dth < 1f64.to_radians(),
            "{name} push {i}: the slider moved on the plate: {:.2} mm over {:.1} mm, {:.2}°",
            dpos * 1e3,
            len * 1e3,
            dth.to_degrees()
        );
    }
    eprintln!("{name}: {:.0} mm pushed, end {:?}", total * 1e3, o.end);
    assert!(total > 0.3, "{name}: pushed only {total} m");
}

#[test]
fn fig15_executed_open_loop_in_the_sim_keeps_the_slider_on_the_plate() {
    check("fig15", 2.0);
}

/// Fig. 13's task for the plated differential drive needs a left and a right 90° turn; its
/// turning pushes rotate the slider by fixed angles per step, and on the planning grid no
/// sequence ends within the paper's ±2° (the search exhausts), so the goal's heading tolerance
/// is widened to ±10° here; position tolerance and everything checked are as in the preset.
///
/// Why (the planner, not the executor or the sim): with ±2° the search empties OPEN — it does
/// not hit the node limit — for every setting tried (step 0.1–0.3 of the slider length, grid
/// 0.5–1 step and 3–6°, refined radius 0–2 lengths, refinement 3–6, 3 million nodes), and
/// giving the robot extra half-way arcs makes it fail even at ±10°. The robot's three controls
/// (two extremal turns about points on its axle, straight ahead; forward only) reach a lattice
/// of headings, and the grid pruning of §4.2.3 keeps one configuration per 2° cell near the
/// goal, about the width of the goal window, so the configurations that would end inside it are
/// pruned. The executed pushes themselves stay on the plate (< 1 mm per 100 mm, < 1°).
#[test]
fn fig13_executed_open_loop_in_the_sim_keeps_the_slider_on_the_plate() {
    check("fig13", 10.0);
}

/// The other side of the check: a push STABLE rejects (spinning in place about the axle centre,
/// a rotation centre nearer the slider than the extremal stable ones) does make the slider
/// move on the plate in the sim.
#[test]
fn a_push_outside_the_stable_set_slides_on_the_plate_in_the_sim() {
    let (s, p) = problem("fig15", 2.0);
    let (axle, heading) = robot_in_slider(&p, 0);
    // Spin about the axle centre: the slider-frame twist with its rotation centre there.
    let xi = V3::new(axle.y, -axle.x, 1.0);
    assert!(
        !p.contacts[0].usable.set.contains(&xi) && !p.contacts[0].usable.set.contains(&-xi),
        "spinning in place is stable?"
    );
    let a0 = p.start.apply(axle);
    let h0 = p.start.rotate(heading);
    let start = [a0.x, a0.y, h0.y.atan2(h0.x)];
    let mut robot = sim_robot(&s, &p, start);
    let mut rel = || {
        let rp = robot.robot_pose();
        let sp = robot.body_pose("slider").unwrap();
        relative(
            Pose::new(rp.x, rp.y, rp.theta),
            Pose::new(sp.x, sp.y, sp.theta),
        )
    };
    let q0 = rel();
    robot.drive(0.0, -0.5, 1.0).unwrap();
    let rp = robot.robot_pose();
    let sp = robot.body_pose("slider").unwrap();
    let q1 = relative(
        Pose::new(rp.x, rp.y, rp.theta),
        Pose::new(sp.x, sp.y, sp.theta),
    );
    let (dpos, dth) = (
        (q1.x - q0.x).hypot(q1.y - q0.y),
        pushbot::planner::stable::angle_diff(q1.theta, q0.theta).abs(),
    );
    eprintln!("spin: drift {:.2} mm, {:.2}°", dpos * 1e3, dth.to_degrees());
    assert!(
        dpos > 0.001 || dth > 1f64.to_radians(),
        "the slider stayed fixed under an unstable push: {dpos} m, {dth} rad"
    );
}

/// Fig. 13's task at the paper's ±2° for the plated robot on two opposite edges (0 and 3), a
/// contact change costing `c = 10`: on edge 0 alone no plan ends within ±2° (the test above
/// needs ±10°); with both edges the plan changes contact once, from edge 3 to edge 0 after its
/// first push. Between the two pushing runs the robot drives the transit path around the slider
/// (closed loop between primitives) and comes back flush on edge 0 with a short seating push:
/// the pushes after the change must keep the slider on the plate too, and the executed run must
/// end where the plan ends (within 20 mm and 0.5°: what open-loop tracking over ~2 m and a
/// re-seating can promise). Executed without the transit (the arcs of edge 0 driven from
/// edge 3), the slider leaves the plate (push 2) and ends far from the plan's end.
///
/// Not the goal neighbourhood itself: the plan may end near its border (its end is 1.74° off
/// the goal heading, at ±2°), and an open-loop run gets no correction for the few millimetres
/// and tenths of a degree it drifts (here 0.33°); reaching the goal despite them is the
/// closed-loop executor's job (`exec/stable_feedback.rs`, tests in `stable_closed_loop`).
///
/// Figs. 16–18 do not work for this robot: on their small tables (1.2 × 0.8 m, 1.6 × 1.2 m)
/// the plated robot behind the slider finds no plan even on a single edge, nor with both edges
/// at ±10° (the search empties OPEN after 4–15 configurations: every push soon runs robot and
/// slider into a wall, an obstacle or the table's edge, where the paper's arm has no extent).
#[test]
fn fig13_with_a_contact_change_executed_in_the_sim_keeps_the_slider_on_the_plate() {
    let name = "fig13";
    let (s, p) = robot_problem_edges(name, Some(2.0), &[0, 3], Some(10)).unwrap();
    let (pl, o) = plan_and_run(name, &s, &p);
    assert!(
        pl.contact_changes >= 1 && pl.transits.len() == pl.contact_changes,
        "{name}: the plan changes contact {} times with {} transit paths",
        pl.contact_changes,
        pl.transits.len()
    );
    let last = pl.steps.last().unwrap().to;
    eprintln!("{name}: planned end {last:?}");
    let driven = contact_changes(&o.pushes);
    eprintln!(
        "{name}: {driven} contact change(s) driven, transits {:?}",
        pl.transits
            .iter()
            .map(|t| (t.from_contact, t.to_contact, t.length))
            .collect::<Vec<_>>()
    );
    assert_eq!(
        driven, pl.contact_changes,
        "{name}: contact changes driven vs planned"
    );
    check_pushes(name, &o);
    let (dx, dy) = (o.end.x - last.x, o.end.y - last.y);
    let (dpos, dth) = (dx.hypot(dy), angle_diff(o.end.theta, last.theta).abs());
    eprintln!(
        "{name}: executed end {:.1} mm and {:.2}° from the plan's end",
        dpos * 1e3,
        dth.to_degrees()
    );
    assert!(
        dpos < 0.02 && dth < 0.5f64.to_radians(),
        "{name}: the open-loop run ended {:.1} mm and {:.2}° from the plan's end",
        dpos * 1e3,
        dth.to_degrees()
    );
}

/// The exact-goal finish of a wheeled pusher (§4.5 with the Dubins path of the tightest stable
/// turn, `exact.rs`), driven open loop like every other push: its turns are stable pushes too,
/// so the slider stays on the plate, and it ends nearer the goal itself than the plan's own end
/// in the neighbourhood does.
#[test]
fn fig15_exact_finish_executed_open_loop_ends_on_the_goal() {
    let (s, p) = problem("fig15", 2.0);
    let pl = plan(&p);
    assert!(pl.found);
    let done = finish_exactly(&p, &pl).expect("an exact finish for fig15");
    assert!(done.exact_goal);
    let start = robot_start(&p, &done).unwrap();
    let mut robot = sim_robot(&s, &p, start);
    let (pushes, end) = run_plan(&p, &done, &mut robot).unwrap();
    let o = Outcome { pushes, end };
    check_outcome("fig15 exact", &p, &o);
    let plan_end = pl.steps.last().unwrap().to;
    let miss = |q: &Pose| (q.x - p.goal.x).hypot(q.y - p.goal.y);
    eprintln!(
        "fig15 exact: executed end {:.1} mm and {:.2}° from the goal; the search's own end {:.1} mm, {:.2}°",
        miss(&end) * 1e3,
        angle_diff(end.theta, p.goal.theta).to_degrees(),
        miss(&plan_end) * 1e3,
        angle_diff(plan_end.theta, p.goal.theta).to_degrees()
    );
    // Open-loop execution error on top of an exact plan: within 1 cm and 0.5° (measured 3.6 mm
    // and 0.12°), where the search's neighbourhood end is 62 mm and 1.9° away.
    assert!(
        miss(&end) < 0.01 && angle_diff(end.theta, p.goal.theta).abs() < 0.5f64.to_radians(),
        "fig15 exact: ended {:.1} mm, {:.2}° from the goal",
        miss(&end) * 1e3,
        angle_diff(end.theta, p.goal.theta).to_degrees()
    );
    assert!(miss(&end) < miss(&plan_end));
}
