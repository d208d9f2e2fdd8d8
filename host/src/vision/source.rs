//! Frame sources behind one trait: a USB camera through V4L2, a folder of image files, and the
//! simulated camera's socket. `--camera SRC` picks one:
//!
//! | SRC | source |
//! |---|---|
//! | `/dev/videoN` or `v4l2:/dev/videoN` | USB camera ([`super::v4l2`]) |
//! | `sim:HOST:PORT` or `tcp:HOST:PORT` | the sim camera's socket ([`super::simsocket`]) |
//! | a directory | its PNG/JPEG files in name order ([`super::folder`]) |
//!
//! [`open_source`] is the picker, above the sources; the frame types and the trait are in
//! [`super::frame`], below them, and re-exported here.

use std::path::Path;

pub use super::frame::{Frame, FrameSource, SourceError};

/// Open a source from its `--camera` spelling.
pub fn open_source(spec: &str, fps: f64) -> Result<Box<dyn FrameSource>, SourceError> {
    if let Some(addr) = spec
        .strip_prefix("sim:")
        .or_else(|| spec.strip_prefix("tcp:"))
    {
        return Ok(Box::new(super::simsocket::SimSocketSource::connect(addr)?));
    }
    if let Some(dev) = spec.strip_prefix("v4l2:") {
        return Ok(Box::new(super::v4l2::V4l2Source::open(
            Path::new(dev),
            Default::default(),
        )?));
    }
    if spec.starts_with("/dev/video") {
        return Ok(Box::new(super::v4l2::V4l2Source::open(
            Path::new(spec),
            Default::default(),
        )?));
    }
    let path = Path::new(spec);
    if path.is_dir() {
        return Ok(Box::new(super::folder::FolderSource::open(path, fps)?));
    }
    let what = if spec.is_empty() {
        "is empty".to_owned()
    } else if !path.exists() {
        "does not exist".to_owned()
    } else {
        "is not a directory".to_owned()
    };
    Err(SourceError::BadSource(format!(
        "camera source {spec:?} {what}: give a V4L2 device (/dev/videoN), the sim camera \
         (sim:HOST:PORT) or a directory of images"
    )))
}
