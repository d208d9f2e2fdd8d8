//! Table-plane calibration: markers fixed at known table positions give pixel ↔ table point
//! pairs (their corners and centres); a homography is fitted and its reprojection error reported.
//! Tracking then maps each detected marker to its pose on the table and its body's pose.

use std::collections::BTreeSet;
use std::path::Path;

use pushbot_world::camera::Homography;
use pushbot_world::camera_pose::CameraPose;
use serde::{Deserialize, Serialize};

use super::detection::{DetectError, Detection, Detector};
use super::frame::Frame;
use super::homography::{fit_homography, reprojection_errors};
use super::layout::{MarkerLayout, Pose};

/// A saved calibration (JSON).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// File format version: 1.
    pub version: u32,
    /// Image size it was made for, pixels.
    pub image_size: [u32; 2],
    /// Pixel (centres at `i + 0.5`) → table metres.
    pub pixel_to_table: Homography,
    /// Table metres → pixel.
    pub table_to_pixel: Homography,
    /// Root-mean-square reprojection error of the point pairs, pixels.
    pub rms_px: f64,
    /// Largest reprojection error, pixels.
    pub max_px: f64,
    /// Mean table distance per pixel near the image centre, millimetres.
    pub mm_per_px: f64,
    /// Ids of the calibration markers used.
    pub markers: Vec<u32>,
    /// Number of point pairs.
    pub points: usize,
    /// The lens the corners were undistorted through before the fit: the pipeline
    /// measures through the same lens. `None`: an ideal pinhole (raw corners).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lens: Option<pushbot_world::lens::Intrinsics>,
    /// The camera's centre in the table frame (metres, z up), known when the lens is: the
    /// camera's pose solved from the calibration markers through the lens ([`super::pnp`],
    /// started from the homography's decomposition `H = K [r1 r2 t]`). A marker at a height is
    /// then placed where its ray meets its own plane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera_centre: Option<[f64; 3]>,
}

/// Why calibration failed.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    /// Too few calibration markers were seen.
    #[error("calibration needs at least 4 calibration markers in view, saw {seen:?} of {known:?}")]
    TooFewMarkers {
        /// Ids seen.
        seen: Vec<u32>,
        /// Ids the layout knows.
        known: Vec<u32>,
    },
    /// The fit failed or is too poor to trust.
    #[error("calibration fit: {0}")]
    Fit(String),
    /// Reading or writing the file failed.
    #[error("{0}")]
    File(String),
    /// The lens does not fit the frames.
    #[error("{0}")]
    Lens(String),
}

/// One frame's detections to calibrate from: the decimated search, and the search at full
/// resolution only when that missed one of the layout's calibration markers (small or far
/// markers need it; most frames do not, and it is many times slower).
pub fn calibration_markers(
    det: &mut dyn Detector,
    frame: &Frame,
    layout: &MarkerLayout,
) -> Result<Vec<Detection>, DetectError> {
    let found = det.detect(frame)?;
    let all = layout
        .calibration
        .iter()
        .all(|m| found.iter().any(|d| d.family == m.family && d.id == m.id));
    if all {
        return Ok(found);
    }
    det.detect_fine(frame)
}

impl Calibration {
    /// Fit from the detections of one or more frames of the same still scene: every sighting of
    /// a calibration marker contributes its four corners and its centre.
    pub fn fit(
        frames: &[Vec<Detection>],
        layout: &MarkerLayout,
        image_size: [u32; 2],
    ) -> Result<Calibration, CalibrationError> {
        let (table, pixel, ids) = point_pairs(frames, layout);
        if ids.len() < 4 {
            return Err(CalibrationError::TooFewMarkers {
                seen: ids.into_iter().collect(),
                known: layout.calibration.iter().map(|m| m.id).collect(),
            });
        }
        let table_to_pixel =
            fit_homography(&table, &pixel).map_err(|e| CalibrationError::Fit(e.to_string()))?;
        let pixel_to_table = table_to_pixel
            .inverse()
            .ok_or_else(|| CalibrationError::Fit("singular homography".into()))?;
        let errs = reprojection_errors(&table_to_pixel, &table, &pixel);
        let rms_px = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
        let max_px = errs.iter().cloned().fold(0.0, f64::max);
        let c = [image_size[0] as f64 / 2.0, image_size[1] as f64 / 2.0];
        let mm_per_px = match (
            pixel_to_table.apply(c),
            pixel_to_table.apply([c[0] + 1.0, c[1]]),
            pixel_to_table.apply([c[0], c[1] + 1.0]),
        ) {
            (Some(a), Some(b), Some(d)) => {
                500.0 * ((b[0] - a[0]).hypot(b[1] - a[1]) + (d[0] - a[0]).hypot(d[1] - a[1]))
            }
            _ => f64::NAN,
        };
        if !rms_px.is_finite() || !mm_per_px.is_finite() {
            return Err(CalibrationError::Fit(
                "the fitted homography sends points to infinity".into(),
            ));
        }
        Ok(Calibration {
            version: 1,
            image_size,
            pixel_to_table,
            table_to_pixel,
            rms_px,
            max_px,
            mm_per_px,
            markers: ids.into_iter().collect(),
            points: table.len(),
            lens: None,
            camera_centre: None,
        })
    }

    /// Fit as [`Calibration::fit`] from raw detections seen through `lens` (if any): their
    /// corners are undistorted first, and the calibration keeps the lens, which must be made for
    /// frames of `image_size`.
    pub fn fit_through(
        frames: &[Vec<Detection>],
        layout: &MarkerLayout,
        image_size: [u32; 2],
        lens: Option<&pushbot_world::lens::Intrinsics>,
    ) -> Result<Calibration, CalibrationError> {
        let Some(lens) = lens else {
            return Calibration::fit(frames, layout, image_size);
        };
        if let Some(why) = super::undistort::lens_mismatch(lens, image_size) {
            return Err(CalibrationError::Lens(why));
        }
        let ideal: Vec<Vec<Detection>> = frames
            .iter()
            .map(|d| super::undistort::undistort_detections(d, lens))
            .collect();
        let mut cal = Calibration::fit(&ideal, layout, image_size)?;
        cal.lens = Some(*lens);
        cal.camera_centre = camera_centre(&cal.table_to_pixel, lens);
        // The camera's pose by PnP through the whole lens, from the homography's: its
        // reprojection error is the model's own, in the frame's pixels.
        let (table, raw, _) = point_pairs(frames, layout);
        if let Some(start) = CameraPose::from_homography(&cal.table_to_pixel, lens)
            && let Some((pose, errs)) = super::pnp::solve(lens, &start, &table, &raw)
            && let Some(h) = pose.plane_homography(lens, 0.0)
            && let Some(inv) = h.inverse()
        {
            let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
            if rms.is_finite() {
                cal.table_to_pixel = h;
                cal.pixel_to_table = inv;
                cal.rms_px = rms;
                cal.max_px = errs.iter().copied().fold(0.0, f64::max);
                cal.camera_centre = Some(pose.centre());
            }
        }
        Ok(cal)
    }

    /// Write as pretty JSON.
    pub fn save(&self, path: &Path) -> Result<(), CalibrationError> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| CalibrationError::File(e.to_string()))?;
        std::fs::write(path, text)
            .map_err(|e| CalibrationError::File(format!("cannot write {}: {e}", path.display())))
    }

    /// Read and check a saved calibration.
    pub fn load(path: &Path) -> Result<Calibration, CalibrationError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CalibrationError::File(format!("cannot read {}: {e}", path.display())))?;
        let c: Calibration = serde_json::from_str(&text).map_err(|e| {
            CalibrationError::File(format!("{}: not a calibration: {e}", path.display()))
        })?;
        if c.version != 1 {
            return Err(CalibrationError::File(format!(
                "{}: unknown calibration version {}",
                path.display(),
                c.version
            )));
        }
        if c.pixel_to_table.inverse().is_none()
            || c.pixel_to_table.0.iter().flatten().any(|v| !v.is_finite())
        {
            return Err(CalibrationError::File(format!(
                "{}: the homography is singular",
                path.display()
            )));
        }
        Ok(c)
    }

    /// A marker's pose on the table from its detected corners: the corners are mapped to the
    /// table and the marker's square is fitted to them (2-D Procrustes: rotation and
    /// translation). Also returns the fitted side length, metres.
    pub fn marker_pose(&self, d: &Detection) -> Option<(Pose, f64)> {
        self.marker_pose_at(d, 0.0)
    }

    /// As [`Calibration::marker_pose`] for a marker `height` metres above the table: each
    /// corner's ray, met with the table, is moved back along the ray to the marker's plane —
    /// when the camera's centre is known ([`Calibration::camera_centre`]); otherwise the marker
    /// is taken to lie on the table.
    pub fn marker_pose_at(&self, d: &Detection, height: f64) -> Option<(Pose, f64)> {
        let mut q = [[0.0; 2]; 4];
        for (k, c) in d.corners.iter().enumerate() {
            q[k] = self.pixel_to_table.apply(*c)?;
            if let Some(cc) = self.camera_centre
                && height != 0.0
                && cc[2] > height
            {
                let f = (cc[2] - height) / cc[2];
                q[k] = [cc[0] + (q[k][0] - cc[0]) * f, cc[1] + (q[k][1] - cc[1]) * f];
            }
        }
        // The square's corners about its centre, unit half-side: BL, BR, TR, TL.
        let local = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
        let cx = q.iter().map(|p| p[0]).sum::<f64>() / 4.0;
        let cy = q.iter().map(|p| p[1]).sum::<f64>() / 4.0;
        let (mut sdot, mut scross, mut norm) = (0.0, 0.0, 0.0);
        for (l, p) in local.iter().zip(&q) {
            let (x, y) = (p[0] - cx, p[1] - cy);
            sdot += l[0] * x + l[1] * y;
            scross += l[0] * y - l[1] * x;
            norm += x * x + y * y;
        }
        let theta = scross.atan2(sdot);
        // Half-side from the corner radius: |corner| = half·√2, over 4 corners.
        let side = 2.0 * (norm / 4.0).sqrt() / std::f64::consts::SQRT_2;
        (cx.is_finite() && cy.is_finite() && theta.is_finite())
            .then_some((Pose::new(cx, cy, theta), side))
    }
}

/// Every sighting of a calibration marker in `frames` as point pairs — its four corners and its
/// centre on the table (metres) and in the frame (pixels) — and the ids seen.
fn point_pairs(
    frames: &[Vec<Detection>],
    layout: &MarkerLayout,
) -> (Vec<[f64; 2]>, Vec<[f64; 2]>, BTreeSet<u32>) {
    let mut table = Vec::new();
    let mut pixel = Vec::new();
    let mut ids = BTreeSet::new();
    for dets in frames {
        for d in dets {
            let Some(m) = layout.fixed_marker(d.family, d.id) else {
                continue;
            };
            let p = m.placement();
            table.extend(p.corners());
            table.push(p.centre);
            pixel.extend(d.corners);
            pixel.push(d.centre);
            ids.insert(d.id);
        }
    }
    (table, pixel, ids)
}

/// The camera's centre in the table frame from the table → ideal-pixel homography and the
/// lens's intrinsics (Zhang's decomposition, [`CameraPose::from_homography`]).
fn camera_centre(
    table_to_pixel: &Homography,
    lens: &pushbot_world::lens::Intrinsics,
) -> Option<[f64; 3]> {
    CameraPose::from_homography(table_to_pixel, lens).map(|p| p.centre())
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_world::camera::{CameraModel, MarkerFamily};

    fn det(id: u32, corners: [[f64; 2]; 4], centre: [f64; 2]) -> Detection {
        Detection {
            family: MarkerFamily::Tag36h11,
            id,
            corners,
            centre,
            hamming: 0,
            margin: 50.0,
        }
    }

    /// Exact detections of the calibration markers seen through a known (tilted) camera give
    /// that camera back, and a marker's pose back.
    #[test]
    fn recovers_a_known_homography() {
        let layout = MarkerLayout::default_table();
        let cam = CameraModel::overhead(layout.table, 960, 720, 16.0).tilted(2e-5, -1e-5);
        let h = cam.table_to_pixel;
        let dets: Vec<Detection> = layout
            .calibration
            .iter()
            .map(|m| {
                let p = m.placement();
                det(
                    m.id,
                    p.corners().map(|c| h.apply(c).unwrap()),
                    h.apply(p.centre).unwrap(),
                )
            })
            .collect();
        let cal = Calibration::fit(&[dets], &layout, [960, 720]).unwrap();
        assert!(cal.rms_px < 1e-6, "{}", cal.rms_px);
        assert_eq!(cal.markers, vec![0, 1, 2, 3, 4, 5]);
        for p in [[0.3, 0.2], [1.0, 0.7]] {
            let a = cal.table_to_pixel.apply(p).unwrap();
            let b = h.apply(p).unwrap();
            assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-6);
        }
        assert!((cal.mm_per_px - 1.31).abs() < 0.05, "{}", cal.mm_per_px);
        let body = pushbot_world::camera::MarkerPlacement {
            id: 10,
            family: MarkerFamily::Tag36h11,
            centre: [0.4, 0.3],
            heading: 2.5,
            side: 0.05,
            height: 0.0,
        };
        let (pose, side) = cal
            .marker_pose(&det(
                10,
                body.corners().map(|c| h.apply(c).unwrap()),
                [0.0; 2],
            ))
            .unwrap();
        assert!(
            (pose.x - 0.4).abs() < 1e-9
                && (pose.y - 0.3).abs() < 1e-9
                && (pose.theta - 2.5).abs() < 1e-9
        );
        assert!((side - 0.05).abs() < 1e-9);
        // Save and load.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cal.json");
        cal.save(&path).unwrap();
        let back = Calibration::load(&path).unwrap();
        assert_eq!(back.markers, cal.markers);
        for (a, b) in back
            .pixel_to_table
            .0
            .iter()
            .flatten()
            .zip(cal.pixel_to_table.0.iter().flatten())
        {
            assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()));
        }
        std::fs::write(&path, "{}").unwrap();
        assert!(Calibration::load(&path).is_err());
    }

    #[test]
    fn too_few_markers_is_an_error() {
        let layout = MarkerLayout::default_table();
        let dets = vec![det(
            0,
            [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]],
            [1.5, 1.5],
        )];
        assert!(matches!(
            Calibration::fit(&[dets], &layout, [960, 720]),
            Err(CalibrationError::TooFewMarkers { .. })
        ));
    }
}
