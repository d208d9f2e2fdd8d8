//! Where the camera is over the table (its extrinsics, any tilt), and what follows from it with
//! the lens ([`crate::lens::Intrinsics`]): the homography of any plane parallel to the table
//! (the table itself, or the top of a marker at a height), a pixel's ray met with such a plane,
//! and — the other way — the pose from a table → ideal-pixel homography (Zhang 2000, "A flexible
//! new technique for camera calibration", §3.1: `K⁻¹ H = λ [r1 r2 t]`).
//!
//! The table frame has z up; the camera frame has z along the optical axis, x right and y down
//! in the image (OpenCV's). Homographies map table metres to *ideal* pixels: the lens's
//! distortion comes after them ([`crate::lens::Intrinsics::distort_pixel`]).

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::camera::Homography;
use crate::lens::Intrinsics;

/// Where the camera is: the table frame (x, y on the table, z up) seen from the camera
/// frame (z along the optical axis, x right, y down in the image).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// Table frame → camera frame.
    pub table_to_camera: Isometry3<f64>,
}

/// A camera's place as a scene gives it: the eye and the point it looks at, table metres
/// (z up). The image's up is the table's +y as far as the view allows (a map's orientation
/// for a camera straight above; the far side up for a camera standing at the near edge).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPlacement {
    /// The camera's centre, m.
    pub eye: [f64; 3],
    /// A point on the optical axis, m.
    pub look_at: [f64; 3],
}

impl CameraPlacement {
    /// What is wrong with this placement, if anything.
    pub fn problem(&self) -> Option<String> {
        let d = Vector3::from(self.look_at) - Vector3::from(self.eye);
        if !self.eye.iter().chain(&self.look_at).all(|v| v.is_finite()) {
            Some("a coordinate is not a finite number".into())
        } else if self.eye[2] <= 0.0 {
            Some(format!(
                "the eye is at height {} m: it must be above the table",
                self.eye[2]
            ))
        } else if d.norm() < 1e-6 {
            Some("the eye and the point it looks at are the same".into())
        } else if d.z >= 0.0 {
            Some("the camera must look down at the table (look_at below the eye)".into())
        } else {
            None
        }
    }

    /// The camera's pose, if the placement has none of the problems [`CameraPlacement::problem`]
    /// names.
    pub fn pose(&self) -> Option<CameraPose> {
        if self.problem().is_some() {
            return None;
        }
        let z = (Vector3::from(self.look_at) - Vector3::from(self.eye)).normalize();
        // Image down is the table's −y, made orthogonal to the optical axis (never parallel to
        // it: the axis points down).
        let y = (-Vector3::y() - z * (-Vector3::y()).dot(&z)).normalize();
        let x = y.cross(&z);
        let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
        let camera_to_table = Isometry3::from_parts(
            nalgebra::Translation3::new(self.eye[0], self.eye[1], self.eye[2]),
            UnitQuaternion::from_rotation_matrix(&rot),
        );
        Some(CameraPose {
            table_to_camera: camera_to_table.inverse(),
        })
    }
}

impl CameraPose {
    /// A camera at `eye` (table frame, m) looking straight down, image x along table +x and
    /// image y along table −y (the table appears as on a map).
    pub fn overhead(eye: [f64; 3]) -> CameraPose {
        let camera_to_table = Isometry3::from_parts(
            nalgebra::Translation3::new(eye[0], eye[1], eye[2]),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
        );
        CameraPose {
            table_to_camera: camera_to_table.inverse(),
        }
    }

    /// The camera's centre, table frame.
    pub fn centre(&self) -> [f64; 3] {
        let c = self.table_to_camera.inverse() * Point3::origin();
        [c.x, c.y, c.z]
    }

    /// The pixel of a table point at height `z` (m), through `lens`.
    pub fn project(&self, lens: &Intrinsics, p: [f64; 3]) -> Option<[f64; 2]> {
        let c = self.table_to_camera * Point3::new(p[0], p[1], p[2]);
        lens.project([c.x, c.y, c.z])
    }

    /// The table point at height `z` (m) seen at pixel `px` through `lens`: the ray through the
    /// pixel met with the plane z = `z`; `None` when the ray misses it (parallel, or behind).
    pub fn ray_to_plane(&self, lens: &Intrinsics, px: [f64; 2], z: f64) -> Option<[f64; 2]> {
        let n = lens.unproject(px)?;
        let to_table = self.table_to_camera.inverse();
        let origin = to_table * Point3::origin();
        let dir = to_table * Vector3::new(n[0], n[1], 1.0);
        if dir.z.abs() < 1e-12 {
            return None;
        }
        let t = (z - origin.z) / dir.z;
        (t > 0.0).then(|| [origin.x + t * dir.x, origin.y + t * dir.y])
    }

    /// The homography from the plane `height` m above the table (its x, y in table metres) to
    /// ideal pixels of `lens`: `K [r1 r2 (t + height·r3)]`. `None` when the camera is in that
    /// plane.
    pub fn plane_homography(&self, lens: &Intrinsics, height: f64) -> Option<Homography> {
        let r = self.table_to_camera.rotation.to_rotation_matrix();
        let r = r.matrix();
        let t = self.table_to_camera.translation.vector + r.column(2) * height;
        let k = Matrix3::new(lens.fx, 0.0, lens.cx, 0.0, lens.fy, lens.cy, 0.0, 0.0, 1.0);
        let m = k * Matrix3::from_columns(&[r.column(0).into(), r.column(1).into(), t]);
        let w = m[(2, 2)];
        if w.abs() < 1e-12 || !w.is_finite() {
            return None;
        }
        Some(Homography(std::array::from_fn(|i| {
            std::array::from_fn(|j| m[(i, j)] / w)
        })))
    }

    /// The pose of a camera whose table → ideal-pixel homography is `table_to_pixel`, for
    /// `lens` (Zhang §3.1): `K⁻¹ H = λ [r1 r2 t]` with λ from the mean length of the first two
    /// columns and its sign putting the table in front; the rotation is the nearest one to
    /// `[r1 r2 r1×r2]` (by SVD). `None` when the homography is degenerate or the table would be
    /// behind the camera.
    pub fn from_homography(table_to_pixel: &Homography, lens: &Intrinsics) -> Option<CameraPose> {
        let h = &table_to_pixel.0;
        let k = Matrix3::new(lens.fx, 0.0, lens.cx, 0.0, lens.fy, lens.cy, 0.0, 0.0, 1.0);
        let m = k.try_inverse()? * Matrix3::from_fn(|i, j| h[i][j]);
        let (m1, m2, m3) = (m.column(0), m.column(1), m.column(2));
        let mut lambda = 2.0 / (m1.norm() + m2.norm());
        if m3[2] * lambda < 0.0 {
            lambda = -lambda;
        }
        let r1: Vector3<f64> = m1 * lambda;
        let r2: Vector3<f64> = m2 * lambda;
        let t: Vector3<f64> = m3 * lambda;
        let q = Matrix3::from_columns(&[r1, r2, r1.cross(&r2)]);
        let svd = q.svd(true, true);
        let (u, vt) = (svd.u?, svd.v_t?);
        let rot = u * vt;
        if rot.determinant() < 0.0 || !rot.iter().chain(t.iter()).all(|v| v.is_finite()) {
            return None;
        }
        let rot = Rotation3::from_matrix_unchecked(rot);
        let pose = CameraPose {
            table_to_camera: Isometry3::from_parts(
                t.into(),
                UnitQuaternion::from_rotation_matrix(&rot),
            ),
        };
        (pose.centre()[2] > 0.0).then_some(pose)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lens::Distortion;

    fn webcam() -> Intrinsics {
        crate::lens::test_webcam()
    }

    fn tilted() -> CameraPose {
        CameraPlacement {
            eye: [0.6, -0.45, 1.0],
            look_at: [0.6, 0.45, 0.0],
        }
        .pose()
        .expect("a valid placement")
    }

    #[test]
    fn a_tilted_cameras_rays_meet_the_table_where_its_points_were() {
        let cam = webcam();
        let pose = tilted();
        for (x, y, z) in [
            (0.6, 0.45, 0.0),
            (0.3, 0.6, 0.06),
            (0.9, 0.7, 0.03),
            (0.5, 0.5, 0.0),
        ] {
            let px = pose.project(&cam, [x, y, z]).expect("seen");
            let back = pose.ray_to_plane(&cam, px, z).expect("meets the plane");
            assert!(
                (back[0] - x).hypot(back[1] - y) < 1e-9,
                "({x}, {y}, {z}) came back as {back:?}"
            );
        }
        // The overhead camera sees table +x to the right and table +y up the image.
        let over = CameraPose::overhead([0.6, 0.45, 1.2]);
        let a = over.project(&cam, [0.7, 0.45, 0.0]).unwrap();
        let b = over.project(&cam, [0.6, 0.55, 0.0]).unwrap();
        assert!(a[0] > cam.cx && b[1] < cam.cy, "{a:?} {b:?}");
        // So does a camera standing at the near edge: the far side is up, +x right, and the
        // point looked at is the image's centre.
        let c = pose.project(&cam, [0.6, 0.45, 0.0]).unwrap();
        let d = pose.project(&cam, [0.6, 0.6, 0.0]).unwrap();
        let e = pose.project(&cam, [0.7, 0.45, 0.0]).unwrap();
        assert!((c[0] - cam.cx).abs() < 1e-6, "{c:?}");
        assert!(d[1] < c[1] && e[0] > c[0], "{c:?} {d:?} {e:?}");
        assert_eq!(
            over.centre().map(|v| (v * 1e9).round()),
            [0.6e9, 0.45e9, 1.2e9]
        );
    }

    /// A plane's homography agrees with projecting its points, and the pose comes back from
    /// the table's homography (Zhang's decomposition) for straight-down and tilted cameras.
    #[test]
    fn plane_homographies_and_the_pose_from_one() {
        let lens = Intrinsics {
            distortion: Distortion::NONE,
            ..webcam()
        };
        for pose in [CameraPose::overhead([0.6, 0.45, 1.1]), tilted()] {
            for height in [0.0, 0.03, 0.06] {
                let h = pose.plane_homography(&lens, height).unwrap();
                for p in [[0.2, 0.3], [0.6, 0.45], [1.0, 0.8]] {
                    let a = h.apply(p).unwrap();
                    let b = pose.project(&lens, [p[0], p[1], height]).unwrap();
                    assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9, "{a:?} {b:?}");
                }
            }
            let h = pose.plane_homography(&lens, 0.0).unwrap();
            let back = CameraPose::from_homography(&h, &lens).expect("decomposes");
            let (c0, c1) = (pose.centre(), back.centre());
            let d = (0..3).map(|i| (c0[i] - c1[i]).powi(2)).sum::<f64>().sqrt();
            assert!(d < 1e-9, "{c0:?} vs {c1:?}");
            let raised = back.plane_homography(&lens, 0.06).unwrap();
            let want = pose.plane_homography(&lens, 0.06).unwrap();
            let (a, b) = (
                raised.apply([0.3, 0.7]).unwrap(),
                want.apply([0.3, 0.7]).unwrap(),
            );
            assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-6, "{a:?} {b:?}");
        }
    }

    #[test]
    fn bad_placements_are_named() {
        let ok = CameraPlacement {
            eye: [0.6, -0.4, 1.0],
            look_at: [0.6, 0.45, 0.0],
        };
        assert_eq!(ok.problem(), None);
        let below = CameraPlacement {
            eye: [0.6, 0.4, -0.1],
            ..ok
        };
        assert!(below.problem().unwrap().contains("above the table"));
        let up = CameraPlacement {
            look_at: [0.6, 0.45, 2.0],
            ..ok
        };
        assert!(up.problem().unwrap().contains("look down"));
        assert!(up.pose().is_none());
    }
}
