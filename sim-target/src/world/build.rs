//! Setting up a [`World`]: the table and its walls, the robot's start, static obstacles and
//! objects to push, from code or from a scene.

use anyhow::{Result, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::geometry::Outline;
use crate::motor::Motor;
use crate::pushing::Slider;
use crate::robot::{Pose, wrap_angle};
use crate::scene::Scene;

use super::{Body, DEFAULT_LOAD, G, Hardware, Wall, World};

impl World {
    /// A robot at `start` on a `table` (width, height; origin at its lower-left corner).
    /// Fails if the table or the start pose are not sensible.
    pub fn new(
        table: (f64, f64),
        start: Pose,
        body: Body,
        hw: Hardware,
        seed: u64,
    ) -> Result<Self> {
        let (w, h) = table;
        let r = body.bumper_radius;
        if !(body.wheel_base > 0.0 && body.wheel_radius > 0.0 && r > 0.0) {
            bail!("robot dimensions must be positive: {body:?}");
        }
        if !(w.is_finite() && h.is_finite() && w > 2.0 * r && h > 2.0 * r) {
            bail!("table {w} m × {h} m must be finite and wider than the robot ({r} m radius)");
        }
        let (x, y) = (start.x, start.y);
        if !(start.theta.is_finite() && x >= r && x <= w - r && y >= r && y <= h - r) {
            bail!(
                "start pose ({x}, {y}, {}) must keep the robot (radius {r} m) on the {w} m × {h} m table",
                start.theta
            );
        }
        let shape = body.outline()?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let s = hw.motor_gain_spread.abs();
        let mut motor = || {
            let gain = if s > 0.0 {
                rng.random_range(1.0 - s..=1.0 + s)
            } else {
                1.0
            };
            Motor::new(hw.motor, gain)
        };
        let motors = [motor(), motor()];
        let walls = vec![
            Wall {
                normal: (1.0, 0.0),
                limit: w - r,
            },
            Wall {
                normal: (-1.0, 0.0),
                limit: -r,
            },
            Wall {
                normal: (0.0, 1.0),
                limit: h - r,
            },
            Wall {
                normal: (0.0, -1.0),
                limit: -r,
            },
        ];
        World {
            table,
            walls,
            body,
            hw,
            pose: Pose::new(x, y, wrap_angle(start.theta)),
            motors,
            slipping: [false; 2],
            pressed: 0,
            rng,
            obstacles: Vec::new(),
            objects: Vec::new(),
            shape,
            statics: Vec::new(),
            object_shapes: Vec::new(),
            contacts: Vec::new(),
            last: (Vec::new(), None),
        }
        .with_walls()
    }

    /// The four walls: half-planes beyond the table's edges. Fails if the robot's outline
    /// (its plate) starts beyond them.
    fn with_walls(mut self) -> Result<Self> {
        let (w, h) = self.table;
        let (inf, ninf) = (f64::INFINITY, f64::NEG_INFINITY);
        for (normal, at, bb) in [
            ([1.0, 0.0], Pose::new(0.0, 0.0, 0.0), [ninf, ninf, 0.0, inf]),
            ([-1.0, 0.0], Pose::new(w, 0.0, 0.0), [w, ninf, inf, inf]),
            ([0.0, 1.0], Pose::new(0.0, 0.0, 0.0), [ninf, ninf, inf, 0.0]),
            ([0.0, -1.0], Pose::new(0.0, h, 0.0), [ninf, h, inf, inf]),
        ] {
            self.statics.push((Outline::half_plane(normal), at, bb));
        }
        if self.robot_overlaps_statics() {
            bail!("the robot's outline at its start pose leaves the table");
        }
        Ok(self)
    }

    fn robot_overlaps_statics(&self) -> bool {
        self.statics
            .iter()
            .any(|(o, at, _)| self.shape.overlaps(&self.pose, o, at, 1e-12))
    }

    /// The world of a scene: its table, obstacles and objects, the robot at its start pose
    /// (with the scene's front plate if `body` has none).
    pub fn from_scene(scene: &Scene, mut body: Body, hw: Hardware, seed: u64) -> Result<Self> {
        if body.front_plate.is_none() {
            body.front_plate = scene.robot.front_plate;
        }
        let mut w = World::new(
            (scene.table.width, scene.table.height),
            scene.robot.start,
            body,
            hw,
            seed,
        )?;
        for o in &scene.obstacles {
            w.add_obstacle(o.outline.clone())?;
        }
        for o in &scene.objects {
            let load = o.support_friction * o.mass * G;
            w.add_object_with_load(&o.id, Slider::from_object(o), load)?;
        }
        Ok(w)
    }

    /// Add a static obstacle (table frame polygon, simple). Fails if it is not a usable
    /// polygon or overlaps the robot or an object.
    pub fn add_obstacle(&mut self, outline: Vec<[f64; 2]>) -> Result<()> {
        let shape = Outline::polygon(&outline)?;
        let mut bb = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for v in &outline {
            bb = [
                bb[0].min(v[0]),
                bb[1].min(v[1]),
                bb[2].max(v[0]),
                bb[3].max(v[1]),
            ];
        }
        let origin = Pose::default();
        if self.shape.overlaps(&self.pose, &shape, &origin, 1e-12) {
            bail!("an obstacle overlaps the robot's start pose");
        }
        for ((id, s), (o, _)) in self.objects.iter().zip(&self.object_shapes) {
            if o.overlaps(&s.pose, &shape, &origin, 1e-12) {
                bail!("an obstacle overlaps object {id:?}");
            }
        }
        self.obstacles.push(outline);
        self.statics.push((shape, origin, bb));
        Ok(())
    }

    /// Lift object `id` and put it down `by` (dx, dy in metres, dθ in radians, table frame)
    /// from where it is, as a hand would; whatever it then overlaps is pushed apart by the next
    /// steps. `false` when there is no such object.
    pub fn shift_object(&mut self, id: &str, by: [f64; 3]) -> bool {
        let Some((_, s)) = self.objects.iter_mut().find(|(o, _)| o == id) else {
            return false;
        };
        s.pose = Pose::new(
            s.pose.x + by[0],
            s.pose.y + by[1],
            wrap_angle(s.pose.theta + by[2]),
        );
        self.last = (Vec::new(), None);
        true
    }

    /// Add a pushable object with the default support-friction load ([`DEFAULT_LOAD`]).
    /// Fails if it overlaps the robot, an obstacle, another object or leaves the table.
    pub fn add_object(&mut self, id: &str, slider: Slider) -> Result<()> {
        self.add_object_with_load(id, slider, DEFAULT_LOAD)
    }

    /// Add a pushable object whose support friction is `load = μ_s·m·g` newtons (it sets how
    /// objects pushed together share the push). Fails if its outline is not a usable polygon,
    /// or it overlaps the robot, an obstacle, another object or leaves the table.
    pub fn add_object_with_load(&mut self, id: &str, slider: Slider, load: f64) -> Result<()> {
        if !(load.is_finite() && load > 0.0) {
            bail!("object {id:?}: the support-friction load must be positive");
        }
        if !(slider.c.is_finite() && slider.c > 0.0 && slider.mu.is_finite() && slider.mu >= 0.0) {
            bail!("object {id:?}: needs a positive limit-surface length and a friction ≥ 0");
        }
        let shape =
            Outline::polygon(&slider.outline).map_err(|e| anyhow::anyhow!("object {id:?}: {e}"))?;
        if shape.overlaps(&slider.pose, &self.shape, &self.pose, 1e-12) {
            bail!("object {id:?} overlaps the robot's start pose");
        }
        if self
            .statics
            .iter()
            .any(|(o, at, _)| shape.overlaps(&slider.pose, o, at, 1e-12))
        {
            bail!("object {id:?} overlaps an obstacle or leaves the table");
        }
        for ((other, s), (o, _)) in self.objects.iter().zip(&self.object_shapes) {
            if shape.overlaps(&slider.pose, o, &s.pose, 1e-12) {
                bail!("object {id:?} overlaps object {other:?}");
            }
        }
        self.objects.push((id.to_owned(), slider));
        self.object_shapes.push((shape, load));
        Ok(())
    }
}
