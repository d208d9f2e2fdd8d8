//! Marker detection behind one trait, so the pipeline does not depend on which library finds
//! the tags: the [`Detector`] trait, its [`Detection`]s, the [`Region`]s of a frame it may be
//! asked to search, and [`DetectError`]. Below the detectors ([`super::apriltag`], `kornia`) and
//! the picker that chooses among them ([`super::detect`]).

use pushbot_world::camera::MarkerFamily;

use super::frame::Frame;

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

/// A rectangle of a frame, pixels: columns `x..x + width`, rows `y..y + height`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Region {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

impl Region {
    /// The whole of a `width × height` frame.
    pub fn full(width: u32, height: u32) -> Region {
        Region {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// A `side × side` square centred as near `centre` (pixel coordinates, centres at
    /// `i + 0.5`) as fits in a `width × height` frame (shifted inside rather than cut, so
    /// squares of one size stay one size); clipped only when the frame is smaller than `side`.
    pub fn square_around(centre: [f64; 2], side: u32, width: u32, height: u32) -> Region {
        let place = |c: f64, len: u32| -> (u32, u32) {
            let s = side.min(len);
            // A NaN centre casts to 0, an infinite one clamps to an edge.
            let start = (c - s as f64 / 2.0).round();
            (start.clamp(0.0, (len - s) as f64) as u32, s)
        };
        let (x, w) = place(centre[0], width);
        let (y, h) = place(centre[1], height);
        Region {
            x,
            y,
            width: w,
            height: h,
        }
    }

    /// Whether the region lies inside a `width × height` frame and is not empty.
    pub fn fits(&self, width: u32, height: u32) -> bool {
        self.width > 0
            && self.height > 0
            && self.x.checked_add(self.width).is_some_and(|e| e <= width)
            && self.y.checked_add(self.height).is_some_and(|e| e <= height)
    }

    /// Copy this region of `frame` into a new frame.
    pub fn crop(&self, frame: &Frame) -> Result<Frame, DetectError> {
        check(frame, self)?;
        let (w, x0) = (frame.width as usize, self.x as usize);
        let mut pixels = Vec::with_capacity(self.width as usize * self.height as usize);
        for row in self.y as usize..(self.y + self.height) as usize {
            pixels
                .extend_from_slice(&frame.pixels[row * w + x0..row * w + x0 + self.width as usize]);
        }
        Ok(Frame {
            seq: frame.seq,
            time: frame.time,
            width: self.width,
            height: self.height,
            pixels,
        })
    }
}

/// Check that `frame`'s buffer matches its size and that `region` lies inside it.
pub fn check(frame: &Frame, region: &Region) -> Result<(), DetectError> {
    if frame.pixels.len() != frame.width as usize * frame.height as usize {
        return Err(DetectError::Failed(
            "frame buffer does not match its size".into(),
        ));
    }
    if !region.fits(frame.width, frame.height) {
        return Err(DetectError::Failed(format!(
            "region {region:?} is not inside the {}×{} frame",
            frame.width, frame.height
        )));
    }
    Ok(())
}

impl Detection {
    /// The same detection moved by `(dx, dy)` pixels.
    pub fn shifted(mut self, dx: f64, dy: f64) -> Detection {
        for c in &mut self.corners {
            c[0] += dx;
            c[1] += dy;
        }
        self.centre[0] += dx;
        self.centre[1] += dy;
        self
    }
}

/// A marker detector: finds tags of its families in a grayscale frame.
pub trait Detector {
    /// A short name for reports (`apriltag-c`, `kornia`).
    fn name(&self) -> &'static str;
    /// The detections in one frame.
    fn detect(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError>;
    /// The detections inside one region of a frame, in the frame's pixel coordinates. The
    /// default copies the region out and runs [`Detector::detect`] on it.
    fn detect_region(
        &mut self,
        frame: &Frame,
        region: Region,
    ) -> Result<Vec<Detection>, DetectError> {
        let crop = region.crop(frame)?;
        let (dx, dy) = (region.x as f64, region.y as f64);
        Ok(self
            .detect(&crop)?
            .into_iter()
            .map(|d| d.shifted(dx, dy))
            .collect())
    }
    /// As [`Detector::detect_region`], searching harder for small markers (for the C library:
    /// quads found at full resolution rather than decimated): for calibration, where time does
    /// not matter, and for a second look where a body was expected and not found. The default
    /// is the same search.
    fn detect_region_fine(
        &mut self,
        frame: &Frame,
        region: Region,
    ) -> Result<Vec<Detection>, DetectError> {
        self.detect_region(frame, region)
    }
    /// The whole frame, searched as [`Detector::detect_region_fine`] does.
    fn detect_fine(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError> {
        self.detect_region_fine(frame, Region::full(frame.width, frame.height))
    }
}

/// Why detection could not run.
#[derive(Debug, thiserror::Error)]
pub enum DetectError {
    /// The detector could not be set up or fed this frame.
    #[error("marker detection: {0}")]
    Failed(String),
}
