//! Stable-pushing trials in perturbed simulated worlds: Lynch & Mason's plan (§4)
//! for the plated robot, made with the nominal model, driven open loop
//! ([`crate::exec::stable::execute`]) or closed loop
//! ([`crate::exec::stable_feedback::execute_closed_loop`]) on the in-process simulated robot
//! whose world runs a perturbation drawn from the scene's `[perturb]` ranges
//! (`sim-target/src/perturb.rs`). `pushbot run stable` and `pushbot eval stable` print them.

use crate::sim::target::Perturbation;
use anyhow::{Context, Result, anyhow, bail};
use pushbot_world::scene::perturb::Perturb;

use crate::exec::io::RobotIo;
use crate::exec::stable::execute;
use crate::exec::stable_feedback::{FeedbackParams, execute_closed_loop};
use crate::exec::stable_replan::plan_clear;
use crate::exec::stable_start::start_path;
use crate::mechanics::V2;
use crate::planner::stable::collision::Body;
use crate::planner::stable::presets::{CostOverride, PRESETS, Scene as StableScene, load_scene};
use crate::planner::stable::random_scene::{RandomPusher, WEIGHT, random_scene};
use crate::planner::stable::robot::{
    PLATE_OFFSET, PLATE_WIDTH, SPEED, robot_problem, robot_problem_in, robot_problem_scene,
    robot_start, sim_scene,
};
use crate::planner::stable::transit::point_segment_distance;
use crate::planner::stable::{Plan, Pose, Problem, angle_diff, plan};
use crate::sim::robot::{SimCamera, SimRobot, SimRobotOptions};

/// The robot-scale versions of the presets: (name, factor on the table and every position on
/// it, the slider's pushing edges, the contact-change cost). The slider and the robot keep
/// their sizes: the paper's figures are drawn for an arm with no extent, and on their tables
/// the plated robot behind the slider finds no plan (Figs. 16–18: the search empties OPEN
/// after 7–12 configurations; Fig. 13 on edge 0 at ±2°: none either). These are the smallest
/// of 1, 1.5, 2 and 2.5 at which the plated robot has a plan; Figs. 16–18 push on the
/// preset's two opposite edges with a contact change costing 10.
pub const ROBOT_SCALE: [(&str, f64, &[usize], Option<u32>); 5] = [
    ("fig13", 1.5, &[0], None),
    ("fig15", 1.0, &[0], None),
    ("fig16", 2.0, &[0, 3], Some(10)),
    ("fig17", 2.0, &[0, 3], Some(10)),
    ("fig18", 2.0, &[0, 3], Some(10)),
];

/// The stable scene `s` with its table and everything on it (obstacles, start, goal) scaled
/// by `k` about the table's corner; the objects keep their shapes.
fn scaled(mut s: StableScene, k: f64) -> StableScene {
    s.table = [s.table[0] * k, s.table[1] * k];
    for o in &mut s.obstacles {
        for v in &mut o.polygon {
            v[0] *= k;
            v[1] *= k;
        }
    }
    for q in [&mut s.task.start, &mut s.task.goal] {
        q[0] *= k;
        q[1] *= k;
    }
    for o in &mut s.objects {
        if let Some(q) = &mut o.pose {
            q[0] *= k;
            q[1] *= k;
        }
    }
    s
}

/// A planned stable-pushing task for the plated robot and the ranges its worlds are drawn from.
#[derive(Debug, Clone)]
pub struct StableTask {
    /// The preset's name or the scene file.
    pub name: String,
    /// The stable scene (the robot as pusher).
    pub scene: StableScene,
    /// Its problem.
    pub problem: Problem,
    /// The plan (found), made with the nominal model for the inner part of the goal
    /// neighbourhood, clear of the obstacles where it can be ([`plan_clear`]).
    pub plan: Plan,
    /// The perturbation ranges: the scene's `[perturb]` or the defaults.
    pub ranges: Perturb,
    /// Where the robot starts (axle centre, heading): `None` flush on the plan's first contact.
    pub robot_start: Option<[f64; 3]>,
}

impl StableTask {
    /// The task of `name`: a preset (`fig13` … `fig18`: its robot-scale version
    /// ([`ROBOT_SCALE`]), the robot's plate as the pusher) or a scene file with a `[stable]` section
    /// whose pusher is a `diff-drive` (the simulated robot is one; its own edges and costs).
    /// Errors on a bad scene or when no plan exists.
    pub fn load(name: &str) -> Result<StableTask> {
        let world = pushbot_world::Scene::preset_or_file(name).map_err(|e| anyhow!("{e}"))?;
        let (scene, problem) = if let Some((_, k, edges, c)) =
            ROBOT_SCALE.iter().find(|r| r.0 == name)
        {
            robot_problem_in(scaled(load_scene(name)?, *k), None, edges, *c)?
        } else if PRESETS.contains(&name) {
            robot_problem(name, None)?
        } else {
            let s = load_scene(name)?;
            if s.pusher.kind != "diff-drive" {
                bail!(
                    "scene {name}: its [stable] pusher is {:?}; the robot that runs it is a \
                     differential drive with a front plate: give pusher = {{ kind = \"diff-drive\" }}",
                    s.pusher.kind
                );
            }
            // Its whole `[stable]` section: edges, start edge, costs, step, grid, tolerances
            // and the robot's plate.
            robot_problem_scene(name)?
        };
        let Some(pl) = plan_clear(&problem).filter(|pl| !pl.steps.is_empty()) else {
            bail!(
                "scene {name}: no plan of stable pushes for the plated robot ({} configurations \
                 expanded)",
                plan(&problem).nodes_expanded
            );
        };
        Ok(StableTask {
            name: name.to_string(),
            scene,
            problem,
            plan: pl,
            ranges: world.perturb.unwrap_or_default(),
            robot_start: None,
        })
    }

    /// The random scene of `seed` ([`random_scene`]) for `pusher` on the simulated robot,
    /// planned with the nominal model as `pushbot bench stable --random` plans it (A* weighted by
    /// [`WEIGHT`]); `Ok(None)` when no plan exists. The robot starts at a free pose of any
    /// heading 0.2–0.45 m from the slider ([`robot_start_pose`]).
    ///
    /// The simulated robot is a differential drive with a 12 cm plate 6 cm ahead of its axle:
    /// the random diff-drive pusher is that robot. The random car (plate 12 cm, rear axle 10 cm
    /// behind it, 14 cm deep) is mapped onto it: its rear axle where the robot's wheel axle is
    /// (6 cm) and the robot's body (10 cm), kept are its turning radius and forward-only
    /// pushing; the planner plans that car. (A differential drive's rotation centres lie on its
    /// axle line, so only a car whose rear axle is that line is a subset of it.)
    pub fn random(seed: u64, pusher: RandomPusher) -> Result<Option<StableTask>> {
        if !matches!(pusher, RandomPusher::DiffDrive | RandomPusher::Car) {
            bail!(
                "random {} scenes: the simulated robot drives diff-drive and car scenes",
                pusher.name()
            );
        }
        let rs = random_scene(seed, pusher)?;
        let mut scene = rs.scene()?;
        if pusher == RandomPusher::Car {
            scene.pusher.axle_offset = Some(PLATE_OFFSET);
            scene.pusher.depth = Some(PLATE_OFFSET + 0.04);
            scene.pusher.width = Some(PLATE_WIDTH);
            scene.pusher.plate_width = Some(PLATE_WIDTH);
        }
        if pusher == RandomPusher::Car {
            // The mapped car may have no usable push on an edge the generator offered (its
            // rotation centres moved): that edge is dropped.
            let all = scene.task.edges.clone();
            scene.task.edges = all
                .into_iter()
                .filter(|e| {
                    let mut one = scene.clone();
                    one.task.edges = vec![*e];
                    one.task.start_edge = None;
                    one.problem(CostOverride::default()).is_ok()
                })
                .collect();
            if scene.task.edges.is_empty() {
                return Ok(None);
            }
            if scene
                .task
                .start_edge
                .is_some_and(|e| !scene.task.edges.contains(&e))
            {
                scene.task.start_edge = None;
            }
        }
        let mut problem = scene.problem(CostOverride::default())?;
        problem.params.weight = WEIGHT;
        if (problem.pusher.axle_offset - PLATE_OFFSET).abs() > 1e-9
            || problem.pusher.plate_width != Some(PLATE_WIDTH)
        {
            bail!(
                "{}: the pusher's plate ({:?} m, {} m ahead of the axle) is not the simulated \
                 robot's ({PLATE_WIDTH} m, {PLATE_OFFSET} m)",
                rs.name(),
                problem.pusher.plate_width,
                problem.pusher.axle_offset
            );
        }
        let Some(pl) = plan_clear(&problem).filter(|pl| !pl.steps.is_empty()) else {
            return Ok(None);
        };
        let robot_start = robot_start_pose(&problem, pl.steps[0].contact, seed);
        Ok(Some(StableTask {
            name: rs.name(),
            scene,
            problem,
            plan: pl,
            ranges: Perturb::default(),
            robot_start,
        }))
    }

    /// The simulated scene: the robot at [`StableTask::robot_start`], else its plate flush on
    /// the plan's first contact.
    pub fn sim_scene(&self) -> Result<pushbot_world::Scene> {
        let start = match self.robot_start {
            Some(r) => r,
            None => robot_start(&self.problem, &self.plan)
                .ok_or_else(|| anyhow!("the plan has no step"))?,
        };
        sim_scene(&self.scene, &self.problem, start, 1)
    }

    /// Trial `trial`'s world with `seed`: drawn from the ranges when `perturbed`, else the
    /// nominal world with only the camera's noise.
    pub fn perturbation(&self, seed: u64, trial: u64, perturbed: bool) -> Perturbation {
        let ranges = if perturbed {
            self.ranges
        } else {
            Perturb {
                camera_xy: self.ranges.camera_xy,
                camera_theta_deg: self.ranges.camera_theta_deg,
                ..Perturb::none()
            }
        };
        Perturbation::draw(&ranges, "slider", seed, trial)
    }
}

/// A start for the robot's axle centre 0.2–0.45 m from the slider's start, of any heading,
/// drawn from `seed`: its turning disk (with 3 cm to spare, for the perturbed start) clear of
/// the table's edges, the obstacles and the slider, and a way for it from there to contact
/// `first` ([`start_path`]; the start heading is free, the position not: an enclosed pocket
/// has no way out). `None` (flush on the first contact) when 500 draws find none.
pub fn robot_start_pose(p: &Problem, first: usize, seed: u64) -> Option<[f64; 3]> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ 0x5747_4152);
    let r = p.pusher.turning_radius_disk() + 0.03;
    let disk: Vec<V2> = (0..16)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 16.0;
            V2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    let body = Body::new(&[disk]);
    let slider: Vec<V2> = p
        .slider
        .vertices
        .iter()
        .map(|v| p.start.apply(*v))
        .collect();
    let n = slider.len();
    for _ in 0..500 {
        let (a, d) = (
            rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
            rng.random_range(0.2..0.45),
        );
        let c = V2::new(p.start.x + d * a.cos(), p.start.y + d * a.sin());
        let heading = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let (w, h) = p.world.table;
        if c.x < r || c.y < r || c.x > w - r || c.y > h - r {
            continue;
        }
        // Outside the slider (d exceeds its radius) and clear of its edges.
        let off_slider = d > p.slider.radius()
            && (0..n).all(|i| point_segment_distance(c, slider[i], slider[(i + 1) % n]) > r);
        if off_slider
            && body.free_at(&p.world, &Pose::new(c.x, c.y, 0.0))
            && start_path(p, c, &p.start, first).is_some()
        {
            return Some([c.x, c.y, heading]);
        }
    }
    None
}

/// One trial's outcome.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct StableTrial {
    /// Trial number.
    pub trial: u64,
    /// Whether the slider truly ended in the goal neighbourhood.
    pub reached: bool,
    /// Its true distance from the goal, m.
    pub final_error_m: f64,
    /// Its true heading error, degrees.
    pub final_error_deg: f64,
    /// Re-plans from the measured poses (closed loop).
    pub replans: usize,
    /// Times the plate lost the edge (closed loop).
    pub contact_losses: usize,
    /// Simulated time the trial took, s.
    pub mission_s: f64,
    /// Why the executor stopped outside the goal, if it did.
    pub failure: Option<String>,
    /// The world it ran.
    pub perturbation: Perturbation,
    /// The slider's observed path (table m), for figures.
    #[serde(skip)]
    pub path: Vec<[f64; 2]>,
}

/// Run `task` once on the in-process simulated robot, in the world `pert`, closed loop or open
/// loop, seeing the table through `camera` (the simulator's poses with the perturbation's camera
/// noise, or the rendered camera read by the host's vision pipeline); judged by the simulator's
/// true slider pose.
pub fn run_trial(
    task: &StableTask,
    trial: u64,
    seed: u64,
    pert: Perturbation,
    closed_loop: bool,
    camera: SimCamera,
) -> Result<StableTrial> {
    let scene = task.sim_scene()?;
    let opts = SimRobotOptions {
        camera,
        seed: seed.wrapping_mul(1000).wrapping_add(trial),
        position_noise: pert.camera_xy,
        heading_noise: pert.camera_theta,
        speed: SPEED,
        boundary_inset: 0.01,
        table_margin: 0.0,
        ..SimRobotOptions::default()
    };
    let mut robot = SimRobot::perturbed(scene, Some("slider"), None, opts, Some(pert.clone()))
        .context("starting the simulated robot")?;
    let t0 = robot.time();
    let p = &task.problem;
    let (replans, contact_losses, failure, path) = if closed_loop {
        let r = execute_closed_loop(p, &task.plan, &mut robot, &FeedbackParams::default())?;
        (r.replans, r.contact_losses, r.failure, r.path)
    } else {
        let mut path = Vec::new();
        let start = robot.body_pose("slider");
        path.extend(start.map(|s| [s.x, s.y]));
        let (_, end) = execute(p, &task.plan, &mut robot)?;
        path.push([end.x, end.y]);
        (0, 0, None, path)
    };
    let t = robot.true_object_pose();
    let end = Pose::new(t.x, t.y, t.theta);
    let reached = p.in_goal(&end);
    Ok(StableTrial {
        trial,
        reached,
        final_error_m: (end.x - p.goal.x).hypot(end.y - p.goal.y),
        final_error_deg: angle_diff(end.theta, p.goal.theta).to_degrees(),
        replans,
        contact_losses,
        mission_s: robot.time() - t0,
        failure: if reached {
            None
        } else {
            failure.or_else(|| Some("ended outside the goal neighbourhood".into()))
        },
        perturbation: pert,
        path,
    })
}

/// Run `task` once through a serial port and a camera, as on a real robot: on `robot`
/// (`(port, camera)`) when given, else on the built-in simulated target served on a pty with its
/// rendered camera (AprilTag detection and tracking in the loop), its world perturbed by `pert`
/// and paced `speed` times faster than the wall clock. Judged by the simulator's truth on the
/// built-in target, by the camera on a real robot (where `pert` is not applied: the table is
/// what it is).
pub fn run_trial_live(
    task: &StableTask,
    trial: u64,
    seed: u64,
    pert: Perturbation,
    closed_loop: bool,
    robot: Option<(&str, &str)>,
    speed: f64,
) -> Result<StableTrial> {
    use crate::exec::{LiveOptions, LiveRobot};
    let scene = task.sim_scene()?;
    let opts = LiveOptions {
        object: Some("slider".into()),
        speed: SPEED,
        watchdog_ms: (1000.0 * speed.max(1.0)).min(5000.0) as u16,
        ..LiveOptions::default()
    };
    let target = match robot {
        Some(_) => None,
        None => Some(crate::sim::SimTarget::start_perturbed(
            &scene,
            seed.wrapping_mul(1000).wrapping_add(trial),
            speed,
            Some(pert.clone()),
        )?),
    };
    let (port, camera) = match (robot, &target) {
        (Some(pc), _) => pc,
        (None, Some(t)) => (t.port(), t.camera()),
        (None, None) => bail!("no robot"),
    };
    let p = &task.problem;
    let outcome = (|| -> Result<_> {
        let mut live = LiveRobot::connect(port, camera, &scene, opts)?;
        let t0 = live.time();
        let r = if closed_loop {
            let r = execute_closed_loop(p, &task.plan, &mut live, &FeedbackParams::default())?;
            (r.replans, r.contact_losses, r.failure, r.path, r.end)
        } else {
            let (_, end) = execute(p, &task.plan, &mut live)?;
            (0, 0, None, vec![[end.x, end.y]], end)
        };
        Ok((r, live.time() - t0))
    })();
    let truth = target.as_ref().and_then(|t| {
        t.sim()
            .objects()
            .into_iter()
            .find(|(id, _)| id == "slider")
            .map(|(_, q)| Pose::new(q.x, q.y, q.theta))
    });
    if let Some(t) = target {
        t.shutdown()?;
    }
    let ((replans, contact_losses, failure, path, seen), mission_s) = outcome?;
    let end = truth.unwrap_or(seen);
    let reached = p.in_goal(&end);
    Ok(StableTrial {
        trial,
        reached,
        final_error_m: (end.x - p.goal.x).hypot(end.y - p.goal.y),
        final_error_deg: angle_diff(end.theta, p.goal.theta).to_degrees(),
        replans,
        contact_losses,
        mission_s,
        failure: if reached {
            None
        } else {
            failure.or_else(|| Some("ended outside the goal neighbourhood".into()))
        },
        perturbation: pert,
        path,
    })
}
