//! The robot's odometry as the tracker's control input: between two frames the robot's
//! own wheel odometry says how it moved — a spin at 360°/s or a dash whose marker the camera sees
//! only as a smear — so the filter predicts that motion instead of extrapolating its last
//! velocity. The increment `Δ = odom(t₀)⁻¹ ∘ odom(t₁)` (robot frame, interpolated between
//! telemetry samples) is composed onto the filtered pose, the covariance carried through the
//! composition's Jacobian, and the odometry's own error (a fraction of the distance and of the
//! turn, as wheel slip and a wrong wheel base make it) added.

use std::collections::VecDeque;

use nalgebra::{SMatrix, SVector};

use super::layout::{Pose, wrap_angle};

type M6 = SMatrix<f64, 6, 6>;

/// How far back samples are kept, seconds.
const KEEP: f64 = 5.0;

/// How far past its newest sample the odometry is extrapolated (at its last rate), seconds: a
/// frame is often a report or two newer than the telemetry that has arrived.
const EXTRAPOLATE: f64 = 0.1;

/// Odometry's error: standard deviation per metre driven and per radian turned, and a floor.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OdometryNoise {
    /// Position error per metre driven, m/m.
    pub per_metre: f64,
    /// Heading error per radian turned, rad/rad.
    pub per_radian: f64,
    /// Heading error per metre driven (unequal wheels), rad/m.
    pub heading_per_metre: f64,
    /// Position error per radian turned (the contact points slide in a spin), m/rad.
    pub position_per_radian: f64,
}

impl Default for OdometryNoise {
    fn default() -> Self {
        OdometryNoise {
            per_metre: 0.03,
            per_radian: 0.03,
            heading_per_metre: 0.05,
            position_per_radian: 0.002,
        }
    }
}

/// The robot's odometry poses (its own frame) by time (the camera's clock, seconds).
#[derive(Debug, Clone, Default)]
pub struct OdometryLog {
    samples: VecDeque<(f64, Pose)>,
}

impl OdometryLog {
    /// Add a sample; samples older than the newest by more than a few seconds are dropped, and
    /// one out of order (or not finite) is ignored.
    pub fn push(&mut self, time: f64, pose: Pose) {
        if !(time.is_finite() && pose.x.is_finite() && pose.y.is_finite() && pose.theta.is_finite())
        {
            return;
        }
        if let Some(&(last, prev)) = self.samples.back() {
            if time <= last {
                return;
            }
            // Unwrap the heading so interpolation never goes the long way round.
            let pose = Pose::new(
                pose.x,
                pose.y,
                prev.theta + wrap_angle(pose.theta - prev.theta),
            );
            self.samples.push_back((time, pose));
        } else {
            self.samples.push_back((time, pose));
        }
        while self.samples.front().is_some_and(|&(t, _)| t < time - KEEP) {
            self.samples.pop_front();
        }
    }

    /// The odometry pose at `time`, interpolated between the samples around it, or up to
    /// `EXTRAPOLATE` past the newest at the rate of the last two; `None` otherwise.
    pub fn at(&self, time: f64) -> Option<Pose> {
        let i = self.samples.partition_point(|&(t, _)| t < time);
        if i == self.samples.len() {
            let (t1, p1) = *self.samples.back()?;
            let (t0, p0) = *self.samples.get(self.samples.len().checked_sub(2)?)?;
            if time - t1 > EXTRAPOLATE {
                return None;
            }
            let f = (time - t0) / (t1 - t0);
            return Some(Pose::new(
                p0.x + f * (p1.x - p0.x),
                p0.y + f * (p1.y - p0.y),
                p0.theta + f * (p1.theta - p0.theta),
            ));
        }
        let (t1, p1) = *self.samples.get(i)?;
        if t1 == time || i == 0 {
            return (t1 == time).then_some(p1);
        }
        let (t0, p0) = self.samples[i - 1];
        let f = (time - t0) / (t1 - t0);
        Some(Pose::new(
            p0.x + f * (p1.x - p0.x),
            p0.y + f * (p1.y - p0.y),
            p0.theta + f * (p1.theta - p0.theta),
        ))
    }

    /// How the robot moved from `t0` to `t1`, in its own frame at `t0`: `(dx, dy, dθ)`.
    pub fn increment(&self, t0: f64, t1: f64) -> Option<[f64; 3]> {
        let (a, b) = (self.at(t0)?, self.at(t1)?);
        let (s, c) = a.theta.sin_cos();
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        Some([c * dx + s * dy, -s * dx + c * dy, b.theta - a.theta])
    }
}

/// The state `[x, y, θ, vx, vy, ω]` and covariance moved by an odometry increment `d` (robot
/// frame) over `dt` seconds: the pose composed with `d`, the velocities those of the
/// increment, the covariance through the composition's Jacobian plus the odometry's error.
pub fn predict(
    x: &SVector<f64, 6>,
    p: &M6,
    d: [f64; 3],
    dt: f64,
    noise: &OdometryNoise,
) -> (SVector<f64, 6>, M6) {
    let (s, c) = x[2].sin_cos();
    let [dx, dy, dth] = d;
    let nx = x[0] + c * dx - s * dy;
    let ny = x[1] + s * dx + c * dy;
    let nth = x[2] + dth;
    let mut out = *x;
    out[0] = nx;
    out[1] = ny;
    out[2] = nth;
    if dt > 1e-9 {
        out[3] = (nx - x[0]) / dt;
        out[4] = (ny - x[1]) / dt;
        out[5] = dth / dt;
    }
    // Jacobian of the composition with respect to the state.
    let mut j = M6::identity();
    j[(0, 2)] = -s * dx - c * dy;
    j[(1, 2)] = c * dx - s * dy;
    // The velocities come from the odometry, not from the old velocities.
    for i in 3..6 {
        j[(i, i)] = 0.0;
    }
    let mut q = M6::zeros();
    let dist = dx.hypot(dy);
    let turn = dth.abs();
    let pos = noise.per_metre * dist + noise.position_per_radian * turn;
    let head = noise.per_radian * turn + noise.heading_per_metre * dist;
    q[(0, 0)] = pos * pos;
    q[(1, 1)] = pos * pos;
    q[(2, 2)] = head * head;
    // The velocity is known as well as the increment over the interval.
    let dt = dt.max(1e-3);
    q[(3, 3)] = (pos / dt).powi(2) + 1e-4;
    q[(4, 4)] = (pos / dt).powi(2) + 1e-4;
    q[(5, 5)] = (head / dt).powi(2) + 1e-3;
    let np = j * p * j.transpose() + q;
    (out, np.symmetric_part())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn increments_are_in_the_robot_frame_and_interpolated() {
        let mut log = OdometryLog::default();
        // Driving along its own +x while facing +y in the odometry frame, then turning.
        log.push(0.0, Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        log.push(1.0, Pose::new(0.0, 0.5, std::f64::consts::FRAC_PI_2));
        log.push(2.0, Pose::new(0.0, 0.5, -3.0));
        let d = log.increment(0.0, 0.5).unwrap();
        assert!((d[0] - 0.25).abs() < 1e-12 && d[1].abs() < 1e-12 && d[2].abs() < 1e-12);
        // The turn goes the short way across ±π: from π/2 to −3 is +1.71 rad.
        let d = log.increment(1.0, 2.0).unwrap();
        let want = wrap_angle(-3.0 - std::f64::consts::FRAC_PI_2);
        assert!((d[2] - want).abs() < 1e-12, "{d:?}");
        assert!(log.increment(-1.0, 0.5).is_none() && log.increment(0.5, 2.5).is_none());
        // A little past the newest sample: extrapolated at the last rate.
        let past = log.at(2.05).unwrap();
        let turned = std::f64::consts::FRAC_PI_2 + 1.05 * want;
        assert!((past.theta - turned).abs() < 1e-9, "{past:?}");
        assert!(log.at(2.2).is_none(), "not far past it");
        // Out of order: ignored.
        log.push(1.5, Pose::new(9.0, 9.0, 0.0));
        assert!((log.at(1.5).unwrap().x).abs() < 1e-12);
    }

    #[test]
    fn a_predicted_pose_is_the_composition_and_grows_its_covariance() {
        let x = SVector::<f64, 6>::new(1.0, 2.0, std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
        let p = M6::identity() * 1e-6;
        let (nx, np) = predict(&x, &p, [0.1, 0.0, 0.2], 0.1, &OdometryNoise::default());
        assert!((nx[0] - 1.0).abs() < 1e-12 && (nx[1] - 2.1).abs() < 1e-12);
        assert!((nx[2] - (std::f64::consts::FRAC_PI_2 + 0.2)).abs() < 1e-12);
        assert!((nx[4] - 1.0).abs() < 1e-12 && (nx[5] - 2.0).abs() < 1e-12);
        assert!(np[(0, 0)] > p[(0, 0)] && np[(2, 2)] > p[(2, 2)]);
        // Heading uncertainty turns into position uncertainty across the motion.
        let p = M6::from_diagonal(&SVector::<f64, 6>::new(0.0, 0.0, 0.01, 0.0, 0.0, 0.0));
        let (_, np) = predict(&x, &p, [0.1, 0.0, 0.0], 0.1, &OdometryNoise::default());
        assert!(np[(0, 0)] > 0.5e-4, "{}", np[(0, 0)]);
    }
}
