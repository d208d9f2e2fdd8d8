//! Advancing a [`World`] by one step: the motors drive the wheels, every contact acts at once
//! through the quasi-static solver ([`crate::quasistatic`]), wheels stall or slip, and the
//! bumper switches close where something presses.

use rand::Rng;

use crate::geometry::ContactPoint;
use crate::motor::advance_with_friction;
use crate::quasistatic::{BodyRef, Drive, Mobile, Row, solve};
use crate::robot::{Pose, arc_displacement, switches_for_angle, twist_from_wheels, wrap_angle};

use super::{FrontPlate, G, OBJECT_FRICTION, WALL_FRICTION, World};

impl World {
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
            rim[i] = rolling[i] * r * (1.0 + noise + self.hw.wheel_slip[i]);
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
