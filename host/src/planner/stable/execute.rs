//! Stable pushes on this project's robot (Lynch & Mason §4, executed as the paper intends: open
//! loop, no sensing during a push): a preset's pusher replaced by the differential-drive robot
//! with its flat front plate, the plan turned into one `Velocity` arc of the axle centre per run
//! of steps with one control, and the simulated scene that matches the problem.
//!
//! Only one edge is used: a mobile robot changing contact needs a transit path around the
//! slider that the executor does not drive yet.

use anyhow::{Result, anyhow};

use super::presets::{CostOverride, CostSpec, Scene as StableScene, load_scene};
use super::{Plan, Pose, Problem};
use crate::mechanics::{V2, V3};
use crate::strategy::robot_io::RobotIo;

/// The robot's plate: width and distance of its face ahead of the wheel axle (m), as in
/// `[robot] front_plate` of the simulated scenes.
pub const PLATE_WIDTH: f64 = 0.12;
/// See [`PLATE_WIDTH`].
pub const PLATE_OFFSET: f64 = 0.06;
/// Pushing speed of the axle centre (m/s): slow, as quasi-static pushing assumes.
pub const SPEED: f64 = 0.04;

/// The preset `name` with its pusher replaced by the plated differential-drive robot, edge 0
/// only, with the goal heading `goal_theta_deg` (if given); and the problem built from it.
pub fn robot_problem(name: &str, goal_theta_deg: Option<f64>) -> Result<(StableScene, Problem)> {
    let mut s = load_scene(name)?;
    if let Some(g) = goal_theta_deg {
        s.task.goal_theta_deg = g;
    }
    s.pusher.kind = "diff-drive".into();
    s.pusher.width = Some(PLATE_WIDTH);
    s.pusher.depth = Some(PLATE_OFFSET + 0.04);
    s.pusher.axle_offset = Some(PLATE_OFFSET);
    s.pusher.plate_width = Some(PLATE_WIDTH);
    s.pusher.min_turning_radius = None;
    s.task.edges = vec![0];
    s.task.start_edge = None;
    s.planner.c = Some(CostSpec::Word("inf".into()));
    let p = s.problem(CostOverride::default())?;
    Ok((s, p))
}

/// The robot's axle centre and heading in the slider frame for contact `ci`.
pub fn robot_in_slider(p: &Problem, ci: usize) -> (V2, V2) {
    let pl = &p.contacts[ci].placement;
    (pl.to_slider(V2::new(0.0, -PLATE_OFFSET)), pl.normal)
}

/// Where the robot starts: its plate flush on the plan's first contact. `None` without steps.
pub fn robot_start(p: &Problem, plan: &Plan) -> Option<[f64; 3]> {
    let ci = plan.steps.first()?.contact;
    let (axle, heading) = robot_in_slider(p, ci);
    let a0 = p.start.apply(axle);
    let h0 = p.start.rotate(heading);
    Some([a0.x, a0.y, h0.y.atan2(h0.x)])
}

/// The simulated scene of the problem: the same table and obstacles, the slider (object frame
/// at its centre of friction, marker `marker_id` on it), the robot with its plate at `start`.
pub fn sim_scene(
    s: &StableScene,
    p: &Problem,
    start: [f64; 3],
    marker_id: u32,
) -> Result<pushbot_sim::Scene> {
    let mut t = format!(
        "name = \"{}\"\n[table]\nwidth = {}\nheight = {}\n[robot]\nstart = {{ x = {}, y = {}, theta = {} }}\nfront_plate = {{ width = {PLATE_WIDTH}, offset = {PLATE_OFFSET} }}\n",
        s.name, s.table[0], s.table[1], start[0], start[1], start[2]
    );
    for o in &s.obstacles {
        t += &format!("[[obstacles]]\noutline = {:?}\n", o.polygon);
    }
    let outline: Vec<[f64; 2]> = p.slider.vertices.iter().map(|v| [v.x, v.y]).collect();
    let r = outline
        .iter()
        .map(|v| v[0].hypot(v[1]))
        .fold(f64::INFINITY, f64::min);
    let size = (r * 1.2).clamp(0.02, 0.05);
    t += &format!(
        "[[objects]]\nid = \"slider\"\noutline = {outline:?}\npose = {{ x = {}, y = {}, theta = {} }}\nmass = 0.1\nsupport = {{ kind = \"uniform\" }}\nsupport_friction = 0.3\npusher_friction = {}\nmarker = {{ id = {marker_id}, x = 0.0, y = 0.0, size = {size} }}\n",
        p.start.x, p.start.y, p.start.theta, s.mu
    );
    t += &format!(
        "[[goals]]\nobject = \"slider\"\npose = {{ x = {}, y = {}, theta = {} }}\ntolerance = {}\n",
        p.goal.x, p.goal.y, p.goal.theta, p.params.goal_xy
    );
    pushbot_sim::Scene::from_toml(&t, &format!("stable scene {}", s.name))
        .map_err(|e| anyhow!("{e}"))
}

/// The plan as arcs of the axle centre: per run of steps with one control, the distance driven
/// (m, along the heading) and the turn (rad).
pub fn arcs(p: &Problem, plan: &Plan) -> Vec<(f64, f64)> {
    let Some(first) = plan.steps.first() else {
        return Vec::new();
    };
    let (axle, heading) = robot_in_slider(p, first.contact);
    let mut runs: Vec<(usize, f64, f64)> = Vec::new();
    for st in &plan.steps {
        let xi = V3::new(st.twist[0], st.twist[1], st.twist[2]);
        let u = V2::new(xi.x - xi.z * axle.y, xi.y + xi.z * axle.x);
        let (d, phi) = (u.dot(&heading), xi.z);
        match runs.last_mut() {
            Some((k, dd, pp)) if *k == st.control => {
                *dd += d;
                *pp += phi;
            }
            _ => runs.push((st.control, d, phi)),
        }
    }
    runs.into_iter().map(|(_, d, phi)| (d, phi)).collect()
}

/// One executed push: the slider's pose relative to the robot before and after, and how far
/// the slider moved.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PushRecord {
    /// Distance the slider moved, m.
    pub pushed: f64,
    /// How far it moved on the plate, m.
    pub drift: f64,
    /// How far it turned on the plate, rad.
    pub drift_angle: f64,
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

/// Drive the plan's arcs open loop on `io` (the slider is the object `slider`); observe only
/// between pushes, to report drift. Returns each push and the slider's final pose.
pub fn execute(p: &Problem, plan: &Plan, io: &mut dyn RobotIo) -> Result<(Vec<PushRecord>, Pose)> {
    let pose = |io: &mut dyn RobotIo| -> Result<(Pose, Pose)> {
        let rp = io.robot_pose();
        let sp = io
            .body_pose("slider")
            .ok_or_else(|| anyhow!("the slider is not seen"))?;
        Ok((
            Pose::new(rp.x, rp.y, rp.theta),
            Pose::new(sp.x, sp.y, sp.theta),
        ))
    };
    let mut pushes = Vec::new();
    for (d, phi) in arcs(p, plan) {
        let (r0, s0) = pose(io)?;
        let dur = (d.abs() / SPEED).max(phi.abs() / 0.5).max(0.05);
        io.drive(d / dur, phi / dur, dur)?;
        let (r1, s1) = pose(io)?;
        let (q0, q1) = (relative(r0, s0), relative(r1, s1));
        pushes.push(PushRecord {
            pushed: (s1.x - s0.x).hypot(s1.y - s0.y),
            drift: (q1.x - q0.x).hypot(q1.y - q0.y),
            drift_angle: super::angle_diff(q1.theta, q0.theta).abs(),
        });
    }
    let (_, end) = pose(io)?;
    Ok((pushes, end))
}
