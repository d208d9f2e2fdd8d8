//! The reference C AprilTag detector (AprilRobotics), through the safe `apriltag` crate and its
//! `apriltag-sys`, built from the source bundled with the crate (`APRILTAG_SYS_METHOD=raw,static`
//! in `.cargo/config.toml`), so results do not depend on what the machine has installed.

use apriltag::{Detector as CDetector, DetectorBuilder, Family, Image};
use pushbot_sim::camera::MarkerFamily;

use super::detect::{DetectError, Detection, Detector};
use super::source::Frame;

/// Settings of the C detector.
#[derive(Debug, Clone, Copy)]
pub struct AprilTagCConfig {
    /// `quad_decimate`: quads are found on an image this many times smaller (corners are then
    /// refined on the full image).
    pub decimate: f32,
    /// `quad_sigma`: Gaussian blur before quad detection (0 = none).
    pub sigma: f32,
    /// `refine_edges`.
    pub refine_edges: bool,
    /// Threads (1 = one core, as measured).
    pub threads: u8,
    /// Bits corrected for tag36h11 (minimum Hamming distance 11).
    pub bits_36h11: usize,
    /// Bits corrected for tag25h9 (minimum Hamming distance 9).
    pub bits_25h9: usize,
}

impl Default for AprilTagCConfig {
    fn default() -> Self {
        AprilTagCConfig {
            decimate: 2.0,
            sigma: 0.0,
            refine_edges: true,
            threads: 1,
            bits_36h11: 2,
            bits_25h9: 1,
        }
    }
}

/// The C detector: one C detector per family, so every detection's family is known.
pub struct AprilTagC {
    detectors: Vec<(MarkerFamily, CDetector)>,
    image: Option<Image>,
}

impl std::fmt::Debug for AprilTagC {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AprilTagC")
            .field(
                "families",
                &self.detectors.iter().map(|d| d.0).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl AprilTagC {
    /// A detector for these families.
    pub fn new(families: &[MarkerFamily], cfg: &AprilTagCConfig) -> Result<AprilTagC, DetectError> {
        let mut detectors = Vec::new();
        for &fam in families {
            let builder = DetectorBuilder::new();
            let builder = match fam {
                MarkerFamily::Tag36h11 => {
                    builder.add_family_bits(Family::tag_36h11(), cfg.bits_36h11)
                }
                MarkerFamily::Tag25h9 => builder.add_family_bits(Family::tag_25h9(), cfg.bits_25h9),
            };
            let mut d = builder
                .build()
                .map_err(|e| DetectError::Failed(format!("{e}")))?;
            d.set_decimation(cfg.decimate);
            d.set_sigma(cfg.sigma);
            d.set_refine_edges(cfg.refine_edges);
            d.set_thread_number(cfg.threads.max(1));
            detectors.push((fam, d));
        }
        Ok(AprilTagC {
            detectors,
            image: None,
        })
    }
}

impl Detector for AprilTagC {
    fn name(&self) -> &'static str {
        "apriltag-c"
    }

    fn detect(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError> {
        let (w, h) = (frame.width as usize, frame.height as usize);
        if frame.pixels.len() != w * h {
            return Err(DetectError::Failed(
                "frame buffer does not match its size".into(),
            ));
        }
        let reuse = self
            .image
            .as_ref()
            .is_some_and(|im| im.width() == w && im.height() == h);
        if !reuse {
            let im = Image::zeros_with_alignment(w, h, 96)
                .map_err(|e| DetectError::Failed(format!("{e}")))?;
            self.image = Some(im);
        }
        let Some(image) = self.image.as_mut() else {
            return Err(DetectError::Failed("no image buffer".into()));
        };
        let stride = image.stride();
        let buf = image.as_slice_mut();
        for (row, src) in frame.pixels.chunks_exact(w).enumerate() {
            buf[row * stride..row * stride + w].copy_from_slice(src);
        }
        let mut out = Vec::new();
        for (fam, det) in &mut self.detectors {
            for d in det.detect(image) {
                // The library's corners are H·(−1, 1), H·(1, 1), H·(1, −1), H·(−1, −1) in tag
                // coordinates with y down the printed tag: bottom-left, bottom-right, top-right,
                // top-left. Its pixel centres are at integer + 0.5 like ours.
                out.push(Detection {
                    family: *fam,
                    id: d.id() as u32,
                    corners: d.corners(),
                    centre: d.center(),
                    hamming: d.hamming() as u32,
                    margin: d.decision_margin(),
                });
            }
        }
        Ok(out)
    }
}
