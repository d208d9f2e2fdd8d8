//! The intrinsics files users already have, read and written: ROS `camera_info` YAML
//! (`image_width`, `image_height`, `camera_matrix`, `distortion_model`,
//! `distortion_coefficients`, as `camera_calibration` writes it) and OpenCV `FileStorage` YAML
//! (`%YAML:1.0`, `camera_matrix` and `distortion_coefficients` as `!!opencv-matrix`, the image
//! size as `image_width`/`image_height` when present). Parsed with `serde-saphyr`; errors name
//! the file, line and column.
//!
//! Both formats put pixel centres at integers; [`Intrinsics`] at `i + 0.5` — the principal
//! point is shifted by half a pixel on the way in and out.

use std::path::Path;

use serde::Deserialize;

use crate::lens::{Distortion, Intrinsics};

/// Why an intrinsics file was refused.
#[derive(Debug, thiserror::Error)]
pub enum LensFileError {
    /// The file could not be read.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said.
        reason: String,
    },
    /// Not YAML of either format.
    #[error("{path}: not a ROS camera_info or OpenCV FileStorage YAML file: {reason}")]
    Format {
        /// The file.
        path: String,
        /// What the parser said (with line and column).
        reason: String,
    },
    /// The values make no camera.
    #[error("{path}: {reason}")]
    Values {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
}

/// A matrix as either format writes it (`rows`, `cols`, `data`; OpenCV adds `dt`).
#[derive(Debug, Deserialize)]
struct Matrix {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

/// The fields both formats share (others are ignored).
#[derive(Debug, Deserialize)]
struct File {
    image_width: Option<u32>,
    image_height: Option<u32>,
    camera_matrix: Matrix,
    distortion_model: Option<String>,
    distortion_coefficients: Option<Matrix>,
}

/// Which of the two formats to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LensFormat {
    /// ROS `camera_info` YAML.
    Ros,
    /// OpenCV `FileStorage` YAML.
    OpenCv,
}

/// Read intrinsics from YAML text of either format; `path` names it in errors.
pub fn parse_intrinsics(path: &str, text: &str) -> Result<Intrinsics, LensFileError> {
    let values = |reason: String| LensFileError::Values {
        path: path.to_string(),
        reason,
    };
    let f: File = serde_saphyr::from_str(text).map_err(|e| LensFileError::Format {
        path: path.to_string(),
        reason: e.to_string(),
    })?;
    let m = &f.camera_matrix;
    if m.rows != 3 || m.cols != 3 || m.data.len() != 9 {
        return Err(values(format!(
            "camera_matrix must be 3×3 with 9 values, not {}×{} with {}",
            m.rows,
            m.cols,
            m.data.len()
        )));
    }
    if m.data[1] != 0.0 || m.data[3] != 0.0 || m.data[6..] != [0.0, 0.0, 1.0] {
        return Err(values(format!(
            "camera_matrix must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew), not {:?}",
            m.data
        )));
    }
    if let Some(model) = &f.distortion_model
        && !matches!(model.as_str(), "plumb_bob" | "rational_polynomial")
    {
        return Err(values(format!(
            "distortion_model {model:?}: only plumb_bob (k1, k2, p1, p2, k3) is supported"
        )));
    }
    let coeffs = f
        .distortion_coefficients
        .map(|d| d.data)
        .unwrap_or_default();
    if coeffs.len() > 5 && coeffs[5..].iter().any(|&c| c != 0.0) {
        return Err(values(format!(
            "{} distortion coefficients with non-zero ones past the fifth: only plumb_bob \
             (k1, k2, p1, p2, k3) is supported",
            coeffs.len()
        )));
    }
    let (Some(width), Some(height)) = (f.image_width, f.image_height) else {
        return Err(values(
            "image_width and image_height are missing: intrinsics hold for one image size only"
                .into(),
        ));
    };
    let cam = Intrinsics {
        width,
        height,
        fx: m.data[0],
        fy: m.data[4],
        cx: m.data[2] + 0.5,
        cy: m.data[5] + 0.5,
        distortion: Distortion::from_slice(&coeffs),
    };
    match cam.problem() {
        Some(p) => Err(values(p)),
        None => Ok(cam),
    }
}

/// Read an intrinsics file of either format.
pub fn read_intrinsics(path: &Path) -> Result<Intrinsics, LensFileError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| LensFileError::Io {
        path: name.clone(),
        reason: e.to_string(),
    })?;
    parse_intrinsics(&name, &text)
}

/// Numbers as YAML writes them: shortest text that reads back to the same f64.
fn list(values: &[f64]) -> String {
    let v: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
    v.join(", ")
}

/// The intrinsics as a file of `format` (`name`: the camera's name, ROS only).
pub fn write_intrinsics(cam: &Intrinsics, format: LensFormat, name: &str) -> String {
    let k = [
        cam.fx,
        0.0,
        cam.cx - 0.5,
        0.0,
        cam.fy,
        cam.cy - 0.5,
        0.0,
        0.0,
        1.0,
    ];
    let d = cam.distortion.to_array();
    match format {
        LensFormat::Ros => {
            let p = [
                cam.fx,
                0.0,
                cam.cx - 0.5,
                0.0,
                0.0,
                cam.fy,
                cam.cy - 0.5,
                0.0,
                0.0,
                0.0,
                1.0,
                0.0,
            ];
            format!(
                "image_width: {}\nimage_height: {}\ncamera_name: {}\ncamera_matrix:\n  rows: 3\n  \
                 cols: 3\n  data: [{}]\ndistortion_model: plumb_bob\ndistortion_coefficients:\n  \
                 rows: 1\n  cols: 5\n  data: [{}]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  \
                 data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\nprojection_matrix:\n  rows: \
                 3\n  cols: 4\n  data: [{}]\n",
                cam.width,
                cam.height,
                name,
                list(&k),
                list(&d),
                list(&p)
            )
        }
        LensFormat::OpenCv => format!(
            "%YAML:1.0\n---\nimage_width: {}\nimage_height: {}\ncamera_matrix: !!opencv-matrix\n   \
             rows: 3\n   cols: 3\n   dt: d\n   data: [ {} ]\ndistortion_coefficients: \
             !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ {} ]\n",
            cam.width,
            cam.height,
            list(&k),
            list(&d)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// As ROS's `camera_calibration` writes it (values of a real 640×480 webcam).
    const ROS: &str = "image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [628.20, 0.00, 314.46, 0.00, 627.81, 243.11, 0.00, 0.00, 1.00]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.0789, 0.1521, 0.0012, -0.0004, 0.0000]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
projection_matrix:
  rows: 3
  cols: 4
  data: [620.4, 0.0, 313.9, 0.0, 0.0, 622.1, 243.2, 0.0, 0.0, 0.0, 1.0, 0.0]
";

    /// As OpenCV's `FileStorage` writes it (`%YAML:1.0`, `!!opencv-matrix`).
    const OPENCV: &str = "%YAML:1.0
---
image_width: 960
image_height: 720
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 7.0e+02, 0., 4.8e+02, 0., 7.0e+02, 3.6e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -8.0e-02, 0., 0., 0., 0. ]
";

    #[test]
    fn both_formats_are_read() {
        let r = parse_intrinsics("ros.yaml", ROS).expect("ROS camera_info");
        assert_eq!((r.width, r.height), (640, 480));
        assert_eq!((r.fx, r.fy), (628.20, 627.81));
        assert_eq!(
            (r.cx, r.cy),
            (314.96, 243.61),
            "half a pixel: centres at i + 0.5"
        );
        assert_eq!(r.distortion.k1, -0.0789);
        assert_eq!(r.distortion.p2, -0.0004);
        let c = parse_intrinsics("cv.yaml", OPENCV).expect("OpenCV FileStorage");
        assert_eq!((c.width, c.height, c.fx, c.cx), (960, 720, 700.0, 480.5));
        assert_eq!(c.distortion.k1, -0.08);
    }

    #[test]
    fn what_is_written_reads_back_the_same_in_both_formats() {
        let cam = parse_intrinsics("ros.yaml", ROS).unwrap();
        for f in [LensFormat::Ros, LensFormat::OpenCv] {
            let text = write_intrinsics(&cam, f, "pushbot");
            let back = parse_intrinsics("written.yaml", &text).expect("reads back");
            assert_eq!(back, cam, "{f:?}:\n{text}");
        }
    }

    #[test]
    fn bad_files_get_errors_that_say_where_and_why() {
        let e = parse_intrinsics("a.yaml", "image_width: 640\nimage_height: [\n").unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("a.yaml: not a ROS"), "{msg}");
        assert!(msg.contains("line 2"), "{msg}");
        let e = parse_intrinsics("b.yaml", &ROS.replace("plumb_bob", "equidistant")).unwrap_err();
        assert!(e.to_string().contains("only plumb_bob"), "{e}");
        let e = parse_intrinsics("c.yaml", &ROS.replace("image_width: 640\n", "")).unwrap_err();
        assert!(e.to_string().contains("image_width"), "{e}");
        let e =
            parse_intrinsics("d.yaml", &ROS.replace("628.20, 0.00", "-628.20, 0.00")).unwrap_err();
        assert!(e.to_string().contains("positive"), "{e}");
        let e = read_intrinsics(Path::new("/nonexistent/cam.yaml")).unwrap_err();
        assert!(e.to_string().starts_with("/nonexistent/cam.yaml"), "{e}");
    }
}
