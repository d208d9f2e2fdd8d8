//! Frame sources behind one trait: a USB camera through V4L2, a folder of image files, and the
//! simulated camera's socket. `--camera SRC` picks one:
//!
//! | SRC | source |
//! |---|---|
//! | `/dev/videoN` or `v4l2:/dev/videoN` | USB camera ([`super::v4l2`]) |
//! | `sim:HOST:PORT` or `tcp:HOST:PORT` | the sim camera's socket ([`super::simsocket`]) |
//! | a directory | its PNG/JPEG files in name order ([`super::folder`]) |

use std::path::Path;

/// One grayscale frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Frame number from the source.
    pub seq: u64,
    /// Time of exposure, seconds (simulated time for the sim camera, time since the source was
    /// opened for a real camera, `seq / fps` or the sidecar's time for files).
    pub time: f64,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Gray levels, row-major, `width × height` bytes.
    pub pixels: Vec<u8>,
}

/// Why a source could not be opened or read.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// The source named does not exist or is not usable (bad input: exit 2).
    #[error("{0}")]
    BadSource(String),
    /// Reading from a working source failed.
    #[error("{0}")]
    Read(String),
}

/// Something that yields frames in order.
pub trait FrameSource {
    /// A description for logs (`folder frames/`, `v4l2 /dev/video0 960x720 MJPG`).
    fn describe(&self) -> String;
    /// The next frame, `Ok(None)` at the end of the stream.
    fn next_frame(&mut self) -> Result<Option<Frame>, SourceError>;
}

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
