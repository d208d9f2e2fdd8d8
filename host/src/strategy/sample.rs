//! One push as a sample of the pushing strategy (Lau et al. §III-B, Fig. 2).
//!
//! A sample is (p_x, p_y, r_x, r_y, s_x, s_y, θ): the robot centre before the push (p), the
//! robot's displacement (r), the object's displacement (s), all in the object's frame at the
//! start of the push, and the object's change of heading θ.

/// A planar pose in table coordinates: the world crate's one pose.
pub use pushbot_world::Pose as Pose2;
pub use pushbot_world::wrap_angle;

/// One push: the paper's (p_x, p_y, r_x, r_y, s_x, s_y, θ), metres and radians, object frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Robot centre before the push.
    pub p: [f64; 2],
    /// Robot displacement.
    pub r: [f64; 2],
    /// Object displacement.
    pub s: [f64; 2],
    /// Object rotation.
    pub theta: f64,
}

impl Sample {
    /// The sample for a push observed as robot and object poses before and after.
    pub fn from_push(
        robot_before: Pose2,
        robot_after: Pose2,
        obj_before: Pose2,
        obj_after: Pose2,
    ) -> Sample {
        let p = obj_before.point_to_local(robot_before.position());
        let r = obj_before.vector_to_local(robot_after.position() - robot_before.position());
        let s = obj_before.vector_to_local(obj_after.position() - obj_before.position());
        Sample {
            p: [p.x, p.y],
            r: [r.x, r.y],
            s: [s.x, s.y],
            theta: wrap_angle(obj_after.theta - obj_before.theta),
        }
    }

    /// Whether every value is finite.
    pub fn is_finite(&self) -> bool {
        self.p
            .iter()
            .chain(&self.r)
            .chain(&self.s)
            .chain([&self.theta])
            .all(|v| v.is_finite())
    }

    /// The same push as the motion of the object's point `c` (object frame) rather than of its
    /// marker: `s` becomes that point's displacement, s + (R(θ) − I)·c, in the object's frame
    /// before the push; the robot's place and motion and the rotation stay.
    pub fn about(&self, c: [f64; 2]) -> Sample {
        let c = nalgebra::Vector2::new(c[0], c[1]);
        let swing = Pose2::new(0.0, 0.0, self.theta).vector_to_world(c) - c;
        Sample {
            s: [self.s[0] + swing.x, self.s[1] + swing.y],
            ..*self
        }
    }

    /// Length of the object's displacement.
    pub fn s_len(&self) -> f64 {
        self.s[0].hypot(self.s[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn push_is_expressed_in_the_object_frame() {
        // Object at (1, 1) facing table +y: its local x is table +y, its local y is table −x.
        // The robot at table (0.9, 1) is at local (0, 0.1); moving table +x is local −y.
        let obj0 = Pose2::new(1.0, 1.0, FRAC_PI_2);
        let obj1 = Pose2::new(1.05, 1.0, FRAC_PI_2 + 0.1);
        let r0 = Pose2::new(0.9, 1.0, 0.0);
        let r1 = Pose2::new(0.96, 1.0, 0.0);
        let s = Sample::from_push(r0, r1, obj0, obj1);
        assert!(
            (s.p[0] - 0.0).abs() < 1e-12 && (s.p[1] - 0.1).abs() < 1e-12,
            "{s:?}"
        );
        // Robot moved +x in the table = local −y.
        assert!(
            (s.r[0]).abs() < 1e-12 && (s.r[1] + 0.06).abs() < 1e-12,
            "{s:?}"
        );
        assert!((s.s[1] + 0.05).abs() < 1e-12);
        assert!((s.theta - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_push_about_a_point_is_that_points_displacement() {
        // The point c (object frame) measured in the table before and after the push.
        let c = Vector2::new(0.04, -0.06);
        let obj0 = Pose2::new(1.0, 0.5, 0.7);
        let obj1 = Pose2::new(1.03, 0.52, 1.1);
        let s = Sample::from_push(
            Pose2::new(0.9, 0.5, 0.0),
            Pose2::new(0.95, 0.5, 0.0),
            obj0,
            obj1,
        );
        let moved = obj0.vector_to_local(obj1.point_to_world(c) - obj0.point_to_world(c));
        let a = s.about([c.x, c.y]);
        assert!((a.s[0] - moved.x).abs() < 1e-12 && (a.s[1] - moved.y).abs() < 1e-12);
        // The marker moved differently: the rotation swings c round it.
        assert!(
            (a.s[0] - s.s[0]).hypot(a.s[1] - s.s[1]) > 0.02,
            "{a:?} {s:?}"
        );
        assert_eq!((a.p, a.r, a.theta), (s.p, s.r, s.theta));
        assert_eq!(s.about([0.0, 0.0]), s);
    }

    #[test]
    fn wrap_angle_stays_in_half_open_interval() {
        use std::f64::consts::PI;
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.5) - 0.5).abs() < 1e-12);
        assert!((wrap_angle(-0.5 - 2.0 * PI) + 0.5).abs() < 1e-12);
    }
}
