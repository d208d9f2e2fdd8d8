//! The reference C AprilTag detector (AprilRobotics), through the safe `apriltag` crate and its
//! `apriltag-sys`, built from the source bundled with the crate (`APRILTAG_SYS_METHOD=raw,static`
//! in `.cargo/config.toml`), so results do not depend on what the machine has installed.

use apriltag::{Detector as CDetector, DetectorBuilder, Family, Image};
use pushbot_world::camera::MarkerFamily;

use super::detection::{DetectError, Detection, Detector, Region, check};
use super::frame::Frame;

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

/// The chosen settings: `quad_decimate = 2`, `quad_sigma = 1.0`. Measured by
/// `pushbot bench vision` on rendered 960×720 frames with sensor noise: the blur before quad
/// detection removes the many small noise components the segmentation otherwise has to cluster
/// and fit (4–5× faster whole frames than `quad_sigma = 0`), and corners are still refined on
/// the unblurred image (corner RMS 0.08 px against 0.125 px). `quad_sigma = 2` lost a sixth of
/// the markers, so 1.0 keeps a margin for blurrier cameras.
impl Default for AprilTagCConfig {
    fn default() -> Self {
        AprilTagCConfig {
            sigma: 1.0,
            ..AprilTagCConfig::reference()
        }
    }
}

impl AprilTagCConfig {
    /// The library's own defaults at `quad_decimate = 2` (no blur): the reference the bench
    /// compares against.
    pub fn reference() -> Self {
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
    /// The same families finding quads at full resolution (small or far markers).
    fine: Vec<(MarkerFamily, CDetector)>,
    /// Aligned image buffers, one per region size in use (the full frame, the crops).
    images: Vec<Image>,
}

/// Region sizes whose buffers are kept.
const IMAGE_CACHE: usize = 8;

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
        // Small markers need every pixel: no decimation, and no blur before the quads are
        // found (σ = 1 px erases a 20-pixel tag's cells).
        let fine = AprilTagCConfig {
            decimate: 1.0,
            sigma: 0.0,
            ..*cfg
        };
        Ok(AprilTagC {
            detectors: Self::build(families, cfg)?,
            fine: Self::build(families, &fine)?,
            images: Vec::new(),
        })
    }

    /// One C detector per family with these settings.
    fn build(
        families: &[MarkerFamily],
        cfg: &AprilTagCConfig,
    ) -> Result<Vec<(MarkerFamily, CDetector)>, DetectError> {
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
        Ok(detectors)
    }

    /// Detect in `region` with the decimated detectors or the `fine` ones. Copies only the
    /// region's rows into a reused, aligned buffer of the region's size (no allocation once the
    /// few sizes in use have been seen).
    fn run(
        &mut self,
        frame: &Frame,
        region: Region,
        fine: bool,
    ) -> Result<Vec<Detection>, DetectError> {
        check(frame, &region)?;
        let (w, h) = (region.width as usize, region.height as usize);
        let slot = match self
            .images
            .iter()
            .position(|im| im.width() == w && im.height() == h)
        {
            Some(i) => i,
            None => {
                let im = Image::zeros_with_alignment(w, h, 96)
                    .map_err(|e| DetectError::Failed(format!("{e}")))?;
                if self.images.len() >= IMAGE_CACHE {
                    self.images.remove(0);
                }
                self.images.push(im);
                self.images.len() - 1
            }
        };
        let image = &mut self.images[slot];
        let stride = image.stride();
        let buf = image.as_slice_mut();
        let (fw, x0, y0) = (frame.width as usize, region.x as usize, region.y as usize);
        for row in 0..h {
            let src = (y0 + row) * fw + x0;
            buf[row * stride..row * stride + w].copy_from_slice(&frame.pixels[src..src + w]);
        }
        let (dx, dy) = (region.x as f64, region.y as f64);
        let mut out = Vec::new();
        let detectors = if fine {
            &mut self.fine
        } else {
            &mut self.detectors
        };
        for (fam, det) in detectors {
            for d in det.detect(image) {
                // The library's corners are H·(−1, 1), H·(1, 1), H·(1, −1), H·(−1, −1) in tag
                // coordinates with y down the printed tag: bottom-left, bottom-right, top-right,
                // top-left. Its pixel centres are at integer + 0.5 like ours.
                let det = Detection {
                    family: *fam,
                    id: d.id() as u32,
                    corners: d.corners(),
                    centre: d.center(),
                    hamming: d.hamming() as u32,
                    margin: d.decision_margin(),
                };
                out.push(det.shifted(dx, dy));
            }
        }
        Ok(out)
    }
}

impl Detector for AprilTagC {
    fn name(&self) -> &'static str {
        "apriltag-c"
    }

    fn detect(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError> {
        self.run(frame, Region::full(frame.width, frame.height), false)
    }

    fn detect_region(
        &mut self,
        frame: &Frame,
        region: Region,
    ) -> Result<Vec<Detection>, DetectError> {
        self.run(frame, region, false)
    }

    fn detect_region_fine(
        &mut self,
        frame: &Frame,
        region: Region,
    ) -> Result<Vec<Detection>, DetectError> {
        self.run(frame, region, true)
    }
}
