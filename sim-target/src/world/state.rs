//! Reading a [`World`]: its bodies, the robot's pose, wheels and bumper, and clearances.

use crate::geometry::Outline;
use crate::pushing::Slider;
use crate::robot::Pose;

use super::{Body, World};

impl World {
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
}
