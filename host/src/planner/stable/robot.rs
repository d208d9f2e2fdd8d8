//! The stable-pushing problem for this project's robot (Lynch & Mason §4): a preset's pusher
//! replaced by the differential-drive robot with its flat front plate (line contact, §2), the
//! plan turned into one `Velocity` arc of the axle centre per run of steps with one control,
//! and the simulated scene that matches the problem. Pure: [`crate::exec::stable`] drives it.

use anyhow::{Context, Result, anyhow, bail};

use super::presets::{CostOverride, CostSpec, PRESETS, Scene as StableScene, load_scene};
use super::{Plan, Problem};
use crate::mechanics::{V2, V3};

/// The robot's plate: width and distance of its face ahead of the wheel axle (m), as in
/// `[robot] front_plate` of the simulated scenes.
pub const PLATE_WIDTH: f64 = 0.12;
/// See [`PLATE_WIDTH`].
pub const PLATE_OFFSET: f64 = 0.06;
/// Pushing speed of the axle centre (m/s): slow, as quasi-static pushing assumes.
pub const SPEED: f64 = 0.04;
/// The robot problem's grid cell in x, y, as a fraction of the step. Lynch & Mason §4.2.4 ask
/// for a grid fine enough that every control moves the configuration to a new cell: the robot
/// turns about centres on its axle, half a metre out, so a step turns the slider only about as
/// much as one 6° cell and moves its centre about one step; with cells of a whole step a
/// diagonal step can stay in its cell and be pruned. Half a step always leaves it. (With whole
/// steps the search for Fig. 13 on one edge finds a plan or not depending on the order it
/// expands equal-cost configurations in.)
pub const ROBOT_GRID_XY_FRAC: f64 = 0.5;

/// The preset `name` with its pusher replaced by the plated differential-drive robot, edge 0
/// only (no contact changes), with the goal heading `goal_theta_deg` (if given); and the problem
/// built from it. [`robot_problem_edges`] with `&[0]` and `None`.
pub fn robot_problem(name: &str, goal_theta_deg: Option<f64>) -> Result<(StableScene, Problem)> {
    robot_problem_edges(name, goal_theta_deg, &[0], None)
}

/// The preset (or scene file) `name` with its pusher replaced by the plated differential-drive
/// robot, pushing on the slider edges `edges` (any of them first), a contact change costing
/// `contact_cost` (`None`: ∞, no contact changes), with the goal heading tolerance
/// `goal_theta_deg` (if given); and the problem built from it. The preset's other costs and
/// search settings are kept, but for the grid's cell in x, y: half a step ([`ROBOT_GRID_XY_FRAC`]).
pub fn robot_problem_edges(
    name: &str,
    goal_theta_deg: Option<f64>,
    edges: &[usize],
    contact_cost: Option<u32>,
) -> Result<(StableScene, Problem)> {
    robot_problem_in(load_scene(name)?, goal_theta_deg, edges, contact_cost)
}

/// [`robot_problem_edges`] on an already loaded (or changed) stable scene `s`.
pub fn robot_problem_in(
    mut s: StableScene,
    goal_theta_deg: Option<f64>,
    edges: &[usize],
    contact_cost: Option<u32>,
) -> Result<(StableScene, Problem)> {
    let name = s.name.clone();
    if edges.is_empty() {
        bail!("robot problem {name}: no edge to push on");
    }
    if let Some(g) = goal_theta_deg {
        if !(g.is_finite() && g > 0.0) {
            bail!("robot problem {name}: goal heading tolerance {g}° must be finite and > 0");
        }
        s.task.goal_theta_deg = g;
    }
    s.pusher.kind = "diff-drive".into();
    s.pusher.width = Some(PLATE_WIDTH);
    s.pusher.depth = Some(PLATE_OFFSET + 0.04);
    s.pusher.axle_offset = Some(PLATE_OFFSET);
    s.pusher.plate_width = Some(PLATE_WIDTH);
    s.pusher.min_turning_radius = None;
    s.task.edges = edges.to_vec();
    s.task.start_edge = None;
    s.planner.grid_xy_frac = Some(ROBOT_GRID_XY_FRAC);
    s.planner.c = Some(match contact_cost {
        Some(c) => CostSpec::Int(c),
        None => CostSpec::Word("inf".into()),
    });
    let p = s
        .problem(CostOverride::default())
        .with_context(|| format!("robot problem {name} on edges {edges:?}"))?;
    Ok((s, p))
}

/// The preset (or scene file) `name` for the plated robot, honouring its `[stable]` section:
/// its edges, start edge, costs (`c` included), step, grid and goal tolerances are kept. A
/// differential-drive pusher is the robot itself and is kept as the scene gives it (its plate
/// from `[robot] front_plate` or the pusher's `plate_width`); any other pusher (the presets'
/// arm, omnidirectional robot or car) is replaced by the robot with its plate
/// ([`PLATE_WIDTH`], [`PLATE_OFFSET`], or the scene's `front_plate`), on a grid of half a step
/// in x, y ([`ROBOT_GRID_XY_FRAC`]) unless the scene sets one. What `pushbot demo`'s stable
/// stage plans with.
pub fn robot_problem_scene(name: &str) -> Result<(StableScene, Problem)> {
    let mut s = load_scene(name)?;
    if s.pusher.kind != "diff-drive" {
        let (width, offset) = match robot_plate(name) {
            Some(p) => p,
            None => (PLATE_WIDTH, PLATE_OFFSET),
        };
        s.pusher.kind = "diff-drive".into();
        s.pusher.width = Some(width);
        s.pusher.depth = Some(offset + 0.04);
        s.pusher.axle_offset = Some(offset);
        s.pusher.plate_width = Some(width);
        s.pusher.min_turning_radius = None;
        if s.planner.grid_xy_frac.is_none() || PRESETS.contains(&name) {
            s.planner.grid_xy_frac = Some(ROBOT_GRID_XY_FRAC);
        }
    }
    let p = s
        .problem(CostOverride::default())
        .with_context(|| format!("robot problem {name} (its [stable] section)"))?;
    Ok((s, p))
}

/// The `[robot] front_plate` (width, offset) of the scene `name`, if it has one.
fn robot_plate(name: &str) -> Option<(f64, f64)> {
    let sc = if PRESETS.contains(&name) {
        pushbot_world::Scene::preset(name).ok()?
    } else {
        let text = std::fs::read_to_string(name).ok()?;
        pushbot_world::Scene::from_toml(&text, name).ok()?
    };
    sc.robot.front_plate.map(|f| (f.width, f.offset))
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

/// Least scale of the overhead camera's image, pixels per metre: a 5 cm marker is then 19 px
/// wide, which the detector reads through blur and noise.
pub const MIN_PX_PER_M: f64 = 380.0;

/// The overhead camera's image size for `table` (m) when the default 960 × 720 (16 px borders)
/// would show it at less than [`MIN_PX_PER_M`]: the default scaled up, to a multiple of 16.
pub fn camera_image(table: [f64; 2]) -> Option<[u32; 2]> {
    let (w, h) = (960.0, 720.0);
    let scale = ((w - 32.0) / table[0]).min((h - 32.0) / table[1]);
    if !(scale.is_finite() && scale > 0.0) || scale >= MIN_PX_PER_M {
        return None;
    }
    let k = MIN_PX_PER_M / scale;
    let up = |v: f64| ((v * k / 16.0).ceil() * 16.0) as u32;
    Some([up(w), up(h)])
}

/// The simulated scene of the problem: the same table and obstacles, the slider (object frame
/// at its centre of friction, marker `marker_id` on it), the robot with its plate at `start`.
pub fn sim_scene(
    s: &StableScene,
    p: &Problem,
    start: [f64; 3],
    marker_id: u32,
) -> Result<pushbot_world::Scene> {
    let mut t = format!(
        "name = \"{}\"\n[table]\nwidth = {}\nheight = {}\n[robot]\nstart = {{ x = {}, y = {}, theta = {} }}\nfront_plate = {{ width = {PLATE_WIDTH}, offset = {PLATE_OFFSET} }}\n",
        s.name, s.table[0], s.table[1], start[0], start[1], start[2]
    );
    // The overhead camera sees the whole table; on a large table (a scaled preset) its image
    // grows so the markers keep the scale they have on a small one.
    if let Some([w, h]) = camera_image(s.table) {
        t += &format!("[camera]\nwidth = {w}\nheight = {h}\n");
    }
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
    pushbot_world::Scene::from_toml(&t, &format!("stable scene {}", s.name))
        .map_err(|e| anyhow!("{e}"))
}

/// One pushing arc of the axle centre: a run of a plan's steps with one contact and one control.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PushArc {
    /// Contact (index into the problem's contacts) the robot pushes on.
    pub contact: usize,
    /// Distance driven along the heading, m.
    pub distance: f64,
    /// Turn, rad (counter-clockwise positive).
    pub turn: f64,
}

/// The plan as arcs of the axle centre: per run of steps with one contact and one control, the
/// distance driven (m, along the heading) and the turn (rad).
pub fn arcs(p: &Problem, plan: &Plan) -> Vec<PushArc> {
    let mut runs: Vec<(usize, PushArc)> = Vec::new();
    for st in &plan.steps {
        let (axle, heading) = robot_in_slider(p, st.contact);
        let xi = V3::new(st.twist[0], st.twist[1], st.twist[2]);
        let u = V2::new(xi.x - xi.z * axle.y, xi.y + xi.z * axle.x);
        let (d, phi) = (u.dot(&heading), xi.z);
        match runs.last_mut() {
            Some((k, a)) if *k == st.control && a.contact == st.contact => {
                a.distance += d;
                a.turn += phi;
            }
            _ => runs.push((
                st.control,
                PushArc {
                    contact: st.contact,
                    distance: d,
                    turn: phi,
                },
            )),
        }
    }
    runs.into_iter().map(|(_, a)| a).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The presets' own tables keep the default image; the scaled Fig. 13 (3.6 × 2.4 m) gets
    /// one that shows it at the least scale, and no larger than it needs.
    #[test]
    fn large_tables_get_a_larger_image_at_the_least_scale() {
        assert_eq!(camera_image([1.6, 1.2]), None);
        assert_eq!(
            camera_image([2.4, 1.6]),
            None,
            "Fig. 17 × 2 is seen at 387 px/m"
        );
        let [w, h] = camera_image([3.6, 2.4]).unwrap();
        let scale = ((f64::from(w) - 32.0) / 3.6).min((f64::from(h) - 32.0) / 2.4);
        assert!(
            (MIN_PX_PER_M..MIN_PX_PER_M + 10.0).contains(&scale),
            "{w} × {h}: {scale}"
        );
        assert!(w % 16 == 0 && h % 16 == 0);
    }
}
