//! The geometric checks of a scene, after its fields parse and are in range: the robot (with its
//! front plate) starts on the table and clear of obstacles and objects, and no object overlaps
//! an obstacle or another object, every goal puts its object on the table and clear of the
//! obstacles, and every named position (an object's start, in the layouts that have them) is
//! on the table and clear of the obstacles. Shapes and overlaps come from parry2d ([`crate::geometry`]);
//! touching is allowed, overlapping by more than 1 nm is not.

use super::error::{Invalid, Seg, invalid};
use super::{Scene, placed};
use crate::body::Body;
use crate::geometry::Outline;
use crate::pose::Pose;

/// Overlaps deeper than this (m) are refused; touching is fine.
const TOUCH: f64 = 1e-9;

impl Scene {
    /// The checks that need the shapes (run after the per-field checks, so every polygon here
    /// is simple and every pose finite).
    pub(super) fn check_geometry(&self) -> Result<(), Invalid> {
        use Seg::{Index, Key};
        let fine = self
            .obstacles
            .iter()
            .map(|o| ("obstacles", &o.outline))
            .chain(self.objects.iter().map(|o| ("objects", &o.outline)))
            .enumerate();
        for (k, (what, outline)) in fine {
            if outline.len() > crate::simplify::MOST_VERTICES {
                let i = if what == "objects" {
                    k - self.obstacles.len()
                } else {
                    k
                };
                return Err(invalid(
                    vec![Key(what), Index(i), Key("outline")],
                    format!(
                        "keeps {} vertices even simplified within {:.1} mm; at most {} can be \
                         used (export it coarser)",
                        outline.len(),
                        crate::simplify::OUTLINE_TOLERANCE * 1e3,
                        crate::simplify::MOST_VERTICES
                    ),
                ));
            }
        }
        let r = &self.robot;
        if let Some(p) = r.front_plate
            && !p.valid()
        {
            return Err(invalid(
                vec![Key("robot"), Key("front_plate")],
                format!(
                    "needs a positive width and its face ahead of the axle by more than its \
                     thickness ({} m)",
                    crate::body::FrontPlate::THICKNESS
                ),
            ));
        }
        let body = Body {
            wheel_base: r.wheel_base,
            wheel_radius: r.wheel_radius,
            bumper_radius: r.bumper_radius,
            front_plate: r.front_plate,
        };
        let start = vec![Key("robot"), Key("start")];
        let robot = body
            .outline()
            .map_err(|e| invalid(vec![Key("robot")], e.to_string()))?;
        let (w, h) = (self.table.width, self.table.height);
        let origin = Pose::default();
        let walls = [
            ([1.0, 0.0], Pose::new(0.0, 0.0, 0.0)),
            ([-1.0, 0.0], Pose::new(w, 0.0, 0.0)),
            ([0.0, 1.0], Pose::new(0.0, 0.0, 0.0)),
            ([0.0, -1.0], Pose::new(0.0, h, 0.0)),
        ];
        if walls
            .iter()
            .any(|(n, at)| robot.overlaps(&r.start, &Outline::half_plane(*n), at, TOUCH))
        {
            return Err(invalid(
                start,
                "the robot's outline (bumper and front plate) must start on the table",
            ));
        }
        let mut obstacles = Vec::with_capacity(self.obstacles.len());
        for (i, o) in self.obstacles.iter().enumerate() {
            let shape = Outline::polygon(&o.outline).map_err(|e| {
                invalid(
                    vec![Key("obstacles"), Index(i), Key("outline")],
                    e.to_string(),
                )
            })?;
            if robot.overlaps(&r.start, &shape, &origin, TOUCH) {
                return Err(invalid(
                    start,
                    format!("the robot starts inside obstacles[{i}]"),
                ));
            }
            obstacles.push(shape);
        }
        let mut objects: Vec<Outline> = Vec::with_capacity(self.objects.len());
        for (i, o) in self.objects.iter().enumerate() {
            let at = |k| vec![Key("objects"), Index(i), Key(k)];
            let shape =
                Outline::polygon(&o.outline).map_err(|e| invalid(at("outline"), e.to_string()))?;
            for (j, obstacle) in obstacles.iter().enumerate() {
                if shape.overlaps(&o.pose, obstacle, &origin, TOUCH) {
                    return Err(invalid(
                        at("pose"),
                        format!("the object overlaps obstacles[{j}]"),
                    ));
                }
            }
            for (j, other) in objects.iter().enumerate() {
                if shape.overlaps(&o.pose, other, &self.objects[j].pose, TOUCH) {
                    return Err(invalid(
                        at("pose"),
                        format!(
                            "the object overlaps objects[{j}] ({:?})",
                            self.objects[j].id
                        ),
                    ));
                }
            }
            if shape.overlaps(&o.pose, &robot, &r.start, TOUCH) {
                return Err(invalid(
                    at("pose"),
                    "the object overlaps the robot's start pose",
                ));
            }
            objects.push(shape);
        }
        let on_table = |outline: &[[f64; 2]], at: &Pose| {
            placed(outline, at)
                .iter()
                .all(|v| v[0] >= 0.0 && v[0] <= w && v[1] >= 0.0 && v[1] <= h)
        };
        for (i, g) in self.goals.iter().enumerate() {
            let Some(k) = self.objects.iter().position(|o| o.id == g.object) else {
                continue;
            };
            let what = format!(
                "goals[{i}] (object {:?}): the goal pose puts the object",
                g.object
            );
            let at = vec![Key("goals"), Index(i), Key("pose")];
            if !on_table(&self.objects[k].outline, &g.pose) {
                return Err(invalid(at, format!("{what} off the table")));
            }
            for (j, obstacle) in obstacles.iter().enumerate() {
                if objects[k].overlaps(&g.pose, obstacle, &origin, TOUCH) {
                    return Err(invalid(at, format!("{what} inside obstacles[{j}]")));
                }
            }
        }
        // A named position is a start of the scene's object (the layouts with positions have
        // one): its outline there must be on the table and clear of obstacles; with several
        // objects, the position's point.
        for (i, p) in self.positions.iter().enumerate() {
            let at = vec![Key("positions"), Index(i), Key("pose")];
            let what = format!("positions[{i}] ({:?})", p.name);
            let (off, inside) = match (self.objects.as_slice(), objects.as_slice()) {
                ([o], [shape]) => (
                    !on_table(&o.outline, &p.pose),
                    obstacles
                        .iter()
                        .position(|ob| shape.overlaps(&p.pose, ob, &origin, TOUCH)),
                ),
                _ => (
                    !(p.pose.x >= 0.0 && p.pose.x <= w && p.pose.y >= 0.0 && p.pose.y <= h),
                    obstacles
                        .iter()
                        .position(|ob| ob.contains(&origin, [p.pose.x, p.pose.y])),
                ),
            };
            if off {
                return Err(invalid(
                    at,
                    format!("{what}: the position is off the table"),
                ));
            }
            if let Some(j) = inside {
                return Err(invalid(
                    at,
                    format!("{what}: the position is inside obstacles[{j}]"),
                ));
            }
        }
        Ok(())
    }
}
