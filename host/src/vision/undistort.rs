//! Undistortion where it is needed: the detected marker corners and centres, not the whole
//! image. A detection's points go through the lens's inverse
//! ([`pushbot_world::lens::Intrinsics::undistort_pixel`]) into the ideal pinhole image, where
//! the table is a plane seen through a homography again and the calibration and measurement
//! hold as for an ideal camera. Detections stay in raw pixels for drawing and for the regions
//! of interest; only what is measured is undistorted.

use pushbot_world::lens::Intrinsics;

use super::detection::Detection;

/// The detections as an ideal camera with `lens`'s focal lengths and centre would see them;
/// a detection with a point the lens cannot invert (far outside its image) is dropped.
pub fn undistort_detections(dets: &[Detection], lens: &Intrinsics) -> Vec<Detection> {
    dets.iter()
        .filter_map(|d| {
            let mut corners = d.corners;
            for c in &mut corners {
                *c = lens.undistort_pixel(*c)?;
            }
            Some(Detection {
                corners,
                centre: lens.undistort_pixel(d.centre)?,
                ..*d
            })
        })
        .collect()
}

/// What is wrong with using `lens` on frames of `size` (px), if anything: a lens file is made
/// for one image size.
pub fn lens_mismatch(lens: &Intrinsics, size: [u32; 2]) -> Option<String> {
    if let Some(p) = lens.problem() {
        return Some(format!("the lens: {p}"));
    }
    ([lens.width, lens.height] != size).then(|| {
        format!(
            "the lens file is for {}×{} frames, the camera gives {}×{}",
            lens.width, lens.height, size[0], size[1]
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_world::camera::MarkerFamily;
    use pushbot_world::lens::Distortion;

    #[test]
    fn corners_come_back_to_the_ideal_image() {
        let lens = Intrinsics {
            width: 960,
            height: 720,
            fx: 700.0,
            fy: 700.0,
            cx: 480.0,
            cy: 360.0,
            distortion: Distortion {
                k1: -0.08,
                ..Distortion::NONE
            },
        };
        let ideal = [[100.0, 80.0], [140.0, 80.0], [140.0, 120.0], [100.0, 120.0]];
        let distort = |p: [f64; 2]| lens.distort_pixel(p);
        let det = Detection {
            family: MarkerFamily::Tag36h11,
            id: 4,
            corners: ideal.map(distort),
            centre: distort([120.0, 100.0]),
            hamming: 0,
            margin: 50.0,
        };
        assert!((det.corners[0][0] - 100.0).abs() > 5.0, "the lens moved it");
        let out = undistort_detections(&[det], &lens);
        for (c, want) in out[0].corners.iter().zip(ideal) {
            assert!(
                (c[0] - want[0]).hypot(c[1] - want[1]) < 1e-6,
                "{c:?} {want:?}"
            );
        }
        assert_eq!(out[0].id, 4);
        assert!(lens_mismatch(&lens, [960, 720]).is_none());
        let e = lens_mismatch(&lens, [640, 480]).unwrap();
        assert!(e.contains("960×720") && e.contains("640×480"), "{e}");
    }
}
