//! The sim camera's socket as a frame source: the protocol of
//! `pushbot_world::camera::server` (a JSON header line, then `width × height` gray bytes).

use std::io::{BufRead, BufReader, Read};
use std::net::TcpStream;

use pushbot_world::camera::FrameHeader;

use super::frame::{Frame, FrameSource, SourceError};

/// Largest frame accepted (pixels), so a bad header cannot make us allocate without bound.
const MAX_PIXELS: u64 = 8192 * 8192;

/// Frames from the simulated camera.
#[derive(Debug)]
pub struct SimSocketSource {
    addr: String,
    reader: BufReader<TcpStream>,
    /// The ground truth sent with the last frame, if any.
    pub last_truth: Vec<pushbot_world::camera::MarkerTruth>,
}

impl SimSocketSource {
    /// Connect to the sim camera at `addr` (`HOST:PORT`).
    pub fn connect(addr: &str) -> Result<SimSocketSource, SourceError> {
        let stream = TcpStream::connect(addr).map_err(|e| {
            SourceError::BadSource(format!("cannot connect to the sim camera at {addr}: {e}"))
        })?;
        Ok(SimSocketSource {
            addr: addr.to_string(),
            reader: BufReader::new(stream),
            last_truth: Vec::new(),
        })
    }
}

impl FrameSource for SimSocketSource {
    fn describe(&self) -> String {
        format!("sim camera {}", self.addr)
    }

    fn next_frame(&mut self) -> Result<Option<Frame>, SourceError> {
        let mut line = String::new();
        let n = (&mut self.reader)
            .take(1 << 20)
            .read_line(&mut line)
            .map_err(|e| SourceError::Read(format!("sim camera {}: {e}", self.addr)))?;
        if n == 0 {
            return Ok(None);
        }
        let h: FrameHeader = serde_json::from_str(line.trim_end()).map_err(|e| {
            SourceError::Read(format!("sim camera {}: bad frame header: {e}", self.addr))
        })?;
        if h.format != "gray8" {
            return Err(SourceError::Read(format!(
                "sim camera {}: unknown pixel format {:?}",
                self.addr, h.format
            )));
        }
        let count = h.width as u64 * h.height as u64;
        if count == 0 || count > MAX_PIXELS || !h.time.is_finite() {
            return Err(SourceError::Read(format!(
                "sim camera {}: bad frame size {}x{}",
                self.addr, h.width, h.height
            )));
        }
        let mut pixels = vec![0u8; count as usize];
        self.reader.read_exact(&mut pixels).map_err(|e| {
            SourceError::Read(format!("sim camera {}: frame cut short: {e}", self.addr))
        })?;
        self.last_truth = h.truth;
        Ok(Some(Frame {
            seq: h.seq,
            time: h.time,
            width: h.width,
            height: h.height,
            pixels,
        }))
    }
}
