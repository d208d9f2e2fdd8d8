//! The simulated overhead camera (Lau et al. §IV: a ceiling camera sees the table from above, with
//! markers on the robot, the objects and the goals; 960×720 at 30 fps).
//!
//! [`Camera::capture`] renders one grayscale frame of the table at a simulated time: polygons for
//! the table and the bodies, AprilTag markers (tag36h11 by default) with a white quiet zone, then
//! blur, exposure and seeded noise. Every frame carries its ground truth: each marker's pose on
//! the table and its exact corners in pixels (pixel centres at `i + 0.5`). Frames can be written
//! as PNG files ([`CameraFrame::write_png`]) or served over a local socket ([`server`]).

pub mod blur;
pub mod board;
pub mod draw;
pub mod families;
pub mod lens;
pub mod live;
mod redraw;
pub mod render;
pub mod scene_view;
pub mod sensor;
pub mod server;

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

pub use draw::{Overlay, View};
pub use render::{Homography, MarkerFamily, MarkerPlacement, Polygon, TagCodes};
pub use scene_view::{SceneCamera, scene_view};

pub use pushbot_world::camera::{CameraModel, MarkerTruth};
use pushbot_world::camera_pose::CameraPose;

/// Optics and sensor of the simulated camera.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Imaging {
    /// Gaussian blur, standard deviation in pixels (0.6–1.0 is mild).
    pub blur_sigma_px: f64,
    /// Sensor noise, standard deviation in gray levels.
    pub noise_sigma: f64,
    /// Exposure multiplier (1 nominal).
    pub exposure: f64,
    /// Gray level of a perfectly black surface.
    pub black_level: f64,
    /// Gray level of a perfectly white surface at exposure 1.
    pub white_level: f64,
    /// Reflectance of the table top.
    pub table_shade: f64,
    /// Reflectance of what is around the table.
    pub floor_shade: f64,
    /// Reflectance of the markers' black and white.
    pub ink: [f64; 2],
    /// White quiet zone around each tag beyond its own white border, in tag cells.
    pub quiet_cells: f64,
    /// Sub-rows per pixel row of polygons and markers (each with exact horizontal coverage).
    pub supersample: usize,
}

impl Default for Imaging {
    fn default() -> Self {
        Imaging {
            blur_sigma_px: 0.7,
            noise_sigma: 3.0,
            exposure: 1.0,
            black_level: 20.0,
            white_level: 235.0,
            table_shade: 0.55,
            floor_shade: 0.2,
            ink: [0.04, 0.95],
            quiet_cells: 1.0,
            supersample: 8,
        }
    }
}

/// Everything that makes a camera: where it looks, its optics, its frame rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraConfig {
    /// Geometry.
    pub model: CameraModel,
    /// Optics and sensor.
    pub imaging: Imaging,
    /// Frames per second of simulated time.
    pub fps: f64,
    /// Table size (metres), drawn as a rectangle from (0, 0).
    pub table: [f64; 2],
    /// A real lens: the image is drawn through `model` (the ideal pinhole) and then distorted
    /// by these intrinsics, made for the same image size ([`lens::LensWarp`]); with it the
    /// camera knows its place over the table (from `model` and the focal lengths), so what is
    /// at a height is drawn in perspective.
    pub lens: Option<pushbot_world::lens::Intrinsics>,
}

impl CameraConfig {
    /// 960×720 at 30 fps over a `table` (metres) with a 16 px margin, default optics.
    pub fn default_for_table(table: [f64; 2]) -> CameraConfig {
        CameraConfig {
            model: CameraModel::overhead(table, 960, 720, 16.0),
            imaging: Imaging::default(),
            fps: 30.0,
            table,
            lens: None,
        }
    }
}

/// One frame: 8-bit grayscale pixels row-major plus ground truth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraFrame {
    /// Frame number from 0.
    pub seq: u64,
    /// Simulated time of exposure, seconds.
    pub time: f64,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Gray levels, row-major, `width × height` bytes.
    #[serde(skip)]
    pub pixels: Vec<u8>,
    /// Ground truth of every marker drawn.
    pub truth: Vec<MarkerTruth>,
}

/// Why a frame could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum CameraError {
    /// A placement or the configuration is not drawable.
    #[error("camera: {0}")]
    Invalid(String),
    /// Writing a file failed.
    #[error("camera: {0}")]
    Io(#[from] std::io::Error),
}

impl CameraFrame {
    /// Write the frame as `frame-NNNNNN.png` and its ground truth (with `time`) as
    /// `frame-NNNNNN.json` into `dir`; returns the PNG's path.
    pub fn write_png(&self, dir: &Path) -> Result<PathBuf, CameraError> {
        std::fs::create_dir_all(dir)?;
        let png = dir.join(format!("frame-{:06}.png", self.seq));
        let img = image::GrayImage::from_raw(self.width, self.height, self.pixels.clone())
            .ok_or_else(|| {
                CameraError::Invalid("pixel buffer size does not match the frame size".into())
            })?;
        img.save(&png)
            .map_err(|e| CameraError::Io(std::io::Error::other(e)))?;
        let json = serde_json::to_string(self).map_err(|e| CameraError::Invalid(e.to_string()))?;
        std::fs::write(dir.join(format!("frame-{:06}.json", self.seq)), json)?;
        Ok(png)
    }
}

/// The simulated camera: renders frames of the table in simulated time with seeded noise.
#[derive(Debug, Clone)]
pub struct Camera {
    config: CameraConfig,
    codes: TagCodes,
    rng: ChaCha8Rng,
    seq: u64,
    /// The last scene drawn and its blurred irradiance: a frame of a scene that has not moved
    /// (the robot waiting for its host) differs from it only by the sensor's fresh noise.
    still: Option<Still>,
    /// The lens's warp, when the configuration has a lens that distorts.
    warp: Option<lens::LensWarp>,
    /// Where the camera is over the table, when the configuration has a lens.
    pose: Option<CameraPose>,
}

/// A drawn scene: what was drawn, the blurred irradiance, the markers' ground truth.
#[derive(Debug, Clone)]
struct Still {
    polygons: Vec<Polygon>,
    markers: Vec<MarkerPlacement>,
    overlays: Vec<Overlay>,
    irradiance: Vec<f32>,
    truth: Vec<MarkerTruth>,
    /// Of a scene drawn from one view, its image before the blur (and, with a lens, after the
    /// blur and before the warp): the next frame is drawn again only where it changed.
    sharp: Option<Sharp>,
}

/// The ideal image of a still before the optics' blur, and its blur when a lens warps it.
#[derive(Debug, Clone)]
struct Sharp {
    data: Vec<f32>,
    blurred: Option<Vec<f32>>,
}

impl Still {
    /// Whether `polygons` and `markers` draw the same image as this still (every coordinate
    /// within a micrometre, a thousandth of a pixel or less).
    fn same(
        &self,
        polygons: &[Polygon],
        markers: &[MarkerPlacement],
        overlays: &[Overlay],
    ) -> bool {
        const EPS: f64 = 1e-6;
        let close =
            |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() <= EPS && (a[1] - b[1]).abs() <= EPS;
        self.overlays == overlays
            && self.polygons.len() == polygons.len()
            && self.markers.len() == markers.len()
            && self.polygons.iter().zip(polygons).all(|(a, b)| {
                a.shade == b.shade
                    && a.points.len() == b.points.len()
                    && a.points.iter().zip(&b.points).all(|(p, q)| close(*p, *q))
            })
            && self.markers.iter().zip(markers).all(|(a, b)| {
                a.id == b.id
                    && a.family == b.family
                    && a.side == b.side
                    && close(a.centre, b.centre)
                    && (a.heading - b.heading).abs() <= EPS
                    && (a.height - b.height).abs() <= EPS
            })
    }
}

impl Camera {
    /// A camera with its own noise stream from `seed`.
    pub fn new(config: CameraConfig, seed: u64) -> Result<Camera, CameraError> {
        if config.model.table_to_pixel.inverse().is_none() {
            return Err(CameraError::Invalid(
                "table→pixel homography is singular".into(),
            ));
        }
        if !(config.fps.is_finite() && config.fps > 0.0)
            || config.model.width == 0
            || config.model.height == 0
        {
            return Err(CameraError::Invalid(
                "frame rate and image size must be positive".into(),
            ));
        }
        if let Some(l) = &config.lens
            && let Some(p) = l.problem()
        {
            return Err(CameraError::Invalid(format!("lens: {p}")));
        }
        // A lens that distorts warps the image; any lens (an ideal one too) gives the camera's
        // place over the table, so markers and occluders at a height are drawn in perspective.
        let warp = match config.lens {
            Some(l) if !l.distortion.is_none() => Some(
                lens::LensWarp::new(l, config.model.width, config.model.height)
                    .map_err(CameraError::Invalid)?,
            ),
            _ => None,
        };
        let pose = config
            .lens
            .and_then(|l| CameraPose::from_homography(&config.model.table_to_pixel, &l));
        if config.lens.is_some() && pose.is_none() {
            return Err(CameraError::Invalid(
                "the table homography is not a camera seeing the table through this lens".into(),
            ));
        }
        Ok(Camera {
            warp,
            pose,
            config,
            codes: TagCodes::new().map_err(CameraError::Invalid)?,
            rng: ChaCha8Rng::seed_from_u64(seed),
            seq: 0,
            still: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CameraConfig {
        &self.config
    }

    /// Seconds between frames.
    pub fn period(&self) -> f64 {
        1.0 / self.config.fps
    }

    /// Render the next frame at simulated `time`: table, `polygons` in order, then `markers`.
    pub fn capture(
        &mut self,
        time: f64,
        polygons: &[Polygon],
        markers: &[MarkerPlacement],
    ) -> Result<CameraFrame, CameraError> {
        self.capture_exposure(time, &[View { polygons, markers }], &[])
    }

    /// Render the next frame at simulated `time` from `views` of the scene spread evenly over
    /// the exposure (one: an instant; more: what moved between them smears), with `overlays`
    /// (things between the camera and the table, at their heights) drawn over everything. The
    /// ground truth is the middle view's.
    pub fn capture_exposure(
        &mut self,
        time: f64,
        views: &[View<'_>],
        overlays: &[Overlay],
    ) -> Result<CameraFrame, CameraError> {
        self.capture_exposure_within(time, views, overlays, None)
    }

    /// As [`Self::capture_exposure`], with the sensor read out only within `windows` (frame
    /// pixels) when given: every other pixel is 0 and draws no noise. For a reader that looks
    /// only there, as the host's tracker does between its whole-frame searches.
    pub fn capture_exposure_within(
        &mut self,
        time: f64,
        views: &[View<'_>],
        overlays: &[Overlay],
        windows: Option<&[render::Window]>,
    ) -> Result<CameraFrame, CameraError> {
        let still = matches!(views, [v] if self.still.as_ref().is_some_and(|s| s.same(v.polygons, v.markers, overlays)));
        if !still {
            // One view after one view: drawn again where something moved; otherwise whole.
            let redrawn = match (views, self.still.take()) {
                ([v], Some(mut s)) => self.redraw(&mut s, v, overlays)?.then_some(s),
                _ => None,
            };
            self.still = Some(match redrawn {
                Some(s) => s,
                None => self.draw(views, overlays)?,
            });
        }
        let Some(still) = &self.still else {
            return Err(CameraError::Invalid("no image drawn".into()));
        };
        let cfg = &self.config;
        let im = &cfg.imaging;
        let levels =
            sensor::Levels::new(im.exposure, im.black_level, im.white_level, im.noise_sigma);
        let pixels = match windows {
            Some(w) => sensor::develop_within(
                &still.irradiance,
                cfg.model.width as usize,
                w,
                &levels,
                &mut self.rng,
            ),
            None => sensor::develop(
                &still.irradiance,
                im.exposure,
                im.black_level,
                im.white_level,
                im.noise_sigma,
                &mut self.rng,
            ),
        };
        let frame = CameraFrame {
            seq: self.seq,
            time,
            width: cfg.model.width,
            height: cfg.model.height,
            pixels,
            truth: still.truth.clone(),
        };
        self.seq += 1;
        Ok(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overhead_maps_table_corners_inside_image() {
        let m = CameraModel::overhead([1.2, 0.9], 960, 720, 16.0);
        let a = m.table_to_pixel.apply([0.0, 0.9]).unwrap();
        let b = m.table_to_pixel.apply([1.2, 0.0]).unwrap();
        assert!(
            a[0] >= 15.9 && a[1] >= 15.9 && b[0] <= 944.1 && b[1] <= 704.1,
            "{a:?} {b:?}"
        );
        let t = m.tilted(1e-5, -1e-5);
        let c = t.table_to_pixel.apply([0.6, 0.45]).unwrap();
        assert!(
            (c[0] - 480.0).abs() < 1e-9 && (c[1] - 360.0).abs() < 1e-9,
            "centre stays: {c:?}"
        );
    }

    /// A still scene is drawn once: the next frame has the same image under fresh noise, the
    /// same truth, and equals what a fresh camera draws; a moved marker is drawn anew.
    #[test]
    fn a_still_scene_is_drawn_once_and_a_moved_one_again() {
        let cfg = CameraConfig::default_for_table([1.2, 0.9]);
        let m = MarkerPlacement {
            id: 3,
            family: MarkerFamily::Tag36h11,
            centre: [0.5, 0.4],
            heading: 0.2,
            side: 0.05,
            height: 0.0,
        };
        let mut cam = Camera::new(cfg, 9).unwrap();
        let a = cam.capture(0.0, &[], &[m]).unwrap();
        let b = cam.capture(0.1, &[], &[m]).unwrap();
        assert_ne!(a.pixels, b.pixels, "fresh noise in every frame");
        let mean_diff = a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(x, y)| (f64::from(*x) - f64::from(*y)).abs())
            .sum::<f64>()
            / a.pixels.len() as f64;
        assert!(
            mean_diff < 4.0 * cfg.imaging.noise_sigma + 0.5,
            "{mean_diff}"
        );
        assert_eq!(a.truth.len(), b.truth.len());
        assert_eq!(a.truth[0].corners_px, b.truth[0].corners_px);
        // Moved by 2 cm: drawn again, where a fresh camera draws it.
        let moved = MarkerPlacement {
            centre: [0.52, 0.4],
            ..m
        };
        let c = cam.capture(0.2, &[], &[moved]).unwrap();
        let fresh = Camera::new(cfg, 9)
            .unwrap()
            .capture(0.0, &[], &[moved])
            .unwrap();
        assert_eq!(c.truth[0].corners_px, fresh.truth[0].corners_px);
        let far = c
            .pixels
            .iter()
            .zip(&fresh.pixels)
            .filter(|(x, y)| (i32::from(**x) - i32::from(**y)).abs() > 60)
            .count();
        assert!(
            far < 20,
            "{far} pixels differ beyond noise from a fresh drawing"
        );
    }

    #[test]
    fn frames_are_seeded_and_carry_truth() {
        let cfg = CameraConfig::default_for_table([1.2, 0.9]);
        let m = MarkerPlacement {
            id: 7,
            family: MarkerFamily::Tag36h11,
            centre: [0.6, 0.45],
            heading: 0.3,
            side: 0.05,
            height: 0.0,
        };
        let a = Camera::new(cfg, 5)
            .unwrap()
            .capture(0.0, &[], &[m])
            .unwrap();
        let b = Camera::new(cfg, 5)
            .unwrap()
            .capture(0.0, &[], &[m])
            .unwrap();
        let c = Camera::new(cfg, 6)
            .unwrap()
            .capture(0.0, &[], &[m])
            .unwrap();
        assert_eq!(a.pixels, b.pixels);
        assert_ne!(a.pixels, c.pixels);
        assert_eq!(a.pixels.len(), 960 * 720);
        assert!(a.truth[0].fully_visible);
        let centre = a.truth[0].centre_px;
        assert!((centre[0] - 480.0).abs() < 1e-9 && (centre[1] - 360.0).abs() < 1e-9);
        // The pixel at the tag's centre-left black ring is dark, the table is mid-gray.
        let g = |x: f64, y: f64| a.pixels[y as usize * 960 + x as usize];
        assert!(g(10.0, 360.0) < 80, "floor dark");
        assert!(
            (100..160).contains(&g(300.0, 360.0)),
            "table mid-gray: {}",
            g(300.0, 360.0)
        );
        let bad = MarkerPlacement { id: 900, ..m };
        assert!(
            Camera::new(cfg, 5)
                .unwrap()
                .capture(0.0, &[], &[bad])
                .is_err()
        );
    }
}
