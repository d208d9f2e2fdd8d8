//! Picking a marker detector: [`DetectorKind`] names one, [`make_detector`] builds it. Above the
//! detectors ([`super::apriltag`], `kornia`) and the trait they implement
//! ([`super::detection`]), whose items are re-exported here.

use pushbot_world::camera::MarkerFamily;

pub use super::detection::{DetectError, Detection, Detector, Region, check};

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
