//! The pure-Rust candidate, `kornia-apriltag`, measured against the C library by
//! `pushbot bench vision`. Its quad corners are not rotated to the decoded tag, so corners are
//! taken from the detection's tag homography instead; it runs on a one-thread rayon pool so its
//! time is one core's.

use kornia_apriltag::family::TagFamilyKind;
use kornia_apriltag::{AprilTagDecoder, DecodeTagsConfig};
use kornia_image::{Image, ImageSize};
use pushbot_world::camera::MarkerFamily;

use super::detection::{DetectError, Detection, Detector, Region, check};
use super::frame::Frame;

/// Settings of the kornia detector.
#[derive(Debug, Clone, Copy, Default)]
pub struct KorniaConfig {
    /// `threshold_split` of the adaptive threshold (library default 0.33); `None` keeps it.
    pub threshold_split: Option<f32>,
    /// Downscale factor for quad detection (library default 2).
    pub downscale: Option<usize>,
}

/// The kornia detector.
pub struct KorniaDetector {
    config: DecodeTagsConfig,
    /// A decoder and an image buffer per frame size in use (whole frames, regions).
    decoders: Vec<(AprilTagDecoder, Image<u8, 1>)>,
    pool: rayon::ThreadPool,
    families: Vec<MarkerFamily>,
}

impl std::fmt::Debug for KorniaDetector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KorniaDetector")
            .field("families", &self.families)
            .finish()
    }
}

/// Frame sizes whose decoders are kept.
const DECODER_CACHE: usize = 8;

fn kind(f: MarkerFamily) -> TagFamilyKind {
    match f {
        MarkerFamily::Tag36h11 => TagFamilyKind::Tag36H11,
        MarkerFamily::Tag25h9 => TagFamilyKind::Tag25H9,
    }
}

impl KorniaDetector {
    /// A detector for these families.
    pub fn new(
        families: &[MarkerFamily],
        cfg: &KorniaConfig,
    ) -> Result<KorniaDetector, DetectError> {
        let mut config = DecodeTagsConfig::new(families.iter().map(|&f| kind(f)).collect())
            .map_err(|e| DetectError::Failed(format!("{e}")))?;
        if let Some(t) = cfg.threshold_split {
            config.threshold_split = t;
        }
        if let Some(d) = cfg.downscale {
            config.downscale_factor = d.max(1);
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| DetectError::Failed(format!("thread pool: {e}")))?;
        Ok(KorniaDetector {
            config,
            decoders: Vec::new(),
            pool,
            families: families.to_vec(),
        })
    }
}

impl Detector for KorniaDetector {
    fn name(&self) -> &'static str {
        "kornia"
    }

    fn detect(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError> {
        check(frame, &Region::full(frame.width, frame.height))?;
        let size = ImageSize {
            width: frame.width as usize,
            height: frame.height as usize,
        };
        let slot = match self.decoders.iter().position(|(_, im)| im.size() == size) {
            Some(i) => i,
            None => {
                let d = AprilTagDecoder::new(self.config.clone(), size)
                    .map_err(|e| DetectError::Failed(format!("{e}")))?;
                let im = Image::from_size_val(size, 0u8)
                    .map_err(|e| DetectError::Failed(format!("{e}")))?;
                if self.decoders.len() >= DECODER_CACHE {
                    self.decoders.remove(0);
                }
                self.decoders.push((d, im));
                self.decoders.len() - 1
            }
        };
        let (decoder, image) = &mut self.decoders[slot];
        image.as_slice_mut().copy_from_slice(&frame.pixels);
        decoder.clear();
        let found = self
            .pool
            .install(|| decoder.decode(image))
            .map_err(|e| DetectError::Failed(format!("{e}")))?;
        let mut out = Vec::with_capacity(found.len());
        for d in found {
            let family = match d.tag_family_kind {
                TagFamilyKind::Tag36H11 => MarkerFamily::Tag36h11,
                TagFamilyKind::Tag25H9 => MarkerFamily::Tag25h9,
                _ => continue,
            };
            // Same tag-coordinate convention as the C library (y down the printed tag), and
            // the same pixel centres (integer + 0.5, measured: adding 0.5 biased every corner
            // by +0.5 px).
            let p = |x: f32, y: f32| {
                let q = d.quad.homography_project(x, y);
                [q.x as f64, q.y as f64]
            };
            out.push(Detection {
                family,
                id: d.id as u32,
                corners: [p(-1.0, 1.0), p(1.0, 1.0), p(1.0, -1.0), p(-1.0, -1.0)],
                centre: p(0.0, 0.0),
                hamming: d.hamming as u32,
                margin: d.decision_margin,
            });
        }
        Ok(out)
    }
}
