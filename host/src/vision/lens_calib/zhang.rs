//! Zhang's closed-form initial estimate (Zhang 2000, "A flexible new technique for camera
//! calibration", §3.1): each view's board → pixel homography H = λ K [r1 r2 t] gives two linear
//! constraints on the image of the absolute conic B = K⁻ᵀ K⁻¹ (h1ᵀ B h2 = 0, h1ᵀ B h1 = h2ᵀ B h2);
//! with zero skew a third row fixes B12 = 0, and the null vector of the stacked constraints gives
//! K (Zhang's appendix B). The extrinsics of each view follow from K⁻¹ H (§3.1, eq. 3, with the
//! rotation made orthonormal by SVD, Zhang's appendix C).
//!
//! Pixels are first moved and scaled so the image centre is 0 and its half-diagonal 1, which
//! keeps the constraint matrix well conditioned. When the views do not determine the principal
//! point (nearly parallel boards), the centre is fixed at the image's and only the focal
//! lengths are solved for, as OpenCV's `initIntrinsicParams2D` does.

use nalgebra::{DMatrix, Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// The pixel normalisation of a `size` image: centre to 0, half-diagonal to 1.
fn normaliser(size: [u32; 2]) -> Matrix3<f64> {
    let (w, h) = (f64::from(size[0]), f64::from(size[1]));
    let s = 2.0 / w.hypot(h);
    Matrix3::new(s, 0.0, -s * w / 2.0, 0.0, s, -s * h / 2.0, 0.0, 0.0, 1.0)
}

/// Zhang's constraint row v_ij (eq. 7) of homography columns `i`, `j`.
fn v(h: &Matrix3<f64>, i: usize, j: usize) -> [f64; 6] {
    let (a, b) = (h.column(i), h.column(j));
    [
        a[0] * b[0],
        a[0] * b[1] + a[1] * b[0],
        a[1] * b[1],
        a[2] * b[0] + a[0] * b[2],
        a[2] * b[1] + a[1] * b[2],
        a[2] * b[2],
    ]
}

/// The camera matrix from board → pixel homographies of a `size` image, skew zero; `None` when
/// the views determine no camera.
pub fn camera_matrix(homographies: &[Matrix3<f64>], size: [u32; 2]) -> Option<Matrix3<f64>> {
    let n = normaliser(size);
    let hs: Vec<Matrix3<f64>> = homographies
        .iter()
        .map(|h| {
            let m = n * h;
            m / m.norm()
        })
        .collect();
    let k = closed_form(&hs)
        .filter(plausible)
        .or_else(|| centred(&hs).filter(plausible))?;
    let k = n.try_inverse()? * k;
    Some(k / k[(2, 2)])
}

/// Whether a normalised camera matrix makes a camera: positive finite focal lengths, the
/// principal point inside the image.
fn plausible(k: &Matrix3<f64>) -> bool {
    k.iter().all(|v| v.is_finite())
        && k[(0, 0)] > 0.05
        && k[(1, 1)] > 0.05
        && k[(0, 2)].abs() < 0.8
        && k[(1, 2)].abs() < 0.8
}

/// Zhang's closed form with the zero-skew row (normalised pixels).
fn closed_form(hs: &[Matrix3<f64>]) -> Option<Matrix3<f64>> {
    if hs.len() < 2 {
        return None;
    }
    let mut rows: Vec<[f64; 6]> = Vec::with_capacity(2 * hs.len() + 1);
    for h in hs {
        rows.push(v(h, 0, 1));
        let (a, b) = (v(h, 0, 0), v(h, 1, 1));
        rows.push(std::array::from_fn(|k| a[k] - b[k]));
    }
    rows.push([0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
    let m = DMatrix::from_fn(rows.len(), 6, |r, c| rows[r][c]);
    let svd = (m.transpose() * &m).symmetric_eigen();
    let (imin, _) = svd
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let b = svd.eigenvectors.column(imin);
    let (b11, b12, b22, b13, b23, b33) = (b[0], b[1], b[2], b[3], b[4], b[5]);
    let d = b11 * b22 - b12 * b12;
    if d.abs() < 1e-300 || b11.abs() < 1e-300 {
        return None;
    }
    let v0 = (b12 * b13 - b11 * b23) / d;
    let lambda = b33 - (b13 * b13 + v0 * (b12 * b13 - b11 * b23)) / b11;
    let alpha2 = lambda / b11;
    let beta2 = lambda * b11 / d;
    if !(alpha2 > 0.0 && beta2 > 0.0) {
        return None;
    }
    let (alpha, beta) = (alpha2.sqrt(), beta2.sqrt());
    let u0 = -b13 * alpha2 / lambda;
    Some(Matrix3::new(alpha, 0.0, u0, 0.0, beta, v0, 0.0, 0.0, 1.0))
}

/// Focal lengths only, the principal point at the image centre (normalised pixels: 0).
fn centred(hs: &[Matrix3<f64>]) -> Option<Matrix3<f64>> {
    // With K = diag(fx, fy, 1): a = 1/fx², b = 1/fy², linear in both constraints.
    let (mut ata, mut atb) = (nalgebra::Matrix2::zeros(), nalgebra::Vector2::zeros());
    for h in hs {
        let (h1, h2) = (h.column(0), h.column(1));
        for (row, rhs) in [
            ([h1[0] * h2[0], h1[1] * h2[1]], -h1[2] * h2[2]),
            (
                [h1[0] * h1[0] - h2[0] * h2[0], h1[1] * h1[1] - h2[1] * h2[1]],
                -(h1[2] * h1[2] - h2[2] * h2[2]),
            ),
        ] {
            let r = nalgebra::Vector2::new(row[0], row[1]);
            ata += r * r.transpose();
            atb += r * rhs;
        }
    }
    let x = ata.try_inverse()? * atb;
    if !(x[0] > 0.0 && x[1] > 0.0) {
        // One focal length for both axes.
        let s = (atb[0] + atb[1]) / (ata.sum());
        if s.is_nan() || s <= 0.0 {
            return None;
        }
        let f = 1.0 / s.sqrt();
        return Some(Matrix3::new(f, 0.0, 0.0, 0.0, f, 0.0, 0.0, 0.0, 1.0));
    }
    Some(Matrix3::new(
        1.0 / x[0].sqrt(),
        0.0,
        0.0,
        0.0,
        1.0 / x[1].sqrt(),
        0.0,
        0.0,
        0.0,
        1.0,
    ))
}

/// The board → camera pose of a view from its homography and the camera matrix (the board in
/// front of the camera); `None` for a degenerate homography.
pub fn pose(k: &Matrix3<f64>, h: &Matrix3<f64>) -> Option<Isometry3<f64>> {
    let m = k.try_inverse()? * h;
    let (c1, c2, c3) = (m.column(0), m.column(1), m.column(2));
    let scale = 2.0 / (c1.norm() + c2.norm());
    if !scale.is_finite() {
        return None;
    }
    // The board is in front: t_z > 0.
    let lambda = if c3[2] < 0.0 { -scale } else { scale };
    let r1: Vector3<f64> = c1 * lambda;
    let r2: Vector3<f64> = c2 * lambda;
    let t: Vector3<f64> = c3 * lambda;
    let q = Matrix3::from_columns(&[r1, r2, r1.cross(&r2)]);
    let svd = q.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut r = u * vt;
    if r.determinant() < 0.0 {
        r = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0)) * vt;
    }
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Some(Isometry3::from_parts(Translation3::from(t), rot))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn k_true() -> Matrix3<f64> {
        Matrix3::new(700.0, 0.0, 485.0, 0.0, 705.0, 355.0, 0.0, 0.0, 1.0)
    }

    fn view(rx: f64, ry: f64, t: [f64; 3]) -> Isometry3<f64> {
        let rot = UnitQuaternion::from_euler_angles(rx, ry, 0.1)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
        Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), rot)
    }

    fn homography(k: &Matrix3<f64>, p: &Isometry3<f64>) -> Matrix3<f64> {
        let r = p.rotation.to_rotation_matrix();
        k * Matrix3::from_columns(&[
            r.matrix().column(0).clone_owned(),
            r.matrix().column(1).clone_owned(),
            p.translation.vector,
        ])
    }

    #[test]
    fn exact_homographies_give_the_camera_and_the_poses() {
        let k = k_true();
        let poses = [
            view(0.3, 0.1, [-0.1, 0.05, 0.5]),
            view(-0.2, 0.35, [0.05, -0.1, 0.6]),
            view(0.1, -0.4, [0.0, 0.0, 0.45]),
            view(-0.35, -0.2, [0.1, 0.1, 0.55]),
        ];
        let hs: Vec<_> = poses.iter().map(|p| homography(&k, p) * 3.7).collect();
        let est = camera_matrix(&hs, [960, 720]).unwrap();
        assert!((est - k).abs().max() < 1e-6, "{est}");
        for (p, h) in poses.iter().zip(&hs) {
            let back = pose(&est, h).unwrap();
            assert!((back.translation.vector - p.translation.vector).norm() < 1e-9);
            assert!(back.rotation.angle_to(&p.rotation) < 1e-9);
        }
    }

    #[test]
    fn parallel_views_fall_back_to_a_centred_camera() {
        let k = Matrix3::new(700.0, 0.0, 480.0, 0.0, 700.0, 360.0, 0.0, 0.0, 1.0);
        // Boards all turned about the same axis leave the principal point undetermined.
        let hs: Vec<_> = [0.3, -0.3, 0.2]
            .iter()
            .map(|&a| homography(&k, &view(a, 0.0, [0.0, 0.0, 0.5])))
            .collect();
        let est = camera_matrix(&hs, [960, 720]).unwrap();
        assert!((est[(0, 0)] - 700.0).abs() < 5.0, "{est}");
        assert!((est[(0, 2)] - 480.0).abs() < 5.0, "{est}");
        assert!(camera_matrix(&hs[..0], [960, 720]).is_none());
    }
}
