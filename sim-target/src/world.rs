//! The world: a robot on a table bounded by walls, with static obstacles and objects to push.
//!
//! Each step the motors drive the wheels as if they rolled (the wheels carry the body's mass)
//! and the body would move along the arc of the resulting twist. Then every contact acts at
//! once ([`crate::quasistatic`]): the robot pushes objects quasi-statically (the ellipsoidal
//! limit surface of Lynch & Mason §3), objects push each other and rest against walls and
//! obstacles, and the robot's motion is cut back to what the world makes room for, so nothing
//! interpenetrates beyond the step's linearised rotation (a corner at radius r turning by dθ
//! in one step may overshoot by r·dθ²/2, under a micrometre here). Shapes and contact points
//! come from `parry2d` ([`crate::geometry`]).
//! A wheel whose rolling speed no longer matches the body's motion is held by its traction: it
//! stalls (turns with the body) while the motor torque needed to hold it is within traction,
//! and otherwise slips, spinning on the table against kinetic friction. A bumper switch closes
//! while something presses on the bumper within its sector: on the round bumper by the angle
//! of the press, on a flat front plate ([`FrontPlate`]) by where along the plate it presses.

use anyhow::{Result, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::geometry::{ContactPoint, Outline};
use crate::motor::{Motor, MotorParams, advance_with_friction};
use crate::pushing::Slider;
use crate::quasistatic::{BodyRef, Drive, Mobile, Row, solve};
use crate::robot::{Pose, arc_displacement, switches_for_angle, twist_from_wheels, wrap_angle};
use crate::scene::Scene;

/// Standard gravity, m/s².
const G: f64 = 9.81;

pub use pushbot_world::body::{Body, FrontPlate};

/// The robot's body dimensions in a firmware geometry (no front plate).
pub fn body_from_geometry(g: &pushbot_protocol::Geometry) -> Body {
    Body {
        wheel_base: f64::from(g.wheel_base),
        wheel_radius: f64::from(g.wheel_radius),
        bumper_radius: f64::from(g.bumper_radius),
        front_plate: None,
    }
}

/// Coulomb coefficient between two objects.
pub const OBJECT_FRICTION: f64 = 0.3;
/// Coulomb coefficient between an object and a wall or obstacle.
pub const WALL_FRICTION: f64 = 0.2;
/// Support-friction load `μ_s·m·g` (N) of objects added without one ([`World::add_object`]).
pub const DEFAULT_LOAD: f64 = 0.7;

/// The physical model's constants and noise levels (all noise is drawn from the seed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hardware {
    /// The nominal motor.
    pub motor: MotorParams,
    /// Each motor's gain is drawn uniformly from `1 ± motor_gain_spread`.
    pub motor_gain_spread: f64,
    /// Robot mass, kg.
    pub mass_kg: f64,
    /// Share of the weight on each drive wheel (the rest is on the caster).
    pub drive_wheel_load: f64,
    /// Static wheel–table friction coefficient (kinetic is 90 % of it).
    pub traction_mu: f64,
    /// Each step each wheel's rim speed over the ground is off by a relative error drawn
    /// uniformly from ±`slip_noise` (small random slip that averages out).
    pub slip_noise: f64,
    /// Probability that one encoder reading is off by ±1 count.
    pub encoder_jitter: f64,
    /// Longest bumper-switch bounce after a change, µs.
    pub bounce_us: u64,
}

impl Default for Hardware {
    fn default() -> Self {
        Hardware {
            motor: MotorParams::default(),
            motor_gain_spread: 0.05,
            mass_kg: 0.25,
            drive_wheel_load: 0.4,
            traction_mu: 1.0,
            slip_noise: 0.01,
            encoder_jitter: 1e-4,
            bounce_us: 2_000,
        }
    }
}

/// A wall: the robot's centre `c` must keep `normal·c ≤ limit` (normal of unit length, pointing
/// from the robot into the wall).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Wall {
    normal: (f64, f64),
    limit: f64,
}

/// A robot on a walled table.
#[derive(Clone, Debug)]
pub struct World {
    table: (f64, f64),
    walls: Vec<Wall>,
    body: Body,
    hw: Hardware,
    pose: Pose,
    motors: [Motor; 2],
    slipping: [bool; 2],
    pressed: u8,
    rng: ChaCha8Rng,
    obstacles: Vec<Vec<[f64; 2]>>,
    objects: Vec<(String, Slider)>,
    /// The robot's outline, robot frame.
    shape: Outline,
    /// Walls (half-planes beyond the table's edges) and obstacles: outline, pose, bounding box.
    statics: Vec<(Outline, Pose, [f64; 4])>,
    /// Each object's outline (object frame) and support-friction load μ_s·m·g, N.
    object_shapes: Vec<(Outline, f64)>,
    /// Scratch: contacts of the step.
    contacts: Vec<ContactPoint>,
    /// The last step's rows (bodies of each) and solution, to warm-start the next solve.
    last: (
        Vec<(BodyRef, BodyRef)>,
        Option<crate::quasistatic::Solution>,
    ),
}

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

    /// The objects: id and slider (pose, outline, COF, …).
    pub fn objects(&self) -> &[(String, Slider)] {
        &self.objects
    }

    /// The static obstacles.
    pub fn obstacles(&self) -> &[Vec<[f64; 2]>] {
        &self.obstacles
    }

    /// The robot's outline (robot frame; place it at [`World::pose`]).
    pub fn robot_outline(&self) -> &Outline {
        &self.shape
    }

    /// Object `k`'s outline (object frame; place it at its slider's pose).
    pub fn object_outline(&self, k: usize) -> Option<&Outline> {
        self.object_shapes.get(k).map(|(o, _)| o)
    }

    /// The deepest interpenetration between any two bodies (robot, objects, walls,
    /// obstacles), m; 0 when nothing overlaps.
    pub fn max_penetration(&self) -> f64 {
        let mut worst = 0.0f64;
        for (k, ((_, s), (o, _))) in self.objects.iter().zip(&self.object_shapes).enumerate() {
            worst = worst.max(self.shape.depth(&self.pose, o, &s.pose));
            for (st, at, _) in &self.statics {
                worst = worst.max(o.depth(&s.pose, st, at));
            }
            for ((_, s2), (o2, _)) in self.objects.iter().zip(&self.object_shapes).skip(k + 1) {
                worst = worst.max(o.depth(&s.pose, o2, &s2.pose));
            }
        }
        for (st, at, _) in &self.statics {
            worst = worst.max(self.shape.depth(&self.pose, st, at));
        }
        worst
    }

    /// Gather the contacts closer than `prediction` as solver rows: the robot at `robot` with
    /// the walls, obstacles and objects, and, for the objects the robot may move (those it
    /// touches, and those they touch, and so on), theirs. Objects out of reach of that chain
    /// cannot move this step and take no part.
    fn rows(&mut self, robot: &Pose, prediction: f64) -> Vec<Row> {
        let mut rows = Vec::new();
        let near = |bb: &[f64; 4], p: &Pose, r: f64| {
            p.x + r + prediction >= bb[0]
                && p.x - r - prediction <= bb[2]
                && p.y + r + prediction >= bb[1]
                && p.y - r - prediction <= bb[3]
        };
        let push = |rows: &mut Vec<Row>, cs: &mut Vec<ContactPoint>, a, b, mu| {
            let any = !cs.is_empty();
            for c in cs.drain(..) {
                rows.push(Row {
                    a,
                    b,
                    pa: c.pa,
                    pb: c.pb,
                    n: c.normal,
                    gap: c.dist,
                    mu,
                });
            }
            any
        };
        let mut cs = std::mem::take(&mut self.contacts);
        let r_robot = self.shape.radius();
        for (st, at, bb) in &self.statics {
            if near(bb, robot, r_robot) {
                self.shape.contacts(robot, st, at, prediction, &mut cs);
                push(&mut rows, &mut cs, BodyRef::Robot, BodyRef::Static, 0.0);
            }
        }
        let n = self.objects.len();
        let mut state = vec![0u8; n]; // 0 out of reach, 1 reached, 2 done
        let mut queue = Vec::new();
        for (k, ((_, s), (o, _))) in self.objects.iter().zip(&self.object_shapes).enumerate() {
            self.shape.contacts(robot, o, &s.pose, prediction, &mut cs);
            if push(&mut rows, &mut cs, BodyRef::Robot, BodyRef::Object(k), s.mu) {
                state[k] = 1;
                queue.push(k);
            }
        }
        while let Some(k) = queue.pop() {
            if state[k] == 2 {
                continue;
            }
            state[k] = 2;
            let (s, o) = (&self.objects[k].1, &self.object_shapes[k].0);
            for (st, at, bb) in &self.statics {
                if near(bb, &s.pose, o.radius()) {
                    o.contacts(&s.pose, st, at, prediction, &mut cs);
                    let (a, b) = (BodyRef::Object(k), BodyRef::Static);
                    push(&mut rows, &mut cs, a, b, WALL_FRICTION);
                }
            }
            for (j, st) in state.iter_mut().enumerate() {
                if j == k || *st == 2 {
                    continue;
                }
                let (s2, o2) = (&self.objects[j].1, &self.object_shapes[j].0);
                o.contacts(&s.pose, o2, &s2.pose, prediction, &mut cs);
                let (a, b) = (BodyRef::Object(k), BodyRef::Object(j));
                if push(&mut rows, &mut cs, a, b, OBJECT_FRICTION) && *st == 0 {
                    *st = 1;
                    queue.push(j);
                }
            }
        }
        self.contacts = cs;
        rows
    }

    fn mobiles(&self) -> Vec<Mobile> {
        self.objects
            .iter()
            .zip(&self.object_shapes)
            .map(|((_, s), (_, load))| Mobile {
                cof: s.cof_on_table(),
                c: s.c,
                s: 1.0 / load,
            })
            .collect()
    }

    /// Move the objects by the solve's displacements (COF, table frame).
    fn move_objects(&mut self, moves: &[[f64; 3]]) {
        for ((_, s), m) in self.objects.iter_mut().zip(moves) {
            if m == &[0.0; 3] {
                continue;
            }
            let cof = s.cof_on_table();
            let theta = s.pose.theta + m[2];
            let (sn, cs) = theta.sin_cos();
            let off = [cs * s.cof[0] - sn * s.cof[1], sn * s.cof[0] + cs * s.cof[1]];
            s.pose = Pose::new(
                cof[0] + m[0] - off[0],
                cof[1] + m[1] - off[1],
                wrap_angle(theta),
            );
        }
    }

    /// The robot would move by `(dx, dy, dth)`: let every contact act (see [`crate::quasistatic`]),
    /// move the objects, and return the robot's feasible motion, whether it was cut back, and
    /// set the bumper switches.
    fn resolve_contacts(&mut self, dx: f64, dy: f64, dth: f64) -> (f64, f64, f64, bool) {
        let reach = (dx * dx + dy * dy).sqrt() + dth.abs() * self.shape.radius();
        let prediction = 2.0 * reach + 1e-4;
        let pose = self.pose;
        let rows = self.rows(&pose, prediction);
        if rows.is_empty() {
            self.pressed = 0;
            return (dx, dy, dth, false);
        }
        let mobiles = self.mobiles();
        let drive = Drive {
            centre: [pose.x, pose.y],
            d: [dx, dy],
            dth,
        };
        let same = self.last.0.len() == rows.len()
            && self.last.0.iter().zip(&rows).all(|(p, r)| *p == (r.a, r.b));
        let sol = solve(
            &mobiles,
            &rows,
            &drive,
            self.last.1.as_ref().filter(|_| same),
        );
        self.last.0.clear();
        self.last.0.extend(rows.iter().map(|r| (r.a, r.b)));
        self.last.1 = Some(sol.clone());
        self.move_objects(&sol.moves);
        let k = sol.scale;
        let (ax, ay, dth2) = (k * dx, k * dy, k * dth);
        // Second-order corrections: the linearised step may leave a body a hair inside
        // something (an object turned). Push it back out; here the robot is a very stiff
        // mobile body too, so that an object wedged between it and a wall can push it back.
        let (mut ax, mut ay, mut dth2) = (ax, ay, dth2);
        let mut after = Pose::new(pose.x + ax, pose.y + ay, wrap_angle(pose.theta + dth2));
        // Translations keep linearised gaps exact or open them (a disc sliding past a corner);
        // only turning bodies (objects, or a robot that is not round) can close one.
        let turned = sol.moves.iter().any(|m| m[2] != 0.0)
            || (self.body.front_plate.is_some() && dth2 != 0.0);
        for _ in 0..if turned { 4 } else { 0 } {
            let mut fix = self.rows(&after, 1e-6);
            if fix.iter().all(|r| r.gap >= -1e-12) {
                break;
            }
            let mut m = self.mobiles();
            let robot = m.len();
            let stiff = m.iter().map(|b| b.s).fold(f64::INFINITY, f64::min) * 1e-2;
            m.push(Mobile {
                cof: [after.x, after.y],
                c: self.shape.radius(),
                s: if stiff.is_finite() { stiff } else { 1e-3 },
            });
            for r in &mut fix {
                for b in [&mut r.a, &mut r.b] {
                    if *b == BodyRef::Robot {
                        *b = BodyRef::Object(robot);
                    }
                }
            }
            let s = crate::quasistatic::solve(&m, &fix, &Drive::default(), None);
            self.move_objects(&s.moves[..robot]);
            let [rx, ry, rth] = s.moves[robot];
            ax += rx;
            ay += ry;
            dth2 += rth;
            after = Pose::new(pose.x + ax, pose.y + ay, wrap_angle(pose.theta + dth2));
        }
        self.pressed = self.presses(&rows, &sol, &drive, &after);
        (ax, ay, dth2, k < 1.0 - 1e-12)
    }

    /// Which bumper switches the step's contacts close: those of the robot's contacts that
    /// carry force, or that the commanded motion drives into while touching.
    fn presses(
        &self,
        rows: &[Row],
        sol: &crate::quasistatic::Solution,
        drive: &Drive,
        after: &Pose,
    ) -> u8 {
        let mut bits = 0;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let (sn, cs) = after.theta.sin_cos();
        for (i, r) in rows.iter().enumerate() {
            if r.a != BodyRef::Robot {
                continue;
            }
            let u = [
                drive.d[0] - drive.dth * (r.pa[1] - drive.centre[1]),
                drive.d[1] + drive.dth * (r.pa[0] - drive.centre[0]),
            ];
            let into = r.n[0] * u[0] + r.n[1] * u[1];
            let closes = r.gap - into <= 1e-9 && into > 0.0;
            if !(sol.normal[i] > 0.0 || closes) {
                continue;
            }
            // The press point relative to the robot, robot frame.
            let rel = [r.pa[0] - drive.centre[0], r.pa[1] - drive.centre[1]];
            let local = [cs * rel[0] + sn * rel[1], -sn * rel[0] + cs * rel[1]];
            match self.body.front_plate {
                Some(p) if local[0] >= p.offset - FrontPlate::THICKNESS - 1e-9 => {
                    lo = lo.min(local[1]);
                    hi = hi.max(local[1]);
                }
                _ => bits |= switches_for_angle(r.n[1].atan2(r.n[0]) - after.theta),
            }
        }
        if let Some(p) = self.body.front_plate
            && lo <= hi
        {
            bits |= p.switches(lo, hi);
        }
        bits
    }

    /// Table width and height, m.
    pub fn table(&self) -> (f64, f64) {
        self.table
    }

    /// The robot's dimensions.
    pub fn body(&self) -> Body {
        self.body
    }

    /// The true pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Bumper switches pressed after the last step (bits as the firmware reads them).
    pub fn pressed(&self) -> u8 {
        self.pressed
    }

    /// Wheel speeds `[left, right]`, rad/s.
    pub fn wheel_speeds(&self) -> [f64; 2] {
        [self.motors[0].omega, self.motors[1].omega]
    }

    /// Cumulative wheel angles `[left, right]`, rad (what the encoders measure).
    pub fn wheel_angles(&self) -> [f64; 2] {
        [self.motors[0].angle, self.motors[1].angle]
    }

    /// Whether each wheel is slipping on the table.
    pub fn slipping(&self) -> [bool; 2] {
        self.slipping
    }

    /// Distance from the robot's bumper to the nearest wall, m (0 when touching).
    pub fn wall_clearance(&self) -> f64 {
        self.walls
            .iter()
            .map(|w| w.limit - (w.normal.0 * self.pose.x + w.normal.1 * self.pose.y))
            .fold(f64::INFINITY, f64::min)
    }

    /// Advance `dt` seconds with the motors at `duty` `[left, right]` (clamped to ±1).
    pub fn step(&mut self, duty: [f32; 2], dt: f64) {
        let r = self.body.wheel_radius;
        let b = self.body.wheel_base;
        let coulomb = self.hw.motor.coulomb_nm;
        let j_motor = self.hw.motor.inertia;
        // Rolling: each wheel also carries half the body's mass.
        let j_roll = j_motor + self.hw.mass_kg / 2.0 * r * r;

        // 1. The wheels as if they rolled.
        let mut rolling = [0.0; 2];
        for (i, m) in self.motors.iter().enumerate() {
            let tau = m.drive_torque(duty[i], m.omega);
            rolling[i] = if self.slipping[i] {
                m.omega
            } else {
                advance_with_friction(m.omega, tau, coulomb, j_roll, dt)
            };
        }
        let mut rim = [0.0; 2];
        for i in 0..2 {
            let noise = if self.hw.slip_noise > 0.0 {
                self.rng
                    .random_range(-self.hw.slip_noise..=self.hw.slip_noise)
            } else {
                0.0
            };
            rim[i] = rolling[i] * r * (1.0 + noise);
        }
        let (v, omega) = twist_from_wheels(rim, b);
        let (dx, dy, dth) = arc_displacement(self.pose.theta, v, omega, dt);

        // 2. Walls, obstacles and objects: one quasi-static solve with every contact.
        let (ax, ay, dth, blocked) = self.resolve_contacts(dx, dy, dth);
        let r_b = self.body.bumper_radius;

        // 3. Wheels against the body's actual motion: roll, stall or slip.
        let mut ground = rolling;
        if blocked {
            let mid = self.pose.theta + dth / 2.0;
            let v_actual = (ax * mid.cos() + ay * mid.sin()) / dt;
            let w_actual = dth / dt;
            ground = [
                (v_actual - w_actual * b / 2.0) / r,
                (v_actual + w_actual * b / 2.0) / r,
            ];
        }
        let traction = self.hw.traction_mu * self.hw.drive_wheel_load * self.hw.mass_kg * G * r;
        for i in 0..2 {
            let m = &mut self.motors[i];
            let differs = (rolling[i] - ground[i]).abs() > 1e-9;
            if !differs && !self.slipping[i] {
                m.omega = rolling[i];
            } else if !self.slipping[i] {
                // Can traction hold the wheel at the ground speed?
                let hold = m.drive_torque(duty[i], ground[i]);
                if hold.abs() <= traction + coulomb {
                    m.omega = ground[i];
                } else {
                    self.slipping[i] = true;
                }
            }
            if self.slipping[i] {
                // Spinning on the table: kinetic traction opposes the slip.
                let slip = m.omega - ground[i];
                let tau = m.drive_torque(duty[i], m.omega) - 0.9 * traction.copysign(slip);
                let next = advance_with_friction(m.omega, tau, coulomb, j_motor, dt);
                if (next - ground[i]).signum() != slip.signum() || slip.abs() < 1e-9 {
                    m.omega = ground[i];
                    self.slipping[i] = false;
                } else {
                    m.omega = next;
                }
            }
            m.integrate_angle(dt);
        }

        // 4. The body moves, and never leaves the table (an obstacle's or object's correction
        // cannot push it through a wall).
        let (w, h) = self.table;
        self.pose.x = (self.pose.x + ax).clamp(r_b, w - r_b);
        self.pose.y = (self.pose.y + ay).clamp(r_b, h - r_b);
        self.pose.theta = wrap_angle(self.pose.theta + dth);
    }
}

/// Whether two simple polygons (table frame) overlap by more than a touch (more than 1 nm;
/// parry2d contacts between their convex parts). Unusable polygons count as overlapping
/// nothing.
pub fn polygons_overlap(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    match (Outline::polygon(a), Outline::polygon(b)) {
        (Ok(a), Ok(b)) => a.overlaps(&Pose::default(), &b, &Pose::default(), 1e-9),
        _ => false,
    }
}

#[cfg(test)]
mod reference_robot {
    /// The scene format's default robot (in `pushbot-world`, which knows neither the firmware
    /// nor the motor model) is the firmware's reference geometry with the default motor.
    #[test]
    fn scene_default_robot_is_the_firmware_and_motor_default() {
        let spec = crate::scene::RobotSpec::default();
        let g = pushbot_firmware::RobotParams::default().geometry;
        let m = crate::motor::MotorParams::default();
        assert_eq!(spec.bumper_radius, f64::from(g.bumper_radius));
        assert_eq!(spec.wheel_base, f64::from(g.wheel_base));
        assert_eq!(spec.wheel_radius, f64::from(g.wheel_radius));
        assert_eq!(spec.encoder_cpr, g.encoder_cpr);
        assert_eq!(spec.no_load_speed, m.no_load_speed());
        assert_eq!(spec.stall_torque, m.stall_torque());
    }
}
