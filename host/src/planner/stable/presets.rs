//! Scenes for stable pushing and the built-in presets shaped after Lynch & Mason (1996) §4.4:
//! Fig. 13 (omnidirectional robot, one edge), Fig. 15 (car-like robot), Figs. 16 and 17 (robot
//! arm, two edges, costs `a=1 b=5 c=0` and `a=0 b=1 c=10`) and Fig. 18 (cluttered), with goal
//! regions as in the paper (±25 % / ±10 % of the slider length, ±2°). The slider is shaped after
//! Fig. 12: a box with one corner cut, pushed on two opposite edges.
//!
//! Every scene is one of the shared format (`pushbot_world::Scene`) with a `[stable]`
//! section (`pushbot_world::scene::stable`), read through [`from_shared`] into the planner's own
//! description ([`Scene`]): the presets, and scene files (which need a `[table]`).

use anyhow::{Context, anyhow, bail};

use super::collision::{Obstacle, World};
use super::pusher::{Pusher, PusherKind};
use super::{Params, Pose, Problem};
use crate::mechanics::{Slider, V2, centroid};

/// A stable-pushing task as the planner takes it, from a shared-format scene by [`from_shared`].
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Table width and height (m).
    pub table: [f64; 2],
    /// Pusher–slider friction coefficient.
    pub mu: f64,
    /// Obstacles (world frame), convex or not.
    pub obstacles: Vec<ObstacleSpec>,
    /// Objects; the task's object is pushed, the others are static obstacles at `pose`.
    pub objects: Vec<ObjectSpec>,
    /// What to do.
    pub task: TaskSpec,
    /// Who pushes.
    pub pusher: PusherSpec,
    /// Planner settings.
    pub planner: PlannerSpec,
    /// Whether the pushed object's outline was given clockwise and stored counter-clockwise
    /// (the world crate's `normalise_ccw`): its edge `i` as given is edge `n − 1 − i` of the
    /// stored outline. `task.edges` and `task.start_edge` are stored-outline numbers; plans
    /// name edges as given ([`super::ContactModel::label`]).
    pub outline_reversed: bool,
}

/// An obstacle.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleSpec {
    /// Vertices of a simple polygon, counter-clockwise.
    pub polygon: Vec<[f64; 2]>,
}

/// An object.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSpec {
    /// Identifier.
    pub id: String,
    /// Outline in the object frame.
    pub polygon: Vec<[f64; 2]>,
    /// Centre of friction in the object frame (default: area centroid).
    pub centre_of_friction: Option<[f64; 2]>,
    /// Pose `[x, y, θ°]` for objects that are not pushed (default: not placed).
    pub pose: Option<[f64; 3]>,
}

/// The task.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSpec {
    /// Id of the object to push.
    pub object: String,
    /// Start `[x, y, θ°]` of the centre of friction.
    pub start: [f64; 3],
    /// Goal `[x, y, θ°]`.
    pub goal: [f64; 3],
    /// Edges of the object that may be pushed.
    pub edges: Vec<usize>,
    /// Edge the pusher starts at (default: any, chosen for free).
    pub start_edge: Option<usize>,
    /// Goal half-width in x and y as a fraction of the object length.
    pub goal_xy_frac: f64,
    /// Goal half-width in θ (degrees).
    pub goal_theta_deg: f64,
}

/// The pusher.
#[derive(Debug, Clone, PartialEq)]
pub struct PusherSpec {
    /// `arm`, `omni`, `car` or `diff-drive`.
    pub kind: String,
    /// Robot width (m).
    pub width: Option<f64>,
    /// Robot depth behind its front (m).
    pub depth: Option<f64>,
    /// Front plate to wheel axle (m).
    pub axle_offset: Option<f64>,
    /// Width of a flat front plate (bumper); default: as wide as the robot.
    pub plate_width: Option<f64>,
    /// Car: minimum turning radius (m).
    pub min_turning_radius: Option<f64>,
}

/// Planner settings (all optional).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlannerSpec {
    /// Cost per step.
    pub a: Option<u32>,
    /// Cost per control change.
    pub b: Option<u32>,
    /// Cost per contact change: integer or "inf".
    pub c: Option<CostSpec>,
    /// Step length as a fraction of the object length.
    pub step_frac: Option<f64>,
    /// Grid cell in x, y as a fraction of the step.
    pub grid_xy_frac: Option<f64>,
    /// Grid cell in θ (degrees).
    pub grid_theta_deg: Option<f64>,
    /// MAXCOST.
    pub max_cost: Option<u32>,
    /// Node limit.
    pub max_nodes: Option<usize>,
    /// Radius around the goal (fraction of the object length) inside which step and grid are
    /// refined (§4.5); 0 = off.
    pub fine_radius_frac: Option<f64>,
    /// Refinement factor for step and grid near the goal.
    pub fine_factor: Option<f64>,
}

/// A contact-change cost: a number or "inf".
#[derive(Debug, Clone, PartialEq)]
pub enum CostSpec {
    /// Finite.
    Int(u32),
    /// "inf".
    Word(String),
}

impl CostSpec {
    /// `None` for ∞.
    pub fn value(&self) -> anyhow::Result<Option<u32>> {
        match self {
            CostSpec::Int(v) => Ok(Some(*v)),
            CostSpec::Word(w) if w == "inf" => Ok(None),
            CostSpec::Word(w) => {
                bail!("stable.planner.c: expected an integer or \"inf\", got {w:?}")
            }
        }
    }
}

/// Names of the built-in presets: scenes of the shared scene format (`pushbot_world::scene`) with a `[stable]`
/// section.
pub const PRESETS: [&str; 5] = ["fig13", "fig15", "fig16", "fig17", "fig18"];

/// The paper's planning times (s) for the presets, in `PRESETS` order (§4.4).
pub const PAPER_SECONDS: [f64; 5] = [7.0, 1.0, 35.0, 2.0, 43.0];

/// The stable-pushing task of a scene's TOML text (the shared format with a `[stable]`
/// section); `file` names the source in errors, which give its line and field.
pub fn scene_from_toml(text: &str, file: &str) -> anyhow::Result<Scene> {
    // Parsed once (a fine outline makes a scene file large); the old format is told apart
    // only when the scene does not parse.
    let (shared, notes) = pushbot_world::Scene::from_toml_noted(text, file).map_err(|e| {
        if text
            .parse::<toml::Table>()
            .is_ok_and(|t| !t.get("table").is_some_and(|v| v.is_table()))
        {
            anyhow!(
                "{file}: not a scene: it has no [table] section (the shared scene format needs \
                 [table], and [stable] for the stable-pushing planner; the old stable-only \
                 format with `table = [w, h]`, [task] and [pusher] is no longer read: see \
                 docs/src/scenes.md)"
            )
        } else {
            anyhow!("{e}")
        }
    })?;
    let mut s = from_shared(&shared).with_context(|| format!("scene file {file}"))?;
    let object = shared.objects.iter().position(|o| o.id == s.task.object);
    s.outline_reversed = object.is_some_and(|i| {
        let field = format!("objects[{i}].outline");
        notes
            .iter()
            .any(|n| n.field == field && n.message.contains("clockwise"))
    });
    Ok(s)
}

/// Load a scene by preset name or from a file in the shared scene format.
pub fn load_scene(name_or_path: &str) -> anyhow::Result<Scene> {
    if PRESETS.contains(&name_or_path) {
        let shared = pushbot_world::Scene::preset(name_or_path).map_err(|e| anyhow!("{e}"))?;
        return from_shared(&shared).with_context(|| format!("preset {name_or_path}"));
    }
    let text = std::fs::read_to_string(name_or_path).with_context(|| {
        format!(
            "scene {name_or_path:?} is neither a preset ({}) nor a readable file",
            PRESETS.join(", ")
        )
    })?;
    scene_from_toml(&text, name_or_path)
}

/// A stable-pushing scene from a scene in the shared format (`pushbot_world::Scene`) with a
/// `[stable]` section: the table, the obstacles (exact: a non-convex one as its convex parts), the pushed object
/// (its centre of friction from its support distribution, its start from its pose, its goal
/// from the scene's goal for it, `μ` from its `pusher_friction`), the other objects as static
/// obstacles, and the pusher and planner settings of `[stable]`; a differential drive takes
/// its plate from the robot's `front_plate`.
pub fn from_shared(sc: &pushbot_world::Scene) -> anyhow::Result<Scene> {
    use pushbot_world::scene::Support;
    use pushbot_world::scene::stable::StableCost;
    let st = sc
        .stable
        .as_ref()
        .ok_or_else(|| anyhow!("stable: the scene has no [stable] section"))?;
    let obj = sc
        .object(&st.object)
        .ok_or_else(|| anyhow!("stable.object: no object with id {:?}", st.object))?;
    let outline = pts(&obj.outline);
    let cof = match &obj.support {
        Support::Uniform => centroid(&outline),
        Support::Points { points, weights } => {
            let w: Vec<f64> = match weights {
                Some(w) if w.len() == points.len() => w.clone(),
                _ => vec![1.0; points.len()],
            };
            let total: f64 = w.iter().sum();
            if points.is_empty() || total.is_nan() || total <= 0.0 {
                bail!("objects[{}].support: no weight", st.object);
            }
            points
                .iter()
                .zip(&w)
                .map(|(p, w)| V2::new(p[0], p[1]) * *w)
                .sum::<V2>()
                / total
        }
    };
    // The centre of friction's pose on the table, θ in degrees, from the object frame's pose.
    let cof_pose = |p: &pushbot_world::Pose| {
        let q = Pose::new(p.x, p.y, p.theta).apply(cof);
        [q.x, q.y, p.theta.to_degrees()]
    };
    let goal = sc
        .goals
        .iter()
        .find(|g| g.object == st.object)
        .ok_or_else(|| anyhow!("goals: no goal for the stable object {:?}", st.object))?;
    let plate = sc.robot.front_plate;
    let p = &st.pusher;
    let diff = p.kind == "diff-drive";
    if diff && plate.is_none() && p.plate_width.is_none() {
        // Stable pushing (§2–3) needs the pusher to hold the edge in a line contact. A round
        // bumper touches a flat edge at one point, and that point slides along the bumper's
        // arc as the robot turns against the slider: not a line contact, and not the plate
        // this planner would otherwise assume.
        bail!(
            "stable.pusher: a diff-drive pushes with the robot, and this robot has a round bumper \
             (no [robot] front_plate): a round bumper touches an edge at one point that moves on \
             its arc, which stable pushing's line contact does not model; give the robot a \
             front_plate = {{ width, offset }} or the pusher a plate_width"
        );
    }
    let pl = &st.planner;
    Ok(Scene {
        name: sc.name.clone(),
        description: String::new(),
        table: [sc.table.width, sc.table.height],
        mu: obj.pusher_friction,
        obstacles: sc
            .obstacles
            .iter()
            .map(|o| ObstacleSpec {
                polygon: o.outline.clone(),
            })
            .collect(),
        objects: sc
            .objects
            .iter()
            .map(|o| ObjectSpec {
                id: o.id.clone(),
                polygon: o.outline.clone(),
                centre_of_friction: (o.id == st.object).then_some([cof.x, cof.y]),
                pose: (o.id != st.object).then_some([
                    o.pose.x,
                    o.pose.y,
                    o.pose.theta.to_degrees(),
                ]),
            })
            .collect(),
        task: TaskSpec {
            object: st.object.clone(),
            start: cof_pose(&obj.pose),
            goal: cof_pose(&goal.pose),
            edges: st.edges.clone(),
            start_edge: st.start_edge,
            goal_xy_frac: st.goal_xy_frac,
            goal_theta_deg: st.goal_theta_deg,
        },
        pusher: PusherSpec {
            kind: p.kind.clone(),
            width: p.width,
            depth: p.depth,
            axle_offset: p.axle_offset.or(plate.filter(|_| diff).map(|f| f.offset)),
            plate_width: p.plate_width.or(plate.filter(|_| diff).map(|f| f.width)),
            min_turning_radius: p.min_turning_radius,
        },
        planner: PlannerSpec {
            a: pl.a,
            b: pl.b,
            c: pl.c.as_ref().map(|c| match c {
                StableCost::Int(v) => CostSpec::Int(*v),
                StableCost::Word(w) => CostSpec::Word(w.clone()),
            }),
            step_frac: pl.step_frac,
            grid_xy_frac: pl.grid_xy_frac,
            grid_theta_deg: pl.grid_theta_deg,
            max_cost: pl.max_cost,
            max_nodes: pl.max_nodes,
            fine_radius_frac: pl.fine_radius_frac,
            fine_factor: pl.fine_factor,
        },
        outline_reversed: false,
    })
    .and_then(|s| {
        validate(&s)?;
        Ok(s)
    })
}

fn finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn validate(s: &Scene) -> anyhow::Result<()> {
    if !(s.table[0] > 0.0 && s.table[1] > 0.0 && finite(&s.table)) {
        bail!("table: width and height must be finite and > 0");
    }
    if !(s.mu >= 0.0 && s.mu.is_finite()) {
        bail!(
            "objects[].pusher_friction (μ): must be finite and >= 0, got {}",
            s.mu
        );
    }
    for (i, o) in s.obstacles.iter().enumerate() {
        if o.polygon.len() < 3 || !o.polygon.iter().all(|p| finite(p)) {
            bail!("obstacles[{i}].outline: needs at least 3 finite points");
        }
        if Obstacle::parts(&pts(&o.polygon)).is_none() {
            bail!("obstacles[{i}].outline: degenerate polygon");
        }
    }
    for (i, o) in s.objects.iter().enumerate() {
        if o.polygon.len() < 3 || !o.polygon.iter().all(|p| finite(p)) {
            bail!("objects[{i}].outline: needs at least 3 finite points");
        }
    }
    if !s.objects.iter().any(|o| o.id == s.task.object) {
        bail!("stable.object: no object with id {:?}", s.task.object);
    }
    if !finite(&s.task.start) || !finite(&s.task.goal) {
        bail!("the stable object's pose and goal: must be finite");
    }
    if s.task.edges.is_empty() {
        bail!("stable.edges: at least one pushing edge is needed");
    }
    if let Some(e) = s.task.start_edge
        && !s.task.edges.contains(&e)
    {
        bail!("stable.start_edge: the start edge is not in stable.edges");
    }
    if !(s.task.goal_xy_frac > 0.0 && s.task.goal_theta_deg > 0.0) {
        bail!("stable.goal_xy_frac and stable.goal_theta_deg: must be > 0");
    }
    let p = &s.planner;
    for (name, v) in [
        ("step_frac", p.step_frac),
        ("grid_xy_frac", p.grid_xy_frac),
        ("grid_theta_deg", p.grid_theta_deg),
        ("fine_factor", p.fine_factor),
    ] {
        if let Some(v) = v
            && !(v > 0.0 && v.is_finite())
        {
            bail!("stable.planner.{name}: must be finite and > 0, got {v}");
        }
    }
    if let Some(c) = &p.c {
        c.value()?;
    }
    if let Some(v) = p.fine_radius_frac
        && !(v >= 0.0 && v.is_finite())
    {
        bail!("stable.planner.fine_radius_frac: must be finite and >= 0, got {v}");
    }
    if p.max_cost.is_some_and(|m| m > 1_000_000) {
        bail!("stable.planner.max_cost: at most 1000000");
    }
    match s.pusher.kind.as_str() {
        "arm" | "omni" | "car" | "diff-drive" => {}
        k => bail!("stable.pusher.kind: expected arm, omni, car or diff-drive, got {k:?}"),
    }
    if s.pusher.kind == "car" && s.pusher.min_turning_radius.is_none() {
        bail!("stable.pusher.min_turning_radius: required for a car");
    }
    for (name, v) in [
        ("width", s.pusher.width),
        ("depth", s.pusher.depth),
        ("axle_offset", s.pusher.axle_offset),
        ("plate_width", s.pusher.plate_width),
        ("min_turning_radius", s.pusher.min_turning_radius),
    ] {
        if let Some(v) = v
            && !(v >= 0.0 && v.is_finite())
        {
            bail!("stable.pusher.{name}: must be finite and >= 0, got {v}");
        }
    }
    Ok(())
}

fn pts(p: &[[f64; 2]]) -> Vec<V2> {
    p.iter().map(|q| V2::new(q[0], q[1])).collect()
}

/// Overrides of the scene's planner costs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CostOverride {
    /// `a`.
    pub a: Option<u32>,
    /// `b`.
    pub b: Option<u32>,
    /// `c`: `Some(None)` = ∞.
    pub c: Option<Option<u32>>,
}

impl Scene {
    /// The slider of object `id` (slider frame at its centre of friction).
    pub fn slider(&self, id: &str) -> anyhow::Result<Slider> {
        let o = self
            .objects
            .iter()
            .find(|o| o.id == id)
            .ok_or_else(|| anyhow!("no object with id {id:?}"))?;
        let outline = pts(&o.polygon);
        let cof = o
            .centre_of_friction
            .map(|c| V2::new(c[0], c[1]))
            .unwrap_or_else(|| centroid(&outline));
        Slider::new(&outline, cof).map_err(|e| anyhow!("objects[{id}]: {e}"))
    }

    /// The pusher.
    pub fn pusher(&self) -> Pusher {
        let p = &self.pusher;
        let w = p.width.unwrap_or(0.1);
        let d = p.depth.unwrap_or(0.1);
        let axle = p.axle_offset.unwrap_or(d / 2.0);
        let plate = p.plate_width.or(Some(w));
        match p.kind.as_str() {
            "omni" => Pusher::boxed(PusherKind::Omni, w, d, d / 2.0, plate),
            "car" => Pusher::boxed(
                PusherKind::Car {
                    min_turning_radius: p.min_turning_radius.unwrap_or(0.0),
                },
                w,
                d,
                axle,
                plate,
            ),
            "diff-drive" => Pusher::boxed(PusherKind::DiffDrive, w, d, axle, plate),
            _ => Pusher::arm(),
        }
    }

    /// The pushed object's edge `e` (stored outline) as the scene numbers it.
    pub fn edge_label(&self, e: usize) -> anyhow::Result<usize> {
        let n = self
            .objects
            .iter()
            .find(|o| o.id == self.task.object)
            .map_or(0, |o| o.polygon.len());
        Ok(if self.outline_reversed && e < n {
            pushbot_world::polygon::reversed_edge(e, n)
        } else {
            e
        })
    }

    /// Build the planning problem.
    pub fn problem(&self, costs: CostOverride) -> anyhow::Result<Problem> {
        let slider = self.slider(&self.task.object)?;
        for (i, &e) in self.task.edges.iter().enumerate() {
            let label = self.edge_label(e)?;
            match slider.is_hull_edge(e) {
                Err(err) => bail!("stable.edges[{i}]: edge {label}: {err}"),
                Ok(false) => bail!(
                    "stable.edges[{i}]: edge {label} is not on the convex hull of the object: a \
                     flat pusher cannot lie on it"
                ),
                Ok(true) => {}
            }
        }
        let len = slider.length();
        let pl = &self.planner;
        let step = pl.step_frac.unwrap_or(0.2) * len;
        let c = match costs.c {
            Some(c) => c,
            None => {
                pl.c.as_ref()
                    .map(|c| c.value())
                    .transpose()?
                    .unwrap_or(Some(0))
            }
        };
        let params = Params {
            a: costs.a.or(pl.a).unwrap_or(1),
            b: costs.b.or(pl.b).unwrap_or(5),
            c,
            step,
            grid_xy: step * pl.grid_xy_frac.unwrap_or(0.5),
            grid_theta: pl.grid_theta_deg.unwrap_or(2.0).to_radians(),
            goal_xy: self.task.goal_xy_frac * len,
            goal_theta: self.task.goal_theta_deg.to_radians(),
            max_cost: pl.max_cost.unwrap_or(3000),
            max_nodes: pl.max_nodes.unwrap_or(200_000),
            fine_radius: pl.fine_radius_frac.unwrap_or(0.0) * len,
            fine_factor: pl.fine_factor.unwrap_or(1.0).max(1.0),
            weight: 1.0,
        };
        let mut obstacles = Vec::new();
        let mut names = Vec::new();
        for (i, o) in self.obstacles.iter().enumerate() {
            let parts = Obstacle::parts(&pts(&o.polygon))
                .ok_or_else(|| anyhow!("obstacles[{i}]: degenerate or not simple"))?;
            names.extend(std::iter::repeat_n(format!("obstacles[{i}]"), parts.len()));
            obstacles.extend(parts);
        }
        for o in &self.objects {
            if o.id == self.task.object {
                continue;
            }
            if let Some(pose) = o.pose {
                let s = self.slider(&o.id)?;
                let q = Pose::new(pose[0], pose[1], pose[2].to_radians());
                let w: Vec<V2> = s.vertices.iter().map(|v| q.apply(*v)).collect();
                let parts =
                    Obstacle::parts(&w).ok_or_else(|| anyhow!("objects[{}]: degenerate", o.id))?;
                names.extend(std::iter::repeat_n(
                    format!("object {:?}", o.id),
                    parts.len(),
                ));
                obstacles.extend(parts);
            }
        }
        let mut world = World::new(self.table[0], self.table[1], obstacles);
        world.names.truncate(world.n_walls);
        world.names.extend(names);
        let t = &self.task;
        let start = Pose::new(t.start[0], t.start[1], t.start[2].to_radians());
        let goal = Pose::new(t.goal[0], t.goal[1], t.goal[2].to_radians());
        let mut problem = Problem::new(
            world,
            slider,
            self.mu,
            self.pusher(),
            &t.edges,
            start,
            goal,
            params,
        )
        .map_err(|e| anyhow!("stable.edges: {e}"))?;
        problem.start_contact = t
            .start_edge
            .and_then(|e| t.edges.iter().position(|&x| x == e));
        for cm in problem.contacts.iter_mut() {
            cm.label = self.edge_label(cm.edge)?;
        }
        for (i, cm) in problem.contacts.iter().enumerate() {
            if cm.usable.controls.is_empty() {
                bail!(
                    "stable.edges[{i}]: edge {} has no usable stable push for this pusher",
                    cm.label
                );
            }
        }
        if !problem
            .contacts
            .iter()
            .any(|cm| cm.body.free_at(&problem.world, &start))
        {
            bail!(
                "stable: the slider (at its start pose) and the pusher collide with an obstacle or wall"
            );
        }
        Ok(problem)
    }
}
