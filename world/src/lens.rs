//! A real camera's lens: pinhole intrinsics with OpenCV's `plumb_bob` distortion (radial k1, k2,
//! k3 and tangential p1, p2 — Brown–Conrady, as OpenCV's `projectPoints` and ROS's
//! `camera_info` define it), and the camera's pose over the table (any tilt).
//!
//! Pixel coordinates here follow the world crate's convention (pixel centres at `i + 0.5`,
//! [`crate::camera`]); OpenCV and ROS put pixel centres at integers, so their principal point
//! is ours minus half a pixel. The files ([`crate::lens_file`]) convert both ways.
//!
//! Undistortion (pixel → normalised ray) inverts the distortion by Newton's method on the
//! 2 × 2 Jacobian, started where OpenCV's fixed-point iteration starts, so it converges on
//! strong barrel lenses too; it fails (`None`) rather than return a point that does not map
//! back to the pixel.

pub use crate::camera_pose::CameraPose;

/// OpenCV's `plumb_bob` distortion coefficients, in OpenCV's order (k1, k2, p1, p2, k3).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Distortion {
    /// Radial, r².
    pub k1: f64,
    /// Radial, r⁴.
    pub k2: f64,
    /// Tangential.
    pub p1: f64,
    /// Tangential.
    pub p2: f64,
    /// Radial, r⁶.
    pub k3: f64,
}

impl Distortion {
    /// No distortion: an ideal pinhole.
    pub const NONE: Distortion = Distortion {
        k1: 0.0,
        k2: 0.0,
        p1: 0.0,
        p2: 0.0,
        k3: 0.0,
    };

    /// The coefficients in OpenCV's order.
    pub fn to_array(self) -> [f64; 5] {
        [self.k1, self.k2, self.p1, self.p2, self.k3]
    }

    /// From OpenCV's order; fewer than five coefficients leave the rest zero (OpenCV writes 4,
    /// 5, 8, 12 or 14; beyond five is another model).
    pub fn from_slice(c: &[f64]) -> Distortion {
        let at = |i: usize| c.get(i).copied().unwrap_or(0.0);
        Distortion {
            k1: at(0),
            k2: at(1),
            p1: at(2),
            p2: at(3),
            k3: at(4),
        }
    }

    /// Whether every coefficient is zero.
    pub fn is_none(self) -> bool {
        self.to_array().iter().all(|&c| c == 0.0)
    }

    /// Distort a normalised image point (x/z, y/z).
    pub fn apply(self, p: [f64; 2]) -> [f64; 2] {
        let [x, y] = p;
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        [
            x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x),
            y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y,
        ]
    }

    /// The Jacobian of [`Distortion::apply`] at `p`, row-major.
    fn jacobian(self, p: [f64; 2]) -> [[f64; 2]; 2] {
        let [x, y] = p;
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        // d(radial)/d(r²)
        let dr = self.k1 + r2 * (2.0 * self.k2 + 3.0 * r2 * self.k3);
        [
            [
                radial + 2.0 * x * x * dr + 2.0 * self.p1 * y + 6.0 * self.p2 * x,
                2.0 * x * y * dr + 2.0 * self.p1 * x + 2.0 * self.p2 * y,
            ],
            [
                2.0 * x * y * dr + 2.0 * self.p1 * x + 2.0 * self.p2 * y,
                radial + 2.0 * y * y * dr + 6.0 * self.p1 * y + 2.0 * self.p2 * x,
            ],
        ]
    }

    /// The normalised point whose distortion is `d`, if Newton's method finds it to 1e-12.
    pub fn invert(self, d: [f64; 2]) -> Option<[f64; 2]> {
        if self.is_none() {
            return Some(d);
        }
        // OpenCV's start: divide out the radial factor at the distorted point a few times.
        let mut p = d;
        for _ in 0..5 {
            let r2 = p[0] * p[0] + p[1] * p[1];
            let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
            if !(radial.is_finite() && radial > 0.1) {
                p = d;
                break;
            }
            p = [d[0] / radial, d[1] / radial];
        }
        for _ in 0..30 {
            let f = self.apply(p);
            let e = [f[0] - d[0], f[1] - d[1]];
            if e[0].abs().max(e[1].abs()) < 1e-12 {
                return Some(p);
            }
            let j = self.jacobian(p);
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if !(det.is_finite() && det.abs() > 1e-12) {
                return None;
            }
            p = [
                p[0] - (j[1][1] * e[0] - j[0][1] * e[1]) / det,
                p[1] - (-j[1][0] * e[0] + j[0][0] * e[1]) / det,
            ];
        }
        let f = self.apply(p);
        ((f[0] - d[0]).abs().max((f[1] - d[1]).abs()) < 1e-9).then_some(p)
    }
}

/// A camera's intrinsics: image size, focal lengths and principal point in pixels (pixel
/// centres at `i + 0.5`), and its lens distortion.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Intrinsics {
    /// Image width, px.
    pub width: u32,
    /// Image height, px.
    pub height: u32,
    /// Focal length along x, px.
    pub fx: f64,
    /// Focal length along y, px.
    pub fy: f64,
    /// Principal point x, px (pixel centres at `i + 0.5`).
    pub cx: f64,
    /// Principal point y, px.
    pub cy: f64,
    /// Lens distortion.
    pub distortion: Distortion,
}

impl Intrinsics {
    /// An ideal pinhole for `width` × `height` frames with focal length `f` px, centred.
    pub fn pinhole(width: u32, height: u32, f: f64) -> Intrinsics {
        Intrinsics {
            width,
            height,
            fx: f,
            fy: f,
            cx: f64::from(width) / 2.0,
            cy: f64::from(height) / 2.0,
            distortion: Distortion::NONE,
        }
    }

    /// What is wrong with these intrinsics for a camera, if anything.
    pub fn problem(&self) -> Option<String> {
        let finite = [self.fx, self.fy, self.cx, self.cy]
            .iter()
            .chain(self.distortion.to_array().iter())
            .all(|v| v.is_finite());
        if !finite {
            Some("a value is not a finite number".into())
        } else if self.width == 0 || self.height == 0 {
            Some(format!("image size {}×{}", self.width, self.height))
        } else if self.fx <= 0.0 || self.fy <= 0.0 {
            Some(format!(
                "focal lengths must be positive: fx {} fy {}",
                self.fx, self.fy
            ))
        } else if !(0.0..=f64::from(self.width)).contains(&self.cx)
            || !(0.0..=f64::from(self.height)).contains(&self.cy)
        {
            Some(format!(
                "principal point ({}, {}) outside the {}×{} image",
                self.cx, self.cy, self.width, self.height
            ))
        } else {
            None
        }
    }

    /// The pixel of a point in the camera frame (z forward, x right, y down), if in front.
    pub fn project(&self, p: [f64; 3]) -> Option<[f64; 2]> {
        // In front of the camera (a NaN depth is not).
        if p[2].is_nan() || p[2] <= 1e-9 {
            return None;
        }
        let d = self.distortion.apply([p[0] / p[2], p[1] / p[2]]);
        Some([self.fx * d[0] + self.cx, self.fy * d[1] + self.cy])
    }

    /// The normalised, undistorted ray (x/z, y/z) through a pixel.
    pub fn unproject(&self, px: [f64; 2]) -> Option<[f64; 2]> {
        let d = [(px[0] - self.cx) / self.fx, (px[1] - self.cy) / self.fy];
        self.distortion.invert(d)
    }

    /// Where a pixel of an ideal lens with the same focal lengths and centre appears through
    /// this one (the inverse of [`Intrinsics::undistort_pixel`]).
    pub fn distort_pixel(&self, ideal: [f64; 2]) -> [f64; 2] {
        let d = self.distortion.apply([
            (ideal[0] - self.cx) / self.fx,
            (ideal[1] - self.cy) / self.fy,
        ]);
        [self.fx * d[0] + self.cx, self.fy * d[1] + self.cy]
    }

    /// Where a pixel would be through an ideal lens with the same focal lengths and centre.
    pub fn undistort_pixel(&self, px: [f64; 2]) -> Option<[f64; 2]> {
        let n = self.unproject(px)?;
        Some([self.fx * n[0] + self.cx, self.fy * n[1] + self.cy])
    }
}

/// A typical webcam (k1 = −0.08, f = 700 px) with some of every coefficient, for
/// this crate's tests.
#[cfg(test)]
pub(crate) fn test_webcam() -> Intrinsics {
    Intrinsics {
        width: 960,
        height: 720,
        fx: 700.0,
        fy: 702.0,
        cx: 480.5,
        cy: 360.5,
        distortion: Distortion {
            k1: -0.08,
            k2: 0.02,
            p1: 0.001,
            p2: -0.0005,
            k3: -0.003,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn webcam() -> Intrinsics {
        test_webcam()
    }

    #[test]
    fn undistortion_inverts_distortion_over_the_whole_image() {
        let cam = webcam();
        let mut worst: f64 = 0.0;
        for i in 0..=48 {
            for j in 0..=36 {
                let px = [f64::from(i) * 20.0, f64::from(j) * 20.0];
                let n = cam.unproject(px).expect("inverts inside the image");
                let back = cam.project([n[0], n[1], 1.0]).expect("in front");
                worst = worst.max((back[0] - px[0]).hypot(back[1] - px[1]));
            }
        }
        assert!(worst < 1e-6, "round trip off by {worst} px");
    }

    #[test]
    fn barrel_distortion_pulls_corners_in() {
        let cam = webcam();
        let ideal = Intrinsics {
            distortion: Distortion::NONE,
            ..cam
        };
        let corner_ray = [0.6, 0.45, 1.0];
        let d = cam.project(corner_ray).expect("projects");
        let i = ideal.project(corner_ray).expect("projects");
        let centre = [cam.cx, cam.cy];
        let r = |p: [f64; 2]| (p[0] - centre[0]).hypot(p[1] - centre[1]);
        assert!(r(d) < r(i) - 10.0, "barrel: {} vs {}", r(d), r(i));
        // On the optical axis nothing moves.
        assert_eq!(cam.project([0.0, 0.0, 1.0]), Some(centre));
    }

    #[test]
    fn bad_intrinsics_are_named() {
        let ok = webcam();
        assert_eq!(ok.problem(), None);
        let bad = Intrinsics { fx: -1.0, ..ok };
        assert!(bad.problem().unwrap().contains("positive"));
        let bad = Intrinsics { cx: 2000.0, ..ok };
        assert!(bad.problem().unwrap().contains("outside"));
        let bad = Intrinsics { fy: f64::NAN, ..ok };
        assert!(bad.problem().unwrap().contains("finite"));
    }
}
