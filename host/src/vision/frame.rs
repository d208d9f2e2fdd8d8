//! Frames and the sources that yield them: [`Frame`], the [`FrameSource`] trait and
//! [`SourceError`]. Below the sources ([`super::v4l2`], [`super::folder`],
//! [`super::simsocket`]) and the opener that picks among them ([`super::source`]).

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
    /// One frame could not be used (a truncated or corrupt image); the source goes on with
    /// the next. Readers skip it and count it.
    #[error("{0}")]
    BadFrame(String),
}

/// Something that yields frames in order.
pub trait FrameSource {
    /// A description for logs (`folder frames/`, `v4l2 /dev/video0 960x720 MJPG`).
    fn describe(&self) -> String;
    /// The next frame, `Ok(None)` at the end of the stream.
    fn next_frame(&mut self) -> Result<Option<Frame>, SourceError>;
}
