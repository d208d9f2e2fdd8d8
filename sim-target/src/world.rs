//! The world of the first cut: a robot on a table bounded by walls.
//!
//! Each step the motors drive the wheels as if they rolled (the wheels carry the body's mass),
//! the body moves along the arc of the resulting twist, and then the walls act: the motion
//! component into a wall the bumper touches is removed, so nothing ever penetrates a wall (the
//! body may slide along it). A wheel whose rolling speed no longer matches the body's motion is
//! held by its traction: it stalls (turns with the body) while the motor torque needed to hold it
//! is within traction, and otherwise slips, spinning on the table against kinetic friction. A
//! bumper switch closes while a wall presses on the bumper within its sector, i.e. while the
//! motion into that wall is being blocked.

use anyhow::{Result, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::motor::{Motor, MotorParams, advance_with_friction};
use crate::pushing::{ContactMode, Slider, closest_boundary_point, point_in_polygon};
use crate::robot::{Pose, arc_displacement, switches_for_angle, twist_from_wheels, wrap_angle};
use crate::scene::{Scene, placed, segments_intersect};

/// Standard gravity, m/s².
const G: f64 = 9.81;

/// The robot's body dimensions, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Distance between the wheel contact points.
    pub wheel_base: f64,
    /// Wheel radius.
    pub wheel_radius: f64,
    /// Bumper radius around the axle centre.
    pub bumper_radius: f64,
}

impl Body {
    /// The dimensions in a firmware geometry.
    pub fn from_geometry(g: &pushbot_protocol::Geometry) -> Self {
        Body {
            wheel_base: f64::from(g.wheel_base),
            wheel_radius: f64::from(g.wheel_radius),
            bumper_radius: f64::from(g.bumper_radius),
        }
    }
}

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
        Ok(World {
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
        })
    }

    /// The world of a scene: its table, obstacles and objects, the robot at its start pose.
    pub fn from_scene(scene: &Scene, body: Body, hw: Hardware, seed: u64) -> Result<Self> {
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
            w.add_object(&o.id, Slider::from_object(o))?;
        }
        Ok(w)
    }

    /// Add a static obstacle (table frame polygon). Fails if it overlaps the robot.
    pub fn add_obstacle(&mut self, outline: Vec<[f64; 2]>) -> Result<()> {
        if outline.len() < 3 {
            bail!("an obstacle needs at least 3 vertices");
        }
        if circle_overlaps(
            &outline,
            [self.pose.x, self.pose.y],
            self.body.bumper_radius,
        ) {
            bail!("an obstacle overlaps the robot's start pose");
        }
        self.obstacles.push(outline);
        Ok(())
    }

    /// Add a pushable object. Fails if it overlaps the robot, an obstacle, another object or
    /// leaves the table.
    pub fn add_object(&mut self, id: &str, slider: Slider) -> Result<()> {
        let outline = placed(&slider.outline, &slider.pose);
        if circle_overlaps(
            &outline,
            [self.pose.x, self.pose.y],
            self.body.bumper_radius,
        ) {
            bail!("object {id:?} overlaps the robot's start pose");
        }
        if self.polygon_blocked(&outline, None) {
            bail!("object {id:?} overlaps an obstacle, another object or the table's edge");
        }
        self.objects.push((id.to_owned(), slider));
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

    /// Whether a placed polygon leaves the table or overlaps an obstacle or another object
    /// (other than the object with index `skip`).
    fn polygon_blocked(&self, outline: &[[f64; 2]], skip: Option<usize>) -> bool {
        self.statically_blocked(outline)
            || !self
                .overlapping_objects(outline, &[skip.unwrap_or(usize::MAX)])
                .is_empty()
    }

    /// Whether a placed polygon leaves the table or overlaps an obstacle.
    fn statically_blocked(&self, outline: &[[f64; 2]]) -> bool {
        let (w, h) = self.table;
        outline
            .iter()
            .any(|v| v[0] < 0.0 || v[0] > w || v[1] < 0.0 || v[1] > h)
            || self.obstacles.iter().any(|o| polygons_overlap(o, outline))
    }

    /// Indices of the objects (except those in `skip`) a placed polygon overlaps.
    fn overlapping_objects(&self, outline: &[[f64; 2]], skip: &[usize]) -> Vec<usize> {
        self.objects
            .iter()
            .enumerate()
            .filter(|(k, (_, s))| {
                !skip.contains(k) && polygons_overlap(&placed(&s.outline, &s.pose), outline)
            })
            .map(|(k, _)| k)
            .collect()
    }

    /// Object `k` moved from `before` into object `j`: let `k` push `j` quasi-statically at the
    /// mean of `k`'s vertices that entered `j` (a point pusher moving with `k`), then back `j`
    /// out of `k`. Returns false (and restores `j`) if `j` cannot move there.
    ///
    /// Simplification: `k`'s own motion is computed as if pushed alone; `j` follows it.
    fn chain_push(&mut self, k: usize, before: &Slider, j: usize) -> bool {
        let saved_j = self.objects[j].1.clone();
        let after = self.objects[k].1.clone();
        let inside: Vec<[f64; 2]> = placed(&after.outline, &after.pose)
            .into_iter()
            .filter(|v| point_in_polygon(saved_j.to_local(*v), &saved_j.outline))
            .collect();
        if inside.is_empty() {
            return false;
        }
        let m = inside.len() as f64;
        let c_after = [
            inside.iter().map(|v| v[0]).sum::<f64>() / m,
            inside.iter().map(|v| v[1]).sum::<f64>() / m,
        ];
        let c_before = before.to_table(after.to_local(c_after));
        self.objects[j].1.push(c_before, c_after, 0.0, 5e-4);
        // Back j out of k: move it so that k's deepest vertex inside it is on its boundary.
        for _ in 0..4 {
            let sj = &self.objects[j].1;
            let mut deepest: Option<([f64; 2], f64)> = None;
            for v in placed(&after.outline, &after.pose) {
                let local = sj.to_local(v);
                if point_in_polygon(local, &sj.outline) {
                    let (cp, d) = closest_boundary_point(local, &sj.outline);
                    if deepest.is_none_or(|(_, dd)| d > dd) {
                        let shift = sj.to_table(local);
                        let cpt = sj.to_table(cp);
                        deepest = Some(([shift[0] - cpt[0], shift[1] - cpt[1]], d));
                    }
                }
            }
            let Some((shift, _)) = deepest else { break };
            let sj = &mut self.objects[j].1;
            // A hair further, so that the two outlines do not stay crossed by rounding.
            sj.pose.x += shift[0] * (1.0 + 1e-9);
            sj.pose.y += shift[1] * (1.0 + 1e-9);
        }
        let moved_j = placed(&self.objects[j].1.outline, &self.objects[j].1.pose);
        if self.statically_blocked(&moved_j)
            || !self.overlapping_objects(&moved_j, &[j, k]).is_empty()
        {
            self.objects[j].1 = saved_j;
            return false;
        }
        true
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

        // 2. The walls remove the motion into them.
        let (mut ax, mut ay) = (dx, dy);
        let mut pressed = 0u8;
        let mut blocked = false;
        for w in &self.walls {
            let (nx, ny) = w.normal;
            let reach = nx * (self.pose.x + ax) + ny * (self.pose.y + ay);
            if reach > w.limit {
                // Remove exactly the excess along the normal: the centre ends on the limit.
                let excess = reach - w.limit;
                ax -= excess * nx;
                ay -= excess * ny;
                blocked = true;
                pressed |= switches_for_angle(ny.atan2(nx) - self.pose.theta);
            }
        }

        // 2b. Static obstacles, like walls: the motion into them is removed.
        let r_b = self.body.bumper_radius;
        for obs in &self.obstacles {
            let q = [self.pose.x + ax, self.pose.y + ay];
            if let Some((n, depth)) = circle_penetration(obs, q, r_b) {
                ax -= n[0] * depth;
                ay -= n[1] * depth;
                blocked = true;
                pressed |= switches_for_angle(n[1].atan2(n[0]) - self.pose.theta);
            }
        }

        // 2c. Objects: pushed quasi-statically; one that would run into a wall, an obstacle
        // or another object stays put and blocks the robot instead.
        let from = [self.pose.x, self.pose.y];
        for k in 0..self.objects.len() {
            let to = [self.pose.x + ax, self.pose.y + ay];
            if self.objects[k].1.gap(to, r_b) > 0.0 {
                continue;
            }
            let saved = self.objects[k].1.clone();
            let mode = self.objects[k].1.push(from, to, r_b, 5e-4);
            let moved = placed(&self.objects[k].1.outline, &self.objects[k].1.pose);
            let stuck = if self.statically_blocked(&moved) {
                true
            } else {
                match self.overlapping_objects(&moved, &[k])[..] {
                    [] => false,
                    [j] => !self.chain_push(k, &saved, j),
                    _ => true,
                }
            };
            if stuck {
                self.objects[k].1 = saved;
            } else if matches!(mode, Some(ContactMode::Sticking | ContactMode::Sliding)) {
                let s = &self.objects[k].1;
                let (cp, _) = closest_boundary_point(s.to_local(to), &s.outline);
                let c = s.to_table(cp);
                pressed |= switches_for_angle((c[1] - to[1]).atan2(c[0] - to[0]) - self.pose.theta);
                continue;
            }
            // Blocked (or a grazing contact): the robot does not enter the object.
            let placed_now = placed(&self.objects[k].1.outline, &self.objects[k].1.pose);
            if let Some((n, depth)) = circle_penetration(&placed_now, to, r_b) {
                ax -= n[0] * depth;
                ay -= n[1] * depth;
                blocked = true;
                pressed |= switches_for_angle(n[1].atan2(n[0]) - self.pose.theta);
            }
        }
        self.pressed = pressed;

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

/// If a circle (centre `q`, radius `r`) overlaps a polygon: the unit normal from the centre
/// towards the polygon and the depth to back out by along it.
fn circle_penetration(outline: &[[f64; 2]], q: [f64; 2], r: f64) -> Option<([f64; 2], f64)> {
    let (cp, d) = closest_boundary_point(q, outline);
    let inside = point_in_polygon(q, outline);
    if !inside && d >= r {
        return None;
    }
    let mut n = [cp[0] - q[0], cp[1] - q[1]];
    let len = (n[0] * n[0] + n[1] * n[1]).sqrt();
    if len < 1e-15 {
        return None;
    }
    n = [n[0] / len, n[1] / len];
    if inside {
        // The centre is inside: the boundary point lies behind the motion; back out through it.
        n = [-n[0], -n[1]];
        return Some((n, d + r));
    }
    Some((n, r - d))
}

fn circle_overlaps(outline: &[[f64; 2]], q: [f64; 2], r: f64) -> bool {
    circle_penetration(outline, q, r).is_some_and(|(_, depth)| depth > 1e-12)
}

/// Whether two simple polygons overlap (edges cross, or one contains the other).
pub fn polygons_overlap(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    let (na, nb) = (a.len(), b.len());
    for i in 0..na {
        for j in 0..nb {
            if segments_intersect(a[i], a[(i + 1) % na], b[j], b[(j + 1) % nb]) {
                return true;
            }
        }
    }
    (!b.is_empty() && point_in_polygon(b[0], a)) || (!a.is_empty() && point_in_polygon(a[0], b))
}
