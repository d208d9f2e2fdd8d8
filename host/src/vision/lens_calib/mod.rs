//! Lens calibration from frames of a printed AprilTag board ([`pushbot_world::board`]): Zhang's
//! method (Zhang 2000, "A flexible new technique for camera calibration", IEEE TPAMI 22(11))
//! for OpenCV's camera model (pinhole, zero skew, `plumb_bob` distortion k1 k2 p1 p2 k3).
//!
//! Each frame's detected tags are matched to the board's layout by id, their corners pair with
//! board points ([`BoardViews::add`]); a view with enough tags gets its board → pixel homography
//! (normalised DLT, [`super::homography`]); Zhang's closed form gives the camera matrix and each
//! view's pose ([`zhang`]); Levenberg–Marquardt refines the intrinsics, the distortion and
//! every pose on the reprojection error ([`refine`]). The result reports the RMS reprojection
//! error, each view's, and how much of the image the corners cover; [`LensFit::refusal`] says
//! why a fit should not be trusted.

pub mod refine;
pub mod zhang;

use nalgebra::Matrix3;
use pushbot_world::board::BoardLayout;
use pushbot_world::lens::Intrinsics;
use serde::Serialize;

use super::detection::Detection;
use super::homography::fit_homography;
use refine::Observations;

/// A corner reprojected this many times the RMS error off is an outlier ([`LensFit::outliers`]).
pub const OUTLIER_FACTOR: f64 = 5.0;
/// … and at least this far off, pixels.
pub const OUTLIER_MIN_PX: f64 = 1.0;

/// The most views fitted at once (the solver's Jacobian is dense: 40 views of 48 tags are
/// 15 360 residuals × 249 parameters); of more, an even spread in frame order is used.
pub const MAX_VIEWS: usize = 40;

/// Tags a view needs to count.
pub const MIN_TAGS_PER_VIEW: usize = 4;

/// The grid of image cells coverage is counted in (columns, rows).
pub const COVERAGE_GRID: [u32; 2] = [8, 6];

/// When a fit is refused.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Requirements {
    /// Fewest usable views.
    pub min_views: usize,
    /// Largest RMS reprojection error, pixels.
    pub max_rms_px: f64,
    /// Smallest fraction of the image's cells ([`COVERAGE_GRID`]) with a corner in them.
    pub min_coverage: f64,
}

impl Default for Requirements {
    fn default() -> Self {
        Requirements {
            min_views: 4,
            max_rms_px: 1.0,
            min_coverage: 0.5,
        }
    }
}

/// Why no lens could be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LensCalibError {
    /// A frame of another size than the first.
    #[error(
        "frame {name} is {got:?} pixels, the first frame {want:?}: all frames must come from one camera at one size"
    )]
    FrameSize {
        /// The frame.
        name: String,
        /// Its size.
        got: [u32; 2],
        /// The first frame's.
        want: [u32; 2],
    },
    /// Too few views showed the board.
    #[error(
        "{usable} of {frames} frames show the board usably (at least {MIN_TAGS_PER_VIEW} of its tags), {needed} are needed: take more frames of the whole board at different angles and places in the image"
    )]
    TooFewViews {
        /// Usable views.
        usable: usize,
        /// Frames looked at.
        frames: usize,
        /// Views needed.
        needed: usize,
    },
    /// The views determine no camera.
    #[error(
        "the views determine no camera ({0}): tilt the board differently between frames (some 20–45° away from facing the camera)"
    )]
    Degenerate(String),
}

/// One view of the board: its name, the tags seen and the matched points.
#[derive(Debug, Clone)]
pub struct BoardView {
    /// The frame's name (its file).
    pub name: String,
    /// Board tags seen.
    pub tags: usize,
    /// Board points and pixels.
    pub points: Observations,
}

/// The views collected from frames.
#[derive(Debug, Clone)]
pub struct BoardViews {
    board: BoardLayout,
    size: Option<[u32; 2]>,
    frames: usize,
    views: Vec<BoardView>,
}

impl BoardViews {
    /// No views yet, of `board`.
    pub fn new(board: BoardLayout) -> BoardViews {
        BoardViews {
            board,
            size: None,
            frames: 0,
            views: Vec::new(),
        }
    }

    /// Add a frame's detections; returns how many board tags it showed (a view counts with at
    /// least [`MIN_TAGS_PER_VIEW`]). Frames of another size than the first are refused.
    pub fn add(
        &mut self,
        name: &str,
        size: [u32; 2],
        dets: &[Detection],
    ) -> Result<usize, LensCalibError> {
        match self.size {
            Some(want) if want != size => {
                return Err(LensCalibError::FrameSize {
                    name: name.to_string(),
                    got: size,
                    want,
                });
            }
            _ => self.size = Some(size),
        }
        self.frames += 1;
        let mut points = Observations {
            board: Vec::new(),
            pixels: Vec::new(),
        };
        let mut tags = 0;
        for d in dets {
            // An id seen twice in one frame is a misreading: neither is used.
            let twice = dets
                .iter()
                .filter(|e| e.id == d.id && e.family == d.family)
                .count()
                > 1;
            let Some(corners) = self.board.corners(d.family, d.id) else {
                continue;
            };
            if twice || d.corners.iter().flatten().any(|v| !v.is_finite()) {
                continue;
            }
            tags += 1;
            points.board.extend_from_slice(&corners);
            points.pixels.extend_from_slice(&d.corners);
        }
        if tags >= MIN_TAGS_PER_VIEW {
            self.views.push(BoardView {
                name: name.to_string(),
                tags,
                points,
            });
        }
        Ok(tags)
    }

    /// The frames' size (of the first frame added).
    pub fn size(&self) -> Option<[u32; 2]> {
        self.size
    }

    /// The usable views so far.
    pub fn views(&self) -> &[BoardView] {
        &self.views
    }

    /// Fit the lens to the views (at least `min_views` of them).
    pub fn fit(&self, min_views: usize) -> Result<LensFit, LensCalibError> {
        let too_few = |usable: usize| LensCalibError::TooFewViews {
            usable,
            frames: self.frames,
            needed: min_views.max(2),
        };
        let Some(size) = self.size else {
            return Err(too_few(0));
        };
        // Views whose homography cannot be fitted are dropped; of many, an even spread is kept.
        let mut views = Vec::new();
        let mut hs = Vec::new();
        for i in spread(self.views.len(), MAX_VIEWS) {
            let v = &self.views[i];
            if let Ok(h) = fit_homography(&v.points.board, &v.points.pixels) {
                hs.push(Matrix3::from_fn(|r, c| h.0[r][c]));
                views.push(v);
            }
        }
        if views.len() < min_views.max(2) {
            return Err(too_few(views.len()));
        }
        let k = zhang::camera_matrix(&hs, size).ok_or_else(|| {
            LensCalibError::Degenerate("Zhang's closed form found no camera matrix".into())
        })?;
        let poses = hs
            .iter()
            .map(|h| zhang::pose(&k, h))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| LensCalibError::Degenerate("a view's pose".into()))?;
        let start = Intrinsics {
            width: size[0],
            height: size[1],
            fx: k[(0, 0)],
            fy: k[(1, 1)],
            cx: k[(0, 2)],
            cy: k[(1, 2)],
            distortion: pushbot_world::lens::Distortion::NONE,
        };
        let mut obs: Vec<Observations> = views.iter().map(|v| v.points.clone()).collect();
        let no_fit = || LensCalibError::Degenerate("the refinement did not converge".into());
        let mut r = refine::refine(&start, &poses, &obs).ok_or_else(no_fit)?;
        let outliers = drop_outliers(&mut obs, &r.errors);
        if outliers > 0 {
            r = refine::refine(&r.intrinsics, &r.poses, &obs).ok_or_else(no_fit)?;
        }
        if let Some(p) = r.intrinsics.problem() {
            return Err(LensCalibError::Degenerate(format!("the fitted lens: {p}")));
        }
        let all: Vec<f64> = r.errors.iter().flatten().copied().collect();
        let view_fits = views
            .iter()
            .zip(&r.errors)
            .map(|(v, e)| ViewFit {
                name: v.name.clone(),
                tags: v.tags,
                rms_px: rms(e),
                max_px: e.iter().copied().fold(0.0, f64::max),
            })
            .collect();
        Ok(LensFit {
            intrinsics: r.intrinsics,
            rms_px: rms(&all),
            max_px: all.iter().copied().fold(0.0, f64::max),
            points: all.len(),
            outliers,
            coverage: coverage(obs.iter().map(|o| &o.pixels[..]), size),
            views: view_fits,
            frames: self.frames,
            evaluations: r.evaluations,
        })
    }
}

/// Drop the corners reprojected more than [`OUTLIER_FACTOR`] × the RMS error (and at least
/// [`OUTLIER_MIN_PX`]) off — a misread corner of a half-hidden tag or a reflection — when they
/// are few (at most 5 % of all) and each view keeps 16 corners; returns how many were dropped.
fn drop_outliers(obs: &mut [Observations], errors: &[Vec<f64>]) -> usize {
    let all: Vec<f64> = errors.iter().flatten().copied().collect();
    let limit = (OUTLIER_FACTOR * rms(&all)).max(OUTLIER_MIN_PX);
    let bad = all.iter().filter(|&&e| e > limit).count();
    if bad == 0 || bad * 20 > all.len() {
        return 0;
    }
    let mut dropped = 0;
    for (o, e) in obs.iter_mut().zip(errors) {
        let keep: Vec<bool> = e.iter().map(|&v| v <= limit).collect();
        let kept = keep.iter().filter(|&&k| k).count();
        if kept == e.len() || kept < 16 {
            continue;
        }
        let mut k = keep.iter();
        o.board.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        o.pixels.retain(|_| *k.next().unwrap_or(&true));
        dropped += e.len() - kept;
    }
    dropped
}

/// At most `max` of the indices `0..n`, evenly spread from the first to the last.
fn spread(n: usize, max: usize) -> Vec<usize> {
    if n <= max || max < 2 {
        return (0..n.min(max)).collect();
    }
    (0..max).map(|k| k * (n - 1) / (max - 1)).collect()
}

fn rms(e: &[f64]) -> f64 {
    if e.is_empty() {
        return 0.0;
    }
    (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
}

/// The fraction of a `size` image's [`COVERAGE_GRID`] cells with at least one of the points.
pub fn coverage<'a>(views: impl Iterator<Item = &'a [[f64; 2]]>, size: [u32; 2]) -> f64 {
    let [gc, gr] = COVERAGE_GRID;
    let mut hit = vec![false; (gc * gr) as usize];
    for p in views.flatten() {
        let c = (p[0] / f64::from(size[0]) * f64::from(gc)).floor();
        let r = (p[1] / f64::from(size[1]) * f64::from(gr)).floor();
        if (0.0..f64::from(gc)).contains(&c) && (0.0..f64::from(gr)).contains(&r) {
            hit[r as usize * gc as usize + c as usize] = true;
        }
    }
    hit.iter().filter(|&&h| h).count() as f64 / hit.len() as f64
}

/// How one view fits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewFit {
    /// The frame.
    pub name: String,
    /// Board tags seen.
    pub tags: usize,
    /// RMS reprojection error, pixels.
    pub rms_px: f64,
    /// Largest reprojection error, pixels.
    pub max_px: f64,
}

/// A fitted lens and how well it fits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LensFit {
    /// The lens.
    pub intrinsics: Intrinsics,
    /// RMS reprojection error over all corners, pixels.
    pub rms_px: f64,
    /// Largest reprojection error, pixels.
    pub max_px: f64,
    /// Corners used.
    pub points: usize,
    /// Corners dropped as misread (far off the first fit, and few).
    pub outliers: usize,
    /// Fraction of the image's cells ([`COVERAGE_GRID`]) with a corner.
    pub coverage: f64,
    /// Every usable view.
    pub views: Vec<ViewFit>,
    /// Frames looked at.
    pub frames: usize,
    /// Residual evaluations of the solver.
    pub evaluations: usize,
}

impl LensFit {
    /// Why this fit should not be used, if it should not: too few views, corners covering too
    /// little of the image, or a poor reprojection error.
    pub fn refusal(&self, req: &Requirements) -> Option<String> {
        if self.views.len() < req.min_views {
            Some(format!(
                "only {} usable views, at least {} are needed: take more frames of the whole \
                 board at different angles and places in the image",
                self.views.len(),
                req.min_views
            ))
        } else if self.coverage < req.min_coverage {
            Some(format!(
                "the board's corners cover {:.0} % of the image ({} × {} cells with a corner), \
                 at least {:.0} % is needed: the distortion is only known where the board was \
                 seen; take frames with the board near the edges and corners of the image",
                100.0 * self.coverage,
                COVERAGE_GRID[0],
                COVERAGE_GRID[1],
                100.0 * req.min_coverage
            ))
        } else if self.rms_px.is_nan() || self.rms_px > req.max_rms_px {
            let worst = self
                .views
                .iter()
                .max_by(|a, b| a.rms_px.total_cmp(&b.rms_px))
                .map(|v| format!(" (worst view {}: {:.2} px)", v.name, v.rms_px))
                .unwrap_or_default();
            Some(format!(
                "the RMS reprojection error is {:.2} px, more than {:.2} px{worst}: the board \
                 is not flat, its layout does not match the print (measure tag_side), or frames \
                 are blurred; drop blurred frames, flatten the board and calibrate again",
                self.rms_px, req.max_rms_px
            ))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_world::camera::MarkerFamily;

    fn det(id: u32, corners: [[f64; 2]; 4]) -> Detection {
        Detection {
            family: MarkerFamily::Tag36h11,
            id,
            corners,
            centre: [0.0; 2],
            hamming: 0,
            margin: 50.0,
        }
    }

    #[test]
    fn detections_pair_with_the_board_and_frame_sizes_must_agree() {
        let board = BoardLayout::default();
        let mut v = BoardViews::new(board);
        let sq = [[0.0, 10.0], [10.0, 10.0], [10.0, 0.0], [0.0, 0.0]];
        let dets: Vec<_> = (100..105)
            .map(|id| det(id, sq))
            .chain([det(7, sq)])
            .collect();
        assert_eq!(v.add("a.png", [960, 720], &dets).unwrap(), 5);
        assert_eq!(v.views().len(), 1);
        assert_eq!(v.views()[0].points.board.len(), 20);
        // A repeated id is dropped, leaving 3 tags: not a view.
        let few = [
            det(100, sq),
            det(101, sq),
            det(101, sq),
            det(102, sq),
            det(103, sq),
        ];
        assert_eq!(v.add("b.png", [960, 720], &few).unwrap(), 3);
        assert_eq!(v.views().len(), 1);
        let e = v.add("c.png", [640, 480], &dets).unwrap_err();
        assert!(e.to_string().contains("c.png"), "{e}");
        let e = v.fit(4).unwrap_err();
        assert!(
            matches!(e, LensCalibError::TooFewViews { usable: 1, .. }),
            "{e}"
        );
    }

    /// Exact corners of the board seen through a known lens from five poses, one of them
    /// misread by 8 px: the fit drops it and finds the lens.
    #[test]
    fn a_misread_corner_is_dropped_and_the_lens_found() {
        use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};
        let truth = Intrinsics {
            width: 960,
            height: 720,
            fx: 700.0,
            fy: 702.0,
            cx: 483.0,
            cy: 357.0,
            distortion: pushbot_world::lens::Distortion {
                k1: -0.08,
                k2: 0.02,
                p1: 0.001,
                p2: -0.0005,
                k3: 0.0,
            },
        };
        let board = BoardLayout::default();
        let mut views = BoardViews::new(board);
        for (i, (rx, ry, tx, ty)) in [
            (0.3, 0.1, -0.25, 0.2),
            (-0.3, 0.2, 0.0, 0.2),
            (0.2, -0.3, -0.25, 0.0),
            (-0.2, -0.2, 0.0, 0.0),
            (0.0, 0.4, -0.12, 0.1),
        ]
        .into_iter()
        .enumerate()
        {
            let pose = Isometry3::from_parts(
                Translation3::new(tx, ty, 0.5),
                UnitQuaternion::from_euler_angles(rx + std::f64::consts::PI, ry, 0.0),
            );
            let dets: Vec<Detection> = board
                .placements()
                .iter()
                .map(|p| {
                    det(
                        p.id,
                        p.corners().map(|b| {
                            let c = pose * Point3::new(b[0], b[1], 0.0);
                            truth.project([c.x, c.y, c.z]).unwrap()
                        }),
                    )
                })
                .map(|mut d| {
                    if i == 2 && d.id == 120 {
                        d.corners[1][0] += 8.0;
                    }
                    d
                })
                .collect();
            views.add(&format!("v{i}"), [960, 720], &dets).unwrap();
        }
        let fit = views.fit(4).unwrap();
        assert_eq!(fit.outliers, 1);
        assert_eq!(fit.points, 5 * 48 * 4 - 1);
        assert!(fit.rms_px < 1e-4, "{}", fit.rms_px);
        let l = fit.intrinsics;
        assert!(
            (l.fx - truth.fx).abs() < 1e-3 && (l.cy - truth.cy).abs() < 1e-3,
            "{l:?}"
        );
        assert!(
            (l.distortion.k1 - truth.distortion.k1).abs() < 1e-5,
            "{l:?}"
        );
    }

    #[test]
    fn many_views_are_thinned_evenly() {
        assert_eq!(spread(5, 40), vec![0, 1, 2, 3, 4]);
        let s = spread(100, 40);
        assert_eq!((s.len(), s[0], s[39]), (40, 0, 99));
        assert!(s.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] <= 3));
    }

    #[test]
    fn coverage_counts_cells() {
        let centre = [[490.0, 370.0], [500.0, 380.0]];
        assert!((coverage([&centre[..]].into_iter(), [960, 720]) - 1.0 / 48.0).abs() < 1e-12);
        let corners = [[1.0, 1.0], [959.0, 719.0], [-5.0, 3.0]];
        assert!((coverage([&corners[..]].into_iter(), [960, 720]) - 2.0 / 48.0).abs() < 1e-12);
    }
}
