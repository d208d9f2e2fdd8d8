//! Rendered test frames with ground truth, and their scoring: the sim camera draws the layout's
//! calibration markers and bodies at random poses with random mild blur, noise and exposure.
//! Used by the vision tests and `pushbot bench vision`.

/// The AprilTag families' bit patterns the renderer draws (the calibration board's SVG prints
/// the same).
pub use pushbot_sim::camera::TagCodes;
use pushbot_sim::camera::{Camera, CameraConfig, CameraModel, Imaging, MarkerTruth, Polygon};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::vision::calibration::Calibration;
use crate::vision::detect::Detection;
use crate::vision::layout::{MarkerLayout, Pose, wrap_angle};
use crate::vision::source::Frame;

/// A rendered frame with the truth of what is in it.
#[derive(Debug, Clone)]
pub struct SynthFrame {
    /// The frame.
    pub frame: Frame,
    /// Every marker drawn.
    pub markers: Vec<MarkerTruth>,
    /// Every body's true pose.
    pub bodies: Vec<(String, Pose)>,
}

/// How to make test frames.
#[derive(Debug, Clone, Copy)]
pub struct SynthParams {
    /// Image size.
    pub size: [u32; 2],
    /// Perspective tilt `(px, py)` per pixel about the image centre.
    pub tilt: [f64; 2],
    /// Blur σ range, pixels.
    pub blur: [f64; 2],
    /// Noise σ range, gray levels.
    pub noise: [f64; 2],
    /// Exposure range.
    pub exposure: [f64; 2],
    /// A real lens the frames are seen through (its image size must be `size`).
    pub lens: Option<pushbot_world::lens::Intrinsics>,
}

impl Default for SynthParams {
    fn default() -> Self {
        SynthParams {
            size: [960, 720],
            tilt: [1.0e-5, -0.7e-5],
            blur: [0.5, 1.0],
            noise: [2.0, 4.0],
            exposure: [0.85, 1.1],
            lens: None,
        }
    }
}

fn body_polygon(name: &str, pose: &Pose) -> Polygon {
    let local: Vec<[f64; 2]> = if name == "robot" {
        (0..24)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 24.0;
                [0.07 * a.cos(), 0.07 * a.sin()]
            })
            .collect()
    } else if name == "goal" {
        (0..24)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 24.0;
                [0.05 * a.cos(), 0.05 * a.sin()]
            })
            .collect()
    } else {
        vec![[-0.07, -0.05], [0.07, -0.05], [0.07, 0.05], [-0.07, 0.05]]
    };
    let shade = match name {
        "robot" => 0.3,
        "goal" => 0.7,
        _ => 0.8,
    };
    let points = local
        .iter()
        .map(|p| {
            let q = pose.compose(&Pose::new(p[0], p[1], 0.0));
            [q.x, q.y]
        })
        .collect();
    Polygon { points, shade }
}

/// `n` frames of the layout: calibration markers where they belong, bodies at random poses
/// (one per region of the table, so they do not overlap), 1/30 s apart.
pub fn frames(
    layout: &MarkerLayout,
    n: usize,
    seed: u64,
    params: &SynthParams,
) -> Result<Vec<SynthFrame>, String> {
    render(layout, n, seed, params, false)
}

/// `n` frames of the layout, 1/30 s apart, as a video: every body moves smoothly within its
/// region of the table (up to about 0.2 m/s and 1.5 rad/s, a pushing robot's pace), so a
/// tracker can follow it from frame to frame.
pub fn moving_frames(
    layout: &MarkerLayout,
    n: usize,
    seed: u64,
    params: &SynthParams,
) -> Result<Vec<SynthFrame>, String> {
    render(layout, n, seed, params, true)
}

/// One body's smooth path within its region: fractions of the region's size and rates.
#[derive(Debug, Clone, Copy)]
struct Path {
    centre: [f64; 2],
    amplitude: [f64; 2],
    rate: [f64; 2],
    phase: [f64; 2],
    heading: f64,
    turn: f64,
}

impl Path {
    fn random(rng: &mut ChaCha8Rng, size: [f64; 2]) -> Path {
        // Peak speed a·ω of each axis up to ~0.15 m/s: about 0.2 m/s along a diagonal.
        let amp = |r: &mut ChaCha8Rng| r.random_range(0.1..0.2);
        let amplitude = [amp(rng), amp(rng)];
        let rate =
            |r: &mut ChaCha8Rng, a: f64, s: f64| r.random_range(0.3..(0.15 / (a * s)).max(0.31));
        Path {
            centre: [rng.random_range(0.4..0.6), rng.random_range(0.4..0.6)],
            amplitude,
            rate: [
                rate(rng, amplitude[0], size[0]),
                rate(rng, amplitude[1], size[1]),
            ],
            phase: [rng.random_range(0.0..6.3), rng.random_range(0.0..6.3)],
            heading: rng.random_range(-3.2..3.2),
            turn: rng.random_range(-1.5..1.5),
        }
    }

    /// Position as fractions of the region, and heading, at time `t`.
    fn at(&self, t: f64) -> ([f64; 2], f64) {
        let f = |i: usize| {
            self.centre[i] + self.amplitude[i] * (self.rate[i] * t + self.phase[i]).sin()
        };
        ([f(0), f(1)], wrap_angle(self.heading + self.turn * t))
    }
}

fn render(
    layout: &MarkerLayout,
    n: usize,
    seed: u64,
    params: &SynthParams,
    moving: bool,
) -> Result<Vec<SynthFrame>, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let model = CameraModel::overhead(layout.table, params.size[0], params.size[1], 16.0)
        .tilted(params.tilt[0], params.tilt[1]);
    let mut config = CameraConfig::default_for_table(layout.table);
    config.model = model;
    config.lens = params.lens;
    let mut camera = Camera::new(config, seed ^ 0x5eed).map_err(|e| e.to_string())?;
    let [tw, th] = layout.table;
    let nb = layout.bodies.len().max(1);
    let cols = (nb as f64).sqrt().ceil() as usize;
    let rows = nb.div_ceil(cols);
    // Keep bodies clear of the calibration markers along the edges.
    let (x0, x1, y0, y1) = (0.15, tw - 0.15, 0.17, th - 0.17);
    let (cw, ch) = ((x1 - x0) / cols as f64, (y1 - y0) / rows as f64);
    // Drawn only for videos, so still frames keep their random stream.
    let paths: Vec<Path> = if moving {
        (0..nb).map(|_| Path::random(&mut rng, [cw, ch])).collect()
    } else {
        Vec::new()
    };
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let range = |r: [f64; 2], rng: &mut ChaCha8Rng| {
            if r[1] > r[0] {
                rng.random_range(r[0]..r[1])
            } else {
                r[0]
            }
        };
        let imaging = Imaging {
            blur_sigma_px: range(params.blur, &mut rng),
            noise_sigma: range(params.noise, &mut rng),
            exposure: range(params.exposure, &mut rng),
            ..Imaging::default()
        };
        let mut cfg = *camera.config();
        cfg.imaging = imaging;
        camera = Camera::new(cfg, rng.random()).map_err(|e| e.to_string())?;
        let mut bodies = Vec::new();
        let mut polys = Vec::new();
        let mut markers: Vec<_> = layout.calibration.iter().map(|m| m.placement()).collect();
        let time = k as f64 / 30.0;
        for (i, b) in layout.bodies.iter().enumerate() {
            let (c, r) = (i % cols, i / cols);
            let (f, heading) = if moving {
                paths[i].at(time)
            } else {
                let f = [rng.random_range(0.3..0.7), rng.random_range(0.3..0.7)];
                (f, wrap_angle(rng.random_range(-3.2..3.2)))
            };
            let x = x0 + cw * (c as f64 + f[0]);
            let y = y0 + ch * (r as f64 + f[1]);
            let pose = Pose::new(x, y, heading);
            polys.push(body_polygon(&b.body, &pose));
            markers.push(b.placement(&pose));
            bodies.push((b.body.clone(), pose));
        }
        let cf = camera
            .capture(time, &polys, &markers)
            .map_err(|e| e.to_string())?;
        let frame = Frame {
            seq: k as u64,
            time,
            width: cf.width,
            height: cf.height,
            pixels: cf.pixels,
        };
        out.push(SynthFrame {
            frame,
            markers: cf.truth,
            bodies,
        });
    }
    Ok(out)
}

/// Detection quality against the truth.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct DetectionScore {
    /// Fully visible markers in the frames.
    pub visible: usize,
    /// Of those, how many were found with the right id within 2 px of their true centre.
    pub found: usize,
    /// Detections whose id is not drawn in that frame, or drawn elsewhere.
    pub wrong_ids: usize,
    /// Corner errors of the found markers, pixels.
    #[serde(skip)]
    pub corner_errors: Vec<f64>,
    /// Mean corner error vector (bias), pixels.
    pub corner_bias: [f64; 2],
}

impl DetectionScore {
    /// Add one frame's detections.
    pub fn add(&mut self, dets: &[Detection], truth: &[MarkerTruth]) {
        for t in truth.iter().filter(|t| t.fully_visible) {
            self.visible += 1;
            let hit = dets.iter().find(|d| {
                d.family == t.marker.family
                    && d.id == t.marker.id
                    && (d.centre[0] - t.centre_px[0]).hypot(d.centre[1] - t.centre_px[1]) < 2.0
            });
            if let Some(d) = hit {
                self.found += 1;
                for (c, tc) in d.corners.iter().zip(&t.corners_px) {
                    let e = [c[0] - tc[0], c[1] - tc[1]];
                    let n = self.corner_errors.len() as f64;
                    self.corner_bias = [
                        (self.corner_bias[0] * n + e[0]) / (n + 1.0),
                        (self.corner_bias[1] * n + e[1]) / (n + 1.0),
                    ];
                    self.corner_errors.push(e[0].hypot(e[1]));
                }
            }
        }
        for d in dets {
            let ok = truth.iter().any(|t| {
                t.marker.family == d.family
                    && t.marker.id == d.id
                    && (d.centre[0] - t.centre_px[0]).hypot(d.centre[1] - t.centre_px[1]) < 10.0
            });
            if !ok {
                self.wrong_ids += 1;
            }
        }
    }

    /// Fraction of visible markers found.
    pub fn rate(&self) -> f64 {
        if self.visible == 0 {
            1.0
        } else {
            self.found as f64 / self.visible as f64
        }
    }

    /// Root-mean-square corner error, pixels.
    pub fn corner_rms(&self) -> f64 {
        let n = self.corner_errors.len().max(1) as f64;
        (self.corner_errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt()
    }
}

/// Body pose errors of per-frame measurements against the truth.
#[derive(Debug, Clone, Default)]
pub struct PoseScore {
    /// Position errors, millimetres.
    pub pos_mm: Vec<f64>,
    /// Heading errors, degrees.
    pub heading_deg: Vec<f64>,
    /// Bodies in view not measured.
    pub missed: usize,
}

impl PoseScore {
    /// Add one frame's measurements.
    pub fn add(&mut self, measured: &[crate::vision::Measurement], truth: &[(String, Pose)]) {
        for (name, pose) in truth {
            match measured.iter().find(|m| &m.body == name) {
                Some(m) => {
                    self.pos_mm
                        .push(1000.0 * (m.body_pose.x - pose.x).hypot(m.body_pose.y - pose.y));
                    self.heading_deg.push(
                        wrap_angle(m.body_pose.theta - pose.theta)
                            .abs()
                            .to_degrees(),
                    );
                }
                None => self.missed += 1,
            }
        }
    }
}

/// The `q`-quantile (0..=1) of values (nearest rank); NaN if empty.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let i = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[i]
}

/// Calibrate from the first `k` frames' detections.
pub fn calibrate(
    dets: &[Vec<Detection>],
    layout: &MarkerLayout,
    size: [u32; 2],
) -> Result<Calibration, String> {
    Calibration::fit(dets, layout, size).map_err(|e| e.to_string())
}
