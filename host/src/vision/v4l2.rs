//! A USB camera through V4L2 (`linuxvideo`, pure Rust: no libv4l or bindgen needed to build).
//! Asks for MJPEG, else YUYV, else 8-bit gray, at 960×720 and 30 fps where the camera offers it
//! (Lau et al. §IV), and hands on the luminance.

use std::path::{Path, PathBuf};
use std::time::Instant;

use linuxvideo::format::{PixFormat, PixelFormat};
use linuxvideo::stream::ReadStream;
use linuxvideo::{BufType, Device};

use super::frame::{Frame, FrameSource, SourceError};

/// 8-bit gray (`V4L2_PIX_FMT_GREY`).
const GREY: PixelFormat = PixelFormat::from_fourcc(*b"GREY");

/// What to ask the camera for.
#[derive(Debug, Clone, Copy)]
pub struct V4l2Request {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Frames per second.
    pub fps: u32,
}

impl Default for V4l2Request {
    fn default() -> Self {
        V4l2Request {
            width: 960,
            height: 720,
            fps: 30,
        }
    }
}

/// A V4L2 capture stream.
pub struct V4l2Source {
    path: PathBuf,
    stream: ReadStream,
    format: PixelFormat,
    width: u32,
    height: u32,
    bytes_per_line: u32,
    start: Instant,
    seq: u64,
}

impl std::fmt::Debug for V4l2Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe())
    }
}

impl V4l2Source {
    /// Open `path` and start streaming; a missing device or one that is no camera is a
    /// [`SourceError::BadSource`] saying so.
    pub fn open(path: &Path, req: V4l2Request) -> Result<V4l2Source, SourceError> {
        if !path.exists() {
            return Err(SourceError::BadSource(format!(
                "camera device {} does not exist: is a USB camera plugged in (and its driver, uvcvideo, loaded)? \
                 Use --camera DIR for image files or sim:HOST:PORT for the simulated camera",
                path.display()
            )));
        }
        let bad = |what: &str, e: std::io::Error| {
            SourceError::BadSource(format!("camera device {}: {what}: {e}", path.display()))
        };
        let device = Device::open(path).map_err(|e| bad("cannot open it as a V4L2 device", e))?;
        let formats: Vec<PixelFormat> = device
            .formats(BufType::VIDEO_CAPTURE)
            .filter_map(|f| f.ok().map(|f| f.pixel_format()))
            .collect();
        let format = [PixelFormat::MJPG, PixelFormat::YUYV, GREY]
            .into_iter()
            .find(|f| formats.contains(f))
            .ok_or_else(|| {
                SourceError::BadSource(format!(
                    "camera device {} offers none of MJPG, YUYV, GREY (it offers {formats:?})",
                    path.display()
                ))
            })?;
        let capture = device
            .video_capture(PixFormat::new(req.width, req.height, format))
            .map_err(|e| bad("cannot start video capture", e))?;
        let _ = capture.set_frame_interval(linuxvideo::Fract::new(1, req.fps.max(1)));
        let got = capture.format();
        let (width, height, bytes_per_line, format) = (
            got.width(),
            got.height(),
            got.bytes_per_line(),
            got.pixel_format(),
        );
        if width == 0 || height == 0 {
            return Err(SourceError::BadSource(format!(
                "camera device {} negotiated an empty frame",
                path.display()
            )));
        }
        let stream = capture
            .into_stream()
            .map_err(|e| bad("cannot start streaming", e))?;
        Ok(V4l2Source {
            path: path.to_path_buf(),
            stream,
            format,
            width,
            height,
            bytes_per_line,
            start: Instant::now(),
            seq: 0,
        })
    }
}

impl FrameSource for V4l2Source {
    fn describe(&self) -> String {
        format!(
            "v4l2 {} {}x{} {}",
            self.path.display(),
            self.width,
            self.height,
            self.format
        )
    }

    fn next_frame(&mut self) -> Result<Option<Frame>, SourceError> {
        let (w, h, bpl, fmt) = (
            self.width as usize,
            self.height as usize,
            self.bytes_per_line as usize,
            self.format,
        );
        let pixels = self
            .stream
            .dequeue(|buf| {
                let data: &[u8] = &buf;
                Ok(to_gray(data, w, h, bpl, fmt))
            })
            .map_err(|e| SourceError::Read(format!("camera {}: {e}", self.path.display())))?
            .map_err(|e| SourceError::BadFrame(format!("camera {}: {e}", self.path.display())))?;
        let time = self.start.elapsed().as_secs_f64();
        let seq = self.seq;
        self.seq += 1;
        Ok(Some(Frame {
            seq,
            time,
            width: self.width,
            height: self.height,
            pixels,
        }))
    }
}

/// Luminance of one captured buffer.
fn to_gray(
    data: &[u8],
    w: usize,
    h: usize,
    bpl: usize,
    fmt: PixelFormat,
) -> Result<Vec<u8>, String> {
    if fmt == PixelFormat::MJPG {
        let img = image::load_from_memory_with_format(data, image::ImageFormat::Jpeg)
            .map_err(|e| format!("bad MJPEG frame: {e}"))?
            .into_luma8();
        if img.dimensions() != (w as u32, h as u32) {
            return Err(format!(
                "MJPEG frame is {:?}, expected {w}x{h}",
                img.dimensions()
            ));
        }
        return Ok(img.into_raw());
    }
    let bytes_per_px = if fmt == PixelFormat::YUYV { 2 } else { 1 }; // else GREY
    let bpl = bpl.max(w * bytes_per_px);
    if data.len() < bpl * (h - 1) + w * bytes_per_px {
        return Err(format!("short frame: {} bytes for {w}x{h}", data.len()));
    }
    let mut out = Vec::with_capacity(w * h);
    for row in 0..h {
        let line = &data[row * bpl..row * bpl + w * bytes_per_px];
        out.extend(line.iter().step_by(bytes_per_px));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yuyv_keeps_luma() {
        let data = [10, 128, 20, 128, 30, 128, 40, 128];
        assert_eq!(
            to_gray(&data, 2, 2, 4, PixelFormat::YUYV).unwrap(),
            vec![10, 20, 30, 40]
        );
        assert!(to_gray(&data[..5], 2, 2, 4, PixelFormat::YUYV).is_err());
    }
}
