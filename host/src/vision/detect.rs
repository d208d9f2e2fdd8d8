//! Marker detection behind one trait, so the pipeline does not depend on which library finds
//! the tags.

use pushbot_sim::camera::MarkerFamily;

use super::source::Frame;

/// One detected marker in image coordinates (pixel centres at `i + 0.5`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// Tag family.
    pub family: MarkerFamily,
    /// Tag id.
    pub id: u32,
    /// Corners of the black square as printed: bottom-left, bottom-right, top-right, top-left.
    pub corners: [[f64; 2]; 4],
    /// Centre (the tag homography's image of the tag centre).
    pub centre: [f64; 2],
    /// Bits corrected when decoding.
    pub hamming: u32,
    /// Decoding confidence (the library's decision margin).
    pub margin: f32,
}

/// A marker detector: finds tags of its families in a grayscale frame.
pub trait Detector {
    /// A short name for reports (`apriltag-c`, `kornia`).
    fn name(&self) -> &'static str;
    /// The detections in one frame.
    fn detect(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError>;
}

/// Why detection could not run.
#[derive(Debug, thiserror::Error)]
pub enum DetectError {
    /// The detector could not be set up or fed this frame.
    #[error("marker detection: {0}")]
    Failed(String),
}

/// Which detector to build.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum DetectorKind {
    /// The reference C AprilTag library (bundled, pinned source): the default.
    ApriltagC,
    /// The pure-Rust `kornia-apriltag` (needs the `kornia` feature).
    Kornia,
}

/// Build a detector for `families` (single-threaded, as measured).
pub fn make_detector(
    kind: DetectorKind,
    families: &[MarkerFamily],
) -> Result<Box<dyn Detector>, DetectError> {
    Ok(match kind {
        DetectorKind::ApriltagC => Box::new(super::apriltag::AprilTagC::new(
            families,
            &Default::default(),
        )?),
        #[cfg(feature = "kornia")]
        DetectorKind::Kornia => Box::new(super::kornia::KorniaDetector::new(
            families,
            &Default::default(),
        )?),
        #[cfg(not(feature = "kornia"))]
        DetectorKind::Kornia => {
            return Err(DetectError::Failed(
                "this pushbot was built without the `kornia` feature".into(),
            ));
        }
    })
}
