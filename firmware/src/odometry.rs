//! Differential-drive odometry from encoder counts.
//!
//! Each step turns the wrap-safe count differences of the two wheels into the arc the axle
//! centre travelled (length `ds`, turn `dθ`) and integrates it exactly along that arc (an
//! arc of constant curvature is what a differential drive describes between two samples when
//! the wheel speeds are constant).

use core::f32::consts::PI;

use pushbot_protocol::{Geometry, Pose};

/// Wrap an angle to (−π, π]. Non-finite input comes back unchanged.
pub fn wrap_angle(theta: f32) -> f32 {
    if !theta.is_finite() {
        return theta;
    }
    let two_pi = 2.0 * PI;
    let mut t = theta - two_pi * libm::roundf(theta / two_pi);
    // `t` is now in [−π, π] up to rounding; fold the ends onto the half-open interval.
    if t <= -PI {
        t += two_pi;
    }
    if t > PI {
        t -= two_pi;
    }
    t
}

/// Difference of two readings of a wrapping i32 counter: correct across the wrap as long as
/// the true difference fits in an i32.
pub fn count_delta(now: i32, before: i32) -> i32 {
    now.wrapping_sub(before)
}

/// The odometry integrator: the pose of the axle centre in the odometry frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Odometry {
    pose: Pose,
    metres_per_count: f32,
    wheel_base: f32,
}

impl Odometry {
    /// Odometry at pose zero for a robot of this geometry.
    pub fn new(geometry: &Geometry) -> Self {
        let cpr = geometry.encoder_cpr.max(1) as f32;
        Odometry {
            pose: Pose::default(),
            metres_per_count: 2.0 * PI * geometry.wheel_radius / cpr,
            wheel_base: geometry.wheel_base,
        }
    }

    /// Metres of wheel travel per encoder count.
    pub fn metres_per_count(&self) -> f32 {
        self.metres_per_count
    }

    /// The current pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Set the pose (heading wrapped to (−π, π]).
    pub fn reset(&mut self, pose: Pose) {
        self.pose = Pose {
            theta: wrap_angle(pose.theta),
            ..pose
        };
    }

    /// Advance by the count differences `[left, right]` of one step.
    pub fn update(&mut self, delta_counts: [i32; 2]) {
        let dl = delta_counts[0] as f32 * self.metres_per_count;
        let dr = delta_counts[1] as f32 * self.metres_per_count;
        let ds = 0.5 * (dl + dr);
        let dtheta = if self.wheel_base > 0.0 {
            (dr - dl) / self.wheel_base
        } else {
            0.0
        };
        let Pose { x, y, theta } = self.pose;
        let (nx, ny) = if libm::fabsf(dtheta) < 1e-6 {
            // Straight (to first order): midpoint heading.
            let mid = theta + 0.5 * dtheta;
            (x + ds * libm::cosf(mid), y + ds * libm::sinf(mid))
        } else {
            // Exact arc of radius ds/dθ.
            let r = ds / dtheta;
            let t1 = theta + dtheta;
            (
                x + r * (libm::sinf(t1) - libm::sinf(theta)),
                y - r * (libm::cosf(t1) - libm::cosf(theta)),
            )
        };
        self.pose = Pose {
            x: nx,
            y: ny,
            theta: wrap_angle(theta + dtheta),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> Geometry {
        crate::RobotParams::default().geometry
    }

    #[test]
    fn wrap_angle_is_half_open() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-6);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-5);
        for i in -1000..1000 {
            let t = i as f32 * 0.037;
            let w = wrap_angle(t);
            assert!(w > -PI && w <= PI, "{t} -> {w}");
            // Same direction as the input.
            assert!((libm::sinf(w) - libm::sinf(t)).abs() < 1e-4);
            assert!((libm::cosf(w) - libm::cosf(t)).abs() < 1e-4);
        }
    }

    #[test]
    fn count_delta_across_wrap() {
        assert_eq!(count_delta(i32::MIN + 4, i32::MAX - 5), 10);
        assert_eq!(count_delta(i32::MAX - 5, i32::MIN + 4), -10);
        assert_eq!(count_delta(7, 3), 4);
    }

    #[test]
    fn straight_line() {
        let g = geometry();
        let mut odo = Odometry::new(&g);
        // One metre = cpr / (2π r) counts.
        let counts_per_m = g.encoder_cpr as f32 / (2.0 * PI * g.wheel_radius);
        let n = libm::roundf(counts_per_m) as i32;
        for _ in 0..100 {
            odo.update([n / 100, n / 100]);
        }
        let p = odo.pose();
        assert!(
            (p.x - (n / 100 * 100) as f32 / counts_per_m).abs() < 1e-4,
            "{p:?}"
        );
        assert!(p.y.abs() < 1e-6 && p.theta.abs() < 1e-6);
    }

    /// A known arc: right wheel on a circle of radius R + b/2, left on R − b/2, for a quarter
    /// turn. The axle centre ends at (R, R) from a start at the origin heading +x.
    #[test]
    fn quarter_circle_arc() {
        let g = geometry();
        let mut odo = Odometry::new(&g);
        let radius = 0.2f32;
        let quarter = PI / 2.0;
        let mpc = odo.metres_per_count();
        let steps = 500;
        // Distribute the counts over the steps as an encoder would (integer, cumulative).
        let total_l = (radius - g.wheel_base / 2.0) * quarter / mpc;
        let total_r = (radius + g.wheel_base / 2.0) * quarter / mpc;
        let (mut prev_l, mut prev_r) = (0i32, 0i32);
        for i in 1..=steps {
            let l = libm::roundf(total_l * i as f32 / steps as f32) as i32;
            let r = libm::roundf(total_r * i as f32 / steps as f32) as i32;
            odo.update([l - prev_l, r - prev_r]);
            prev_l = l;
            prev_r = r;
        }
        let p = odo.pose();
        // Counts are rounded: allow one count of error per wheel.
        let tol = 2.0 * mpc / g.wheel_base * radius + 1e-4;
        assert!(
            (p.theta - quarter).abs() < 2.0 * mpc / g.wheel_base,
            "{p:?}"
        );
        assert!((p.x - radius).abs() < tol, "{p:?}");
        assert!((p.y - radius).abs() < tol, "{p:?}");
    }

    #[test]
    fn spin_on_the_spot_wraps_heading() {
        let g = geometry();
        let mut odo = Odometry::new(&g);
        for _ in 0..10_000 {
            odo.update([-3, 3]);
            let p = odo.pose();
            assert!(p.theta > -PI && p.theta <= PI);
        }
        let p = odo.pose();
        assert!(p.x.abs() < 1e-4 && p.y.abs() < 1e-4, "{p:?}");
    }
}
