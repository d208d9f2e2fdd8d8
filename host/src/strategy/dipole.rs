//! The dipole-field baseline (Igarashi, Kamiyama & Inami, "A dipole field for object delivery
//! by pushing on a flat surface", ICRA 2010), as Lau, Mitani & Igarashi compare against it in
//! §V (Fig. 10–11).
//!
//! With o, r, g the object, robot and goal positions: x̂ = unit(g − o), ŷ = x̂ turned +90°,
//! û = unit(r − o), θ = angle(r − o) − angle(g − o), a = |∠ROG / ∠ORG| capped at 10 (1 when
//! either angle is 0). The robot follows
//! V = (cos²θ − a·sin²θ)·x̂ + (1 + a)·sinθ·cosθ·ŷ, and in front of the object (V·û > 0) the
//! component along û is removed so the robot goes around it. The robot spins toward V when its
//! heading is off by more than [`DipoleParams::spin_threshold`], otherwise drives forward
//! curving toward it.

use nalgebra::Vector2;

use super::sample::wrap_angle;

/// Parameters of the dipole controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DipoleParams {
    /// Heading error above which the robot spins in place, rad.
    pub spin_threshold: f64,
    /// Cap of the ratio a.
    pub a_max: f64,
    /// Forward speed while driving, m/s.
    pub speed: f64,
    /// Turn-rate gain while driving: ω = gain · heading error, rad/s per rad.
    pub turn_gain: f64,
}

impl Default for DipoleParams {
    fn default() -> Self {
        DipoleParams {
            spin_threshold: 0.2,
            a_max: 10.0,
            speed: 0.1,
            turn_gain: 3.0,
        }
    }
}

/// What the robot should do next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DipoleCommand {
    /// Spin in place by this angle, rad (counter-clockwise positive).
    Spin {
        /// Signed angle.
        angle: f64,
    },
    /// Drive forward at `v` while turning at `omega`.
    Drive {
        /// Forward speed, m/s.
        v: f64,
        /// Turn rate, rad/s.
        omega: f64,
    },
}

/// Unsigned angle between two vectors, [0, π].
fn angle_between(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    let c = a.perp(&b).atan2(a.dot(&b));
    c.abs()
}

/// The dipole field's direction at the robot, or `None` when robot, object or goal coincide.
pub fn field(
    o: Vector2<f64>,
    r: Vector2<f64>,
    g: Vector2<f64>,
    params: &DipoleParams,
) -> Option<Vector2<f64>> {
    let og = g - o;
    let or = r - o;
    if og.norm() < 1e-12 || or.norm() < 1e-12 {
        return None;
    }
    let x = og / og.norm();
    let y = Vector2::new(-x.y, x.x);
    let u = or / or.norm();
    let theta = wrap_angle(or.y.atan2(or.x) - og.y.atan2(og.x));
    let rog = angle_between(or, og);
    let org = angle_between(o - r, g - r);
    let a = if rog == 0.0 || org == 0.0 {
        1.0
    } else {
        (rog / org).abs().min(params.a_max)
    };
    let (s, c) = theta.sin_cos();
    let mut v = (c * c - a * s * s) * x + (1.0 + a) * s * c * y;
    let along = v.dot(&u);
    if along > 0.0 {
        v -= along * u;
    }
    (v.norm() > 1e-12).then_some(v)
}

/// The command for a robot at `robot` with heading `heading`.
pub fn command(
    o: Vector2<f64>,
    robot: Vector2<f64>,
    heading: f64,
    g: Vector2<f64>,
    params: &DipoleParams,
) -> Option<DipoleCommand> {
    let v = field(o, robot, g, params)?;
    let err = wrap_angle(v.y.atan2(v.x) - heading);
    Some(if err.abs() > params.spin_threshold {
        DipoleCommand::Spin { angle: err }
    } else {
        DipoleCommand::Drive {
            v: params.speed,
            omega: params.turn_gain * err,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vector2<f64> {
        Vector2::new(x, y)
    }

    #[test]
    fn behind_the_object_the_field_points_at_the_goal() {
        let p = DipoleParams::default();
        let f = field(v(0.0, 0.0), v(-0.1, 0.0), v(1.0, 0.0), &p).unwrap();
        assert!(f.x > 0.99 * f.norm() && f.y.abs() < 1e-9, "{f:?}");
        // Facing it: drive straight.
        assert_eq!(
            command(v(0.0, 0.0), v(-0.1, 0.0), 0.0, v(1.0, 0.0), &p),
            Some(DipoleCommand::Drive {
                v: p.speed,
                omega: 0.0
            })
        );
        // Facing away: spin by π (wrapped into (−π, π]).
        match command(
            v(0.0, 0.0),
            v(-0.1, 0.0),
            std::f64::consts::PI,
            v(1.0, 0.0),
            &p,
        ) {
            Some(DipoleCommand::Spin { angle }) => {
                assert!((angle.abs() - std::f64::consts::PI).abs() < 1e-9)
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn beside_the_object_the_robot_backs_around_it() {
        // θ = 90°: V = −a x̂ (away from the goal), which leads the robot behind the object.
        let p = DipoleParams::default();
        let o = v(0.0, 0.0);
        let r = v(0.0, 0.1);
        let g = v(1.0, 0.0);
        let f = field(o, r, g, &p).unwrap();
        // a = ∠ROG / ∠ORG = (π/2) / atan(10) (angle at R between RO and RG).
        let org = angle_between(o - r, g - r);
        let a = (std::f64::consts::FRAC_PI_2 / org).min(10.0);
        assert!((f - v(-a, 0.0)).norm() < 1e-9, "{f:?} vs a={a}");
    }

    #[test]
    fn in_front_of_the_object_the_robot_never_heads_into_it() {
        let p = DipoleParams::default();
        let o = v(0.0, 0.0);
        let g = v(1.0, 0.0);
        for i in -40..=40 {
            let ang = i as f64 * 0.03; // robot between object and goal side
            let r = o + 0.1 * v(ang.cos(), ang.sin());
            if let Some(f) = field(o, r, g, &p) {
                let u = (r - o).normalize();
                assert!(f.dot(&u) <= 1e-12, "at {ang}: {f:?} heads into the object");
            }
        }
    }

    #[test]
    fn the_field_is_mirror_symmetric_about_the_object_goal_line() {
        let p = DipoleParams::default();
        let o = v(0.2, 0.1);
        let g = v(1.0, 0.1);
        for (x, y) in [(0.1, 0.3), (0.5, 0.2), (-0.3, 0.05), (0.25, 0.4)] {
            let up = field(o, v(x, 0.1 + y), g, &p).unwrap();
            let down = field(o, v(x, 0.1 - y), g, &p).unwrap();
            assert!(
                (up.x - down.x).abs() < 1e-9 && (up.y + down.y).abs() < 1e-9,
                "{up:?} {down:?}"
            );
        }
    }

    #[test]
    fn degenerate_positions_give_no_direction() {
        let p = DipoleParams::default();
        assert!(field(v(0.0, 0.0), v(0.0, 0.0), v(1.0, 0.0), &p).is_none());
        assert!(field(v(0.0, 0.0), v(1.0, 0.0), v(0.0, 0.0), &p).is_none());
    }
}
