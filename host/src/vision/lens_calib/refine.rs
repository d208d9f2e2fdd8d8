//! Maximum-likelihood refinement (Zhang 2000, §3.2–3.3): the intrinsics (fx, fy, cx, cy), the
//! `plumb_bob` distortion (k1, k2, p1, p2, k3 — OpenCV's camera model, as
//! [`pushbot_world::lens`] projects) and every view's pose (a rotation vector and a
//! translation) minimise the sum of squared reprojection errors in pixels, by
//! Levenberg–Marquardt (the `levenberg-marquardt` crate, MINPACK's algorithm).
//!
//! The Jacobian is built by central differences, block by block: a view's residuals depend only
//! on the nine lens parameters and that view's six pose parameters.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use nalgebra_lm::storage::Owned;
use nalgebra_lm::{DMatrix, DVector, Dyn};
use pushbot_world::lens::{Distortion, Intrinsics};

/// Lens parameters: fx, fy, cx, cy, k1, k2, p1, p2, k3.
const LENS: usize = 9;
/// Pose parameters per view: rotation vector, translation.
const POSE: usize = 6;
/// Central-difference steps of the lens and pose parameters.
const STEPS: [f64; LENS + POSE] = [
    1e-3, 1e-3, 1e-3, 1e-3, 1e-6, 1e-6, 1e-7, 1e-7, 1e-6, 1e-7, 1e-7, 1e-7, 1e-7, 1e-7, 1e-7,
];
/// The residual of a point the camera cannot see (behind it, or distorted past the model).
const UNSEEN: f64 = 1e3;

/// One view's observations: board points (metres) and where they were seen (pixels).
#[derive(Debug, Clone)]
pub struct Observations {
    /// Board points, metres.
    pub board: Vec<[f64; 2]>,
    /// Their pixels.
    pub pixels: Vec<[f64; 2]>,
}

/// The refined camera and poses.
#[derive(Debug, Clone)]
pub struct Refined {
    /// The lens.
    pub intrinsics: Intrinsics,
    /// Each view's board → camera pose.
    pub poses: Vec<Isometry3<f64>>,
    /// Each view's reprojection errors, pixels (one per point).
    pub errors: Vec<Vec<f64>>,
    /// Solver iterations (residual evaluations).
    pub evaluations: usize,
}

struct Problem<'a> {
    size: [u32; 2],
    views: &'a [Observations],
    params: DVector<f64>,
}

fn lens_of(size: [u32; 2], p: &[f64]) -> Intrinsics {
    Intrinsics {
        width: size[0],
        height: size[1],
        fx: p[0],
        fy: p[1],
        cx: p[2],
        cy: p[3],
        distortion: Distortion::from_slice(&p[4..LENS]),
    }
}

pub(crate) fn pose_of(p: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p[3], p[4], p[5]),
        UnitQuaternion::from_scaled_axis(Vector3::new(p[0], p[1], p[2])),
    )
}

/// The reprojection residuals (x, y per point) of one view under lens `l` and pose `pose`.
pub(crate) fn view_residuals(l: &Intrinsics, pose: &[f64], v: &Observations, out: &mut [f64]) {
    let iso = pose_of(pose);
    for (k, (b, px)) in v.board.iter().zip(&v.pixels).enumerate() {
        let c = iso * Point3::new(b[0], b[1], 0.0);
        let (rx, ry) = match l.project([c.x, c.y, c.z]) {
            Some(q) if q[0].is_finite() && q[1].is_finite() => (q[0] - px[0], q[1] - px[1]),
            _ => (UNSEEN, UNSEEN),
        };
        out[2 * k] = rx;
        out[2 * k + 1] = ry;
    }
}

impl Problem<'_> {
    fn rows(&self) -> usize {
        self.views.iter().map(|v| 2 * v.board.len()).sum()
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.params.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.params.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let p = self.params.as_slice();
        let l = lens_of(self.size, p);
        let mut r = DVector::zeros(self.rows());
        let mut row = 0;
        for (i, v) in self.views.iter().enumerate() {
            let n = 2 * v.board.len();
            let pose = &p[LENS + POSE * i..LENS + POSE * (i + 1)];
            view_residuals(&l, pose, v, &mut r.as_mut_slice()[row..row + n]);
            row += n;
        }
        Some(r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let p = self.params.as_slice();
        let mut j = DMatrix::zeros(self.rows(), p.len());
        let mut row = 0;
        for (i, v) in self.views.iter().enumerate() {
            let n = 2 * v.board.len();
            // This view's parameters: the lens's, then its pose's.
            let mut local: Vec<f64> = p[..LENS].to_vec();
            local.extend_from_slice(&p[LENS + POSE * i..LENS + POSE * (i + 1)]);
            let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
            for (k, step) in STEPS.iter().enumerate() {
                let h = step * local[k].abs().max(1.0);
                let mut q = local.clone();
                q[k] += h;
                view_residuals(&lens_of(self.size, &q), &q[LENS..], v, &mut plus);
                q[k] -= 2.0 * h;
                view_residuals(&lens_of(self.size, &q), &q[LENS..], v, &mut minus);
                let col = if k < LENS {
                    k
                } else {
                    LENS + POSE * i + k - LENS
                };
                for r in 0..n {
                    j[(row + r, col)] = (plus[r] - minus[r]) / (2.0 * h);
                }
            }
            row += n;
        }
        Some(j)
    }
}

/// Refine `lens` and the views' `poses` against their observations; `None` when the solver
/// breaks down (a non-finite value).
pub fn refine(
    lens: &Intrinsics,
    poses: &[Isometry3<f64>],
    views: &[Observations],
) -> Option<Refined> {
    let mut params = vec![lens.fx, lens.fy, lens.cx, lens.cy];
    params.extend_from_slice(&lens.distortion.to_array());
    for pose in poses {
        let r = pose.rotation.scaled_axis();
        let t = pose.translation.vector;
        params.extend_from_slice(&[r.x, r.y, r.z, t.x, t.y, t.z]);
    }
    let size = [lens.width, lens.height];
    let problem = Problem {
        size,
        views,
        params: DVector::from_vec(params),
    };
    let (solved, report) = LevenbergMarquardt::new()
        .with_patience(200)
        .minimize(problem);
    let p = solved.params.as_slice();
    if report.termination.was_usage_issue() || p.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let intrinsics = lens_of(size, p);
    let poses: Vec<_> = (0..views.len())
        .map(|i| pose_of(&p[LENS + POSE * i..]))
        .collect();
    let errors = views
        .iter()
        .zip(&poses)
        .enumerate()
        .map(|(i, (v, _))| {
            let mut r = vec![0.0; 2 * v.board.len()];
            view_residuals(&intrinsics, &p[LENS + POSE * i..], v, &mut r);
            r.chunks_exact(2).map(|e| e[0].hypot(e[1])).collect()
        })
        .collect();
    Some(Refined {
        intrinsics,
        poses,
        errors,
        evaluations: report.number_of_evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disturbed_start_converges_to_the_true_lens() {
        let truth = Intrinsics {
            width: 960,
            height: 720,
            fx: 700.0,
            fy: 702.0,
            cx: 483.0,
            cy: 357.0,
            distortion: Distortion {
                k1: -0.08,
                k2: 0.02,
                p1: 0.001,
                p2: -0.0005,
                k3: 0.0,
            },
        };
        let mut poses = Vec::new();
        let mut views = Vec::new();
        for (i, (rx, ry, tx, ty)) in [
            (0.3, 0.1, -0.2, -0.1),
            (-0.3, 0.2, 0.15, -0.1),
            (0.2, -0.3, -0.15, 0.1),
            (-0.2, -0.2, 0.1, 0.12),
            (0.0, 0.4, 0.0, 0.0),
        ]
        .into_iter()
        .enumerate()
        {
            let pose = Isometry3::from_parts(
                Translation3::new(tx - 0.1, ty - 0.08, 0.5 + 0.02 * i as f64),
                UnitQuaternion::from_euler_angles(rx + std::f64::consts::PI, ry, 0.0),
            );
            let mut v = Observations {
                board: vec![],
                pixels: vec![],
            };
            for a in 0..9 {
                for b in 0..7 {
                    let bp = [0.025 * f64::from(a), 0.025 * f64::from(b)];
                    let c = pose * Point3::new(bp[0], bp[1], 0.0);
                    v.board.push(bp);
                    v.pixels.push(truth.project([c.x, c.y, c.z]).unwrap());
                }
            }
            views.push(v);
            // Start a little off.
            poses.push(Isometry3::from_parts(
                Translation3::new(tx - 0.1 + 0.01, ty - 0.08, 0.5 + 0.02 * i as f64 + 0.02),
                UnitQuaternion::from_euler_angles(rx + std::f64::consts::PI + 0.02, ry, 0.01),
            ));
        }
        let start = Intrinsics {
            fx: 680.0,
            fy: 690.0,
            cx: 480.0,
            cy: 360.0,
            distortion: Distortion::NONE,
            ..truth
        };
        let r = refine(&start, &poses, &views).unwrap();
        let l = r.intrinsics;
        assert!((l.fx - truth.fx).abs() < 1e-4, "{l:?}");
        assert!((l.cy - truth.cy).abs() < 1e-4, "{l:?}");
        assert!(
            (l.distortion.k1 - truth.distortion.k1).abs() < 1e-6,
            "{l:?}"
        );
        let worst = r.errors.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
        assert!(worst < 1e-6, "{worst}");
    }
}
