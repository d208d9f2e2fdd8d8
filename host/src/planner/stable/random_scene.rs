//! Seeded random scenes for stable pushing (Lynch & Mason 1996 §4.4 tries its planner on a few
//! hand-made scenes; these are many): a table, two to four obstacles (boxes, convex polygons,
//! L and U shapes), a box slider with perhaps one corner cut, its start and goal, and one
//! pusher — the project's differential-drive robot with its plate, a car, an omnidirectional
//! robot or an arm. Each is a scene of the shared format with a `[stable]` section (its TOML
//! text), so the planner, the simulator and `pushbot eval stable` read the same scene.
//!
//! The same seed and pusher give the same scene. A draw the scene checks refuse, or that puts
//! the slider within [`CLEARANCE`] of an obstacle at its start or goal, is drawn again from the
//! same generator.

use anyhow::{Context, Result, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::Problem;
use super::collision::Body;
use super::presets::{CostOverride, Scene, scene_from_toml};

/// Least distance from the slider at its start and its goal to any obstacle or wall (m): room
/// for a pusher on some side.
pub const CLEARANCE: f64 = 0.04;

/// Weight of the A* bound for the random scenes' planner (`Params::weight`): plans are found
/// in a few milliseconds, as a planner re-planning in the loop must, at a cost at most this
/// factor above the search's optimum.
pub const WEIGHT: f64 = 2.0;

fn weight() -> f64 {
    std::env::var("PUSHBOT_STABLE_WEIGHT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(WEIGHT)
}

/// Draws per scene before giving up.
const DRAWS: usize = 200;

/// The pusher of a random scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum RandomPusher {
    /// The project's differential-drive robot with its flat front plate (12 cm, 6 cm ahead of
    /// the axle).
    DiffDrive,
    /// A car-like robot (forward only, minimum turning radius 0.15–0.25 m).
    Car,
    /// An omnidirectional robot.
    Omni,
    /// A robot arm (negligible extent, no transit).
    Arm,
}

impl RandomPusher {
    /// All kinds.
    pub const ALL: [RandomPusher; 4] = [
        RandomPusher::DiffDrive,
        RandomPusher::Car,
        RandomPusher::Omni,
        RandomPusher::Arm,
    ];

    /// The `[stable] pusher.kind` name.
    pub fn name(self) -> &'static str {
        match self {
            RandomPusher::DiffDrive => "diff-drive",
            RandomPusher::Car => "car",
            RandomPusher::Omni => "omni",
            RandomPusher::Arm => "arm",
        }
    }

    /// The kind named `name`.
    pub fn parse(name: &str) -> Result<Self> {
        match Self::ALL.iter().find(|k| k.name() == name) {
            Some(k) => Ok(*k),
            None => bail!("unknown pusher {name:?}: expected diff-drive, car, omni or arm"),
        }
    }

    fn salt(self) -> u64 {
        match self {
            RandomPusher::DiffDrive => 1,
            RandomPusher::Car => 2,
            RandomPusher::Omni => 3,
            RandomPusher::Arm => 4,
        }
    }
}

/// A random stable-pushing scene.
#[derive(Debug, Clone, PartialEq)]
pub struct RandomScene {
    /// The seed it was drawn from.
    pub seed: u64,
    /// The pusher.
    pub pusher: RandomPusher,
    /// The scene, shared format with a `[stable]` section.
    pub toml: String,
}

impl RandomScene {
    /// The scene as the planner reads it.
    pub fn scene(&self) -> Result<Scene> {
        scene_from_toml(&self.toml, &self.name())
    }

    /// Its name, `random-<pusher>-<seed>`.
    pub fn name(&self) -> String {
        format!("random-{}-{}", self.pusher.name(), self.seed)
    }

    /// The planning problem with the scene's settings, searched with the A* bound weighted by
    /// [`WEIGHT`].
    pub fn problem(&self) -> Result<Problem> {
        let mut p = self.scene()?.problem(CostOverride::default())?;
        p.params.weight = weight();
        Ok(p)
    }

    /// The same problem searched harder, to tell whether a plan exists: grid cells halved in
    /// x, y and θ, ten times the node limit, and plain A* (weight 1).
    pub fn refined_problem(&self) -> Result<Problem> {
        let mut p = self.problem()?;
        p.params.weight = 1.0;
        p.params.grid_xy /= 2.0;
        p.params.grid_theta /= 2.0;
        p.params.max_nodes *= 10;
        Ok(p)
    }
}

/// The scene of `seed` for `pusher`.
pub fn random_scene(seed: u64, pusher: RandomPusher) -> Result<RandomScene> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(8).wrapping_add(pusher.salt()));
    let mut last = String::new();
    for _ in 0..DRAWS {
        let toml = draw(&mut rng, seed, pusher);
        let rs = RandomScene { seed, pusher, toml };
        match usable(&rs) {
            Ok(()) => return Ok(rs),
            Err(e) => last = format!("{e:#}"),
        }
    }
    bail!(
        "random scene {seed} ({}): no usable draw in {DRAWS} (the last: {last})",
        pusher.name()
    )
}

/// Whether the scene loads, builds a problem and leaves [`CLEARANCE`] around the slider at its
/// start and goal.
fn usable(rs: &RandomScene) -> Result<()> {
    let p = rs.problem()?;
    let slider = Body::new(std::slice::from_ref(&p.slider.vertices));
    for q in [p.start, p.goal] {
        if slider.clearance(&p.world, &q, CLEARANCE) <= CLEARANCE {
            bail!("the slider is within {CLEARANCE} m of an obstacle at {q:?}");
        }
    }
    Ok(())
}

/// `pts` rotated by `a` and moved to `(x, y)`.
fn placed(pts: &[[f64; 2]], x: f64, y: f64, a: f64) -> Vec<[f64; 2]> {
    let (s, c) = a.sin_cos();
    pts.iter()
        .map(|p| [x + c * p[0] - s * p[1], y + s * p[0] + c * p[1]])
        .collect()
}

/// One obstacle's outline (object frame, centred near the origin).
fn obstacle(rng: &mut ChaCha8Rng) -> Vec<[f64; 2]> {
    match rng.random_range(0..4) {
        0 => {
            let (w, h) = (rng.random_range(0.05..0.3), rng.random_range(0.05..0.3));
            vec![
                [-w / 2.0, -h / 2.0],
                [w / 2.0, -h / 2.0],
                [w / 2.0, h / 2.0],
                [-w / 2.0, h / 2.0],
            ]
        }
        1 => {
            // A convex polygon: points on a circle at sorted random angles.
            let r = rng.random_range(0.05..0.15);
            let n = rng.random_range(3..8);
            let mut a: Vec<f64> = (0..n)
                .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
                .collect();
            a.sort_by(f64::total_cmp);
            a.dedup_by(|x, y| (*x - *y).abs() < 0.3);
            if a.len() < 3 {
                a = vec![0.0, 2.1, 4.2];
            }
            a.iter().map(|t| [r * t.cos(), r * t.sin()]).collect()
        }
        2 => {
            // An L: two arms of thickness t.
            let (l1, l2, t) = (
                rng.random_range(0.15..0.35),
                rng.random_range(0.15..0.35),
                rng.random_range(0.03..0.06),
            );
            vec![[0.0, 0.0], [l1, 0.0], [l1, t], [t, t], [t, l2], [0.0, l2]]
        }
        _ => {
            // A U open upwards: base w, arms h, thickness t.
            let (w, h, t) = (
                rng.random_range(0.2..0.4),
                rng.random_range(0.15..0.3),
                rng.random_range(0.03..0.06),
            );
            vec![
                [0.0, 0.0],
                [w, 0.0],
                [w, h],
                [w - t, h],
                [w - t, t],
                [t, t],
                [t, h],
                [0.0, h],
            ]
        }
    }
}

/// The pusher's `[stable]` line (and the robot's plate).
fn pusher_line(rng: &mut ChaCha8Rng, pusher: RandomPusher) -> String {
    match pusher {
        RandomPusher::DiffDrive => {
            "pusher = { kind = \"diff-drive\", width = 0.12, depth = 0.1 }".into()
        }
        RandomPusher::Car => format!(
            "pusher = {{ kind = \"car\", width = 0.12, depth = 0.14, axle_offset = 0.1, plate_width = 0.12, min_turning_radius = {:.3} }}",
            rng.random_range(0.15..0.25)
        ),
        RandomPusher::Omni => "pusher = { kind = \"omni\", width = 0.12, depth = 0.1 }".into(),
        RandomPusher::Arm => "pusher = { kind = \"arm\" }".into(),
    }
}

/// One draw of a whole scene.
fn draw(rng: &mut ChaCha8Rng, seed: u64, pusher: RandomPusher) -> String {
    use std::f64::consts::PI;
    let (w, h) = (rng.random_range(1.2..1.6), rng.random_range(0.9..1.2));
    // The slider: a box, perhaps with one corner cut (as Fig. 12's), centred on its centroid
    // closely enough: the centre of friction is the area centroid.
    let (lx, ly) = (rng.random_range(0.1..0.18), rng.random_range(0.07..0.13));
    let mut outline: Vec<[f64; 2]> = vec![
        [-lx / 2.0, -ly / 2.0],
        [lx / 2.0, -ly / 2.0],
        [lx / 2.0, ly / 2.0],
        [-lx / 2.0, ly / 2.0],
    ];
    if rng.random_bool(0.5) {
        let cut = rng.random_range(0.2..0.4);
        outline = vec![
            [-lx / 2.0, -ly / 2.0],
            [lx / 2.0, -ly / 2.0],
            [lx / 2.0, ly / 2.0 - cut * ly],
            [lx / 2.0 - cut * lx, ly / 2.0],
            [-lx / 2.0, ly / 2.0],
        ];
    }
    // Pushing edges: every edge long enough to hold a plate's contact.
    let edges: Vec<usize> = (0..outline.len())
        .filter(|&i| {
            let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
            (a[0] - b[0]).hypot(a[1] - b[1]) >= 0.04
        })
        .collect();
    let m = 0.15;
    let start = [
        rng.random_range(m..w - m),
        rng.random_range(m..h - m),
        rng.random_range(-PI..PI),
    ];
    let mut goal = start;
    for _ in 0..50 {
        goal = [
            rng.random_range(m..w - m),
            rng.random_range(m..h - m),
            rng.random_range(-PI..PI),
        ];
        if (goal[0] - start[0]).hypot(goal[1] - start[1]) >= 0.3 {
            break;
        }
    }
    let mut t = format!(
        "# Random stable-pushing scene, seed {seed}, pusher {} (planner::stable::random_scene).\n\
         name = \"random-{}-{seed}\"\n[table]\nwidth = {w:.4}\nheight = {h:.4}\n\
         [robot]\nstart = {{ x = 0.1, y = 0.1, theta = 0.0 }}\n\
         front_plate = {{ width = 0.12, offset = 0.06 }}\n",
        pusher.name(),
        pusher.name()
    );
    for _ in 0..rng.random_range(2..5) {
        let o = obstacle(rng);
        let at = placed(
            &o,
            rng.random_range(0.1..w - 0.1),
            rng.random_range(0.1..h - 0.1),
            rng.random_range(-PI..PI),
        );
        let at: Vec<[f64; 2]> = at
            .iter()
            .map(|p| [(p[0] * 1e4).round() / 1e4, (p[1] * 1e4).round() / 1e4])
            .collect();
        t += &format!("[[obstacles]]\noutline = {at:?}\n");
    }
    let stable_pusher = pusher_line(rng, pusher);
    t += &format!(
        "[[objects]]\nid = \"slider\"\noutline = {outline:?}\npose = {{ x = {:.4}, y = {:.4}, theta = {:.4} }}\n\
         mass = 0.1\nsupport_friction = 0.3\npusher_friction = 0.5\n\
         [[goals]]\nobject = \"slider\"\npose = {{ x = {:.4}, y = {:.4}, theta = {:.4} }}\n\
         [stable]\nobject = \"slider\"\nedges = {edges:?}\ngoal_xy_frac = 0.25\ngoal_theta_deg = 5.0\n\
         {stable_pusher}\n\
         planner = {{ a = 1, b = 5, c = 10, step_frac = 0.3, grid_xy_frac = 0.5, grid_theta_deg = 6.0, max_cost = 3000, max_nodes = 100000 }}\n",
        start[0], start[1], start[2], goal[0], goal[1], goal[2]
    );
    t
}

/// The scenes of `seeds` for `pusher`, with the context of a failing seed.
pub fn random_scenes(
    seeds: impl IntoIterator<Item = u64>,
    pusher: RandomPusher,
) -> Result<Vec<RandomScene>> {
    seeds
        .into_iter()
        .map(|s| random_scene(s, pusher).with_context(|| format!("seed {s}")))
        .collect()
}
