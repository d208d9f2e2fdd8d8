//! Fitting a plane-to-plane homography: the normalised direct linear transform (Hartley &
//! Zisserman, Alg. 4.2) followed by Levenberg–Marquardt refinement of the error in the
//! destination plane.

use nalgebra::{DMatrix, Matrix3, SMatrix, SVector};
use pushbot_world::camera::Homography;

/// Why no homography could be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Fewer than four correspondences, or mismatched lists.
    #[error("a homography needs at least 4 point pairs, got {0}")]
    TooFewPoints(usize),
    /// The points are degenerate (collinear, repeated, not finite).
    #[error("the points are degenerate (collinear or repeated)")]
    Degenerate,
}

fn from_na(m: &Matrix3<f64>) -> Homography {
    Homography([
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ])
}

/// Similarity that moves the points' centroid to 0 and their mean distance to √2.
fn normaliser(pts: &[[f64; 2]]) -> Option<Matrix3<f64>> {
    let n = pts.len() as f64;
    let cx = pts.iter().map(|p| p[0]).sum::<f64>() / n;
    let cy = pts.iter().map(|p| p[1]).sum::<f64>() / n;
    let d = pts
        .iter()
        .map(|p| ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    if !(d > 1e-12 && d.is_finite()) {
        return None;
    }
    let s = std::f64::consts::SQRT_2 / d;
    Some(Matrix3::new(
        s,
        0.0,
        -s * cx,
        0.0,
        s,
        -s * cy,
        0.0,
        0.0,
        1.0,
    ))
}

fn apply(m: &Matrix3<f64>, p: [f64; 2]) -> [f64; 2] {
    let v = m * nalgebra::Vector3::new(p[0], p[1], 1.0);
    [v[0] / v[2], v[1] / v[2]]
}

/// The homography `H` with `dst ≈ H(src)` by the normalised DLT, without refinement.
pub fn fit_dlt(src: &[[f64; 2]], dst: &[[f64; 2]]) -> Result<Homography, FitError> {
    if src.len() != dst.len() || src.len() < 4 {
        return Err(FitError::TooFewPoints(src.len().min(dst.len())));
    }
    if src
        .iter()
        .chain(dst)
        .any(|p| !p[0].is_finite() || !p[1].is_finite())
    {
        return Err(FitError::Degenerate);
    }
    let ts = normaliser(src).ok_or(FitError::Degenerate)?;
    let td = normaliser(dst).ok_or(FitError::Degenerate)?;
    let rows = (2 * src.len()).max(9);
    let mut a = DMatrix::<f64>::zeros(rows, 9);
    for (k, (s, d)) in src.iter().zip(dst).enumerate() {
        let [x, y] = apply(&ts, *s);
        let [u, v] = apply(&td, *d);
        let r = 2 * k;
        a.row_mut(r)
            .copy_from_slice(&[0.0, 0.0, 0.0, -x, -y, -1.0, v * x, v * y, v]);
        a.row_mut(r + 1)
            .copy_from_slice(&[x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, -u]);
    }
    let svd = a.svd(false, true);
    let vt = svd.v_t.ok_or(FitError::Degenerate)?;
    let (imin, smin) =
        svd.singular_values
            .iter()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |b, (i, &s)| if s < b.1 { (i, s) } else { b },
            );
    // A second (near) null direction means the points do not pin down a homography.
    let second = svd
        .singular_values
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != imin)
        .map(|(_, &s)| s)
        .fold(f64::INFINITY, f64::min);
    if second.partial_cmp(&(1e-9 * svd.singular_values.max())) != Some(std::cmp::Ordering::Greater)
        || !smin.is_finite()
    {
        return Err(FitError::Degenerate);
    }
    let h = vt.row(imin);
    let hn = Matrix3::new(h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8]);
    let td_inv = td.try_inverse().ok_or(FitError::Degenerate)?;
    let mut m = td_inv * hn * ts;
    let scale = m[(2, 2)];
    if scale.abs() < 1e-12 {
        return Err(FitError::Degenerate);
    }
    m /= scale;
    Ok(from_na(&m))
}

/// Fit `dst ≈ H(src)`: DLT, then Levenberg–Marquardt on the squared distances in `dst`.
pub fn fit_homography(src: &[[f64; 2]], dst: &[[f64; 2]]) -> Result<Homography, FitError> {
    let h0 = fit_dlt(src, dst)?;
    Ok(refine(&h0, src, dst, 20))
}

fn sq_error(h: &SVector<f64, 8>, src: &[[f64; 2]], dst: &[[f64; 2]]) -> f64 {
    src.iter()
        .zip(dst)
        .map(|(s, d)| {
            let w = h[6] * s[0] + h[7] * s[1] + 1.0;
            let u = (h[0] * s[0] + h[1] * s[1] + h[2]) / w;
            let v = (h[3] * s[0] + h[4] * s[1] + h[5]) / w;
            (u - d[0]).powi(2) + (v - d[1]).powi(2)
        })
        .sum()
}

/// Levenberg–Marquardt on the 8 free entries (`h₃₃ = 1`).
fn refine(h0: &Homography, src: &[[f64; 2]], dst: &[[f64; 2]], iters: usize) -> Homography {
    let m = h0.0;
    let mut h = SVector::<f64, 8>::from_column_slice(&[
        m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1],
    ]);
    let mut err = sq_error(&h, src, dst);
    let mut lambda = 1e-3;
    for _ in 0..iters {
        let mut jtj = SMatrix::<f64, 8, 8>::zeros();
        let mut jtr = SVector::<f64, 8>::zeros();
        for (s, d) in src.iter().zip(dst) {
            let (x, y) = (s[0], s[1]);
            let w = h[6] * x + h[7] * y + 1.0;
            let u = (h[0] * x + h[1] * y + h[2]) / w;
            let v = (h[3] * x + h[4] * y + h[5]) / w;
            let ju = SVector::<f64, 8>::from_column_slice(&[
                x / w,
                y / w,
                1.0 / w,
                0.0,
                0.0,
                0.0,
                -u * x / w,
                -u * y / w,
            ]);
            let jv = SVector::<f64, 8>::from_column_slice(&[
                0.0,
                0.0,
                0.0,
                x / w,
                y / w,
                1.0 / w,
                -v * x / w,
                -v * y / w,
            ]);
            jtj += ju * ju.transpose() + jv * jv.transpose();
            jtr += ju * (u - d[0]) + jv * (v - d[1]);
        }
        let mut improved = false;
        for _ in 0..8 {
            let mut a = jtj;
            for i in 0..8 {
                a[(i, i)] *= 1.0 + lambda;
            }
            let Some(step) = a.lu().solve(&jtr) else {
                break;
            };
            let cand = h - step;
            let e = sq_error(&cand, src, dst);
            if e.is_finite() && e <= err {
                h = cand;
                improved = err - e > 1e-15 * (1.0 + err);
                err = e;
                lambda = (lambda * 0.3).max(1e-12);
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Homography([[h[0], h[1], h[2]], [h[3], h[4], h[5]], [h[6], h[7], 1.0]])
}

/// Distances `|H(src) − dst|` for each pair (infinite where a point maps to infinity).
pub fn reprojection_errors(h: &Homography, src: &[[f64; 2]], dst: &[[f64; 2]]) -> Vec<f64> {
    src.iter()
        .zip(dst)
        .map(|(s, d)| {
            h.apply(*s).map_or(f64::INFINITY, |p| {
                ((p[0] - d[0]).powi(2) + (p[1] - d[1]).powi(2)).sqrt()
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn truth() -> Homography {
        Homography([
            [764.4, 3.1, 21.3],
            [-2.2, -760.0, 704.1],
            [1.5e-3, -2.0e-3, 1.0],
        ])
    }

    #[test]
    fn exact_points_give_the_homography_back() {
        let h = truth();
        let src: Vec<[f64; 2]> = (0..9)
            .map(|i| {
                [
                    0.1 + 0.12 * (i % 3) as f64 * 4.0,
                    0.05 + 0.3 * (i / 3) as f64,
                ]
            })
            .collect();
        let dst: Vec<[f64; 2]> = src.iter().map(|p| h.apply(*p).unwrap()).collect();
        let fit = fit_homography(&src, &dst).unwrap();
        for p in [[0.0, 0.0], [1.2, 0.9], [0.7, 0.2]] {
            let (a, b) = (fit.apply(p).unwrap(), h.apply(p).unwrap());
            assert!(
                (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6,
                "{a:?} vs {b:?}"
            );
        }
        // Four points in general position are enough.
        let four = [0, 2, 6, 8];
        let (s4, d4): (Vec<_>, Vec<_>) = four.iter().map(|&i| (src[i], dst[i])).unzip();
        let fit4 = fit_homography(&s4, &d4).unwrap();
        let (a, b) = (
            fit4.apply([0.5, 0.5]).unwrap(),
            h.apply([0.5, 0.5]).unwrap(),
        );
        assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
    }

    #[test]
    fn noisy_points_refined_error_is_at_most_dlt_error() {
        let h = truth();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let src: Vec<[f64; 2]> = (0..40)
            .map(|_| [rng.random_range(0.0..1.2), rng.random_range(0.0..0.9)])
            .collect();
        let dst: Vec<[f64; 2]> = src
            .iter()
            .map(|p| {
                let q = h.apply(*p).unwrap();
                [
                    q[0] + rng.random_range(-0.3..0.3),
                    q[1] + rng.random_range(-0.3..0.3),
                ]
            })
            .collect();
        let rms = |f: &Homography| {
            let e = reprojection_errors(f, &src, &dst);
            (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
        };
        let dlt = fit_dlt(&src, &dst).unwrap();
        let lm = fit_homography(&src, &dst).unwrap();
        assert!(rms(&lm) <= rms(&dlt) + 1e-12);
        assert!(rms(&lm) < 0.3, "{}", rms(&lm));
        let centre = (
            lm.apply([0.6, 0.45]).unwrap(),
            h.apply([0.6, 0.45]).unwrap(),
        );
        assert!((centre.0[0] - centre.1[0]).hypot(centre.0[1] - centre.1[1]) < 0.2);
    }

    #[test]
    fn degenerate_inputs_are_errors() {
        let line: Vec<[f64; 2]> = (0..6).map(|i| [i as f64, 2.0 * i as f64]).collect();
        assert_eq!(fit_homography(&line, &line), Err(FitError::Degenerate));
        assert_eq!(
            fit_homography(&line[..3], &line[..3]),
            Err(FitError::TooFewPoints(3))
        );
        let nan = vec![[f64::NAN, 0.0]; 5];
        assert_eq!(fit_homography(&nan, &nan), Err(FitError::Degenerate));
    }
}
