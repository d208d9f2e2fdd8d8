//! The camera as the world sees it: the table-plane → pixel map of an overhead camera
//! ([`CameraModel`], a homography; a real lens and the camera's pose are [`crate::lens`]),
//! the AprilTag markers placed on the table ([`MarkerPlacement`]) and what a frame source
//! reports of each frame ([`FrameHeader`], [`MarkerTruth`]). Pixel centres are at `i + 0.5`.

use serde::{Deserialize, Serialize};

/// A planar projective map `p ↦ H p` in homogeneous coordinates (row-major 3×3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Homography(pub [[f64; 3]; 3]);

impl Homography {
    /// The identity map.
    pub const IDENTITY: Homography =
        Homography([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// Map a point; `None` when it maps to infinity (or behind the camera).
    pub fn apply(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let h = &self.0;
        let w = h[2][0] * p[0] + h[2][1] * p[1] + h[2][2];
        if w.abs() < 1e-12 || !w.is_finite() {
            return None;
        }
        let x = (h[0][0] * p[0] + h[0][1] * p[1] + h[0][2]) / w;
        let y = (h[1][0] * p[0] + h[1][1] * p[1] + h[1][2]) / w;
        (x.is_finite() && y.is_finite()).then_some([x, y])
    }

    /// The product `self · other` (apply `other` first).
    pub fn compose(&self, other: &Homography) -> Homography {
        let (a, b) = (&self.0, &other.0);
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        Homography(m)
    }

    /// The inverse map, `None` if singular.
    pub fn inverse(&self) -> Option<Homography> {
        let m = &self.0;
        let c = |r0: usize, r1: usize, c0: usize, c1: usize| {
            m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
        };
        let det = m[0][0] * c(1, 2, 1, 2) - m[0][1] * c(1, 2, 0, 2) + m[0][2] * c(1, 2, 0, 1);
        if det.abs() < 1e-300 || !det.is_finite() {
            return None;
        }
        let inv = [
            [
                c(1, 2, 1, 2) / det,
                -c(0, 2, 1, 2) / det,
                c(0, 1, 1, 2) / det,
            ],
            [
                -c(1, 2, 0, 2) / det,
                c(0, 2, 0, 2) / det,
                -c(0, 1, 0, 2) / det,
            ],
            [
                c(1, 2, 0, 1) / det,
                -c(0, 2, 0, 1) / det,
                c(0, 1, 0, 1) / det,
            ],
        ];
        Some(Homography(inv))
    }
}

/// The AprilTag families the camera can draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MarkerFamily {
    /// tag36h11: the default (587 ids, minimum Hamming distance 11).
    #[default]
    Tag36h11,
    /// tag25h9: for small markers (35 ids, 7×7 black square).
    Tag25h9,
}

impl MarkerFamily {
    /// The family's name as the AprilTag library spells it.
    pub fn name(self) -> &'static str {
        match self {
            MarkerFamily::Tag36h11 => "tag36h11",
            MarkerFamily::Tag25h9 => "tag25h9",
        }
    }
}

/// One marker on the table: its family and id, where its centre is (table metres), which way its
/// printed "right" points (radians from the table's +x, counter-clockwise) and the side of its
/// black square (metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MarkerPlacement {
    /// Tag id within the family.
    pub id: u32,
    /// Tag family.
    pub family: MarkerFamily,
    /// Centre on the table plane, metres.
    pub centre: [f64; 2],
    /// Heading of the printed tag's +x axis, radians CCW from the table's +x.
    pub heading: f64,
    /// Side of the black square, metres.
    pub side: f64,
    /// Height of the printed square above the table, metres (a marker on top of a robot or a
    /// box): a camera sees it in perspective, larger and shifted away from its nadir.
    #[serde(default)]
    pub height: f64,
}

impl MarkerPlacement {
    /// Corners of the black square on the table in the printed tag's order bottom-left,
    /// bottom-right, top-right, top-left (counter-clockwise seen from above).
    pub fn corners(&self) -> [[f64; 2]; 4] {
        let h = self.side / 2.0;
        let (s, c) = self.heading.sin_cos();
        [[-h, -h], [h, -h], [h, h], [-h, h]].map(|[a, b]| {
            [
                self.centre[0] + c * a - s * b,
                self.centre[1] + s * a + c * b,
            ]
        })
    }
}

/// Where the camera looks: image size and the table-plane → pixel homography.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraModel {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Table metres → pixel coordinates (pixel centres at `i + 0.5`).
    pub table_to_pixel: Homography,
}

impl CameraModel {
    /// A camera straight above the centre of a `table[0] × table[1]` m table, the table filling
    /// the image but for `margin_px` on its tighter side; table +y is image up.
    pub fn overhead(table: [f64; 2], width: u32, height: u32, margin_px: f64) -> CameraModel {
        let s = ((width as f64 - 2.0 * margin_px) / table[0])
            .min((height as f64 - 2.0 * margin_px) / table[1]);
        let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
        CameraModel {
            width,
            height,
            table_to_pixel: Homography([
                [s, 0.0, cx - s * table[0] / 2.0],
                [0.0, -s, cy + s * table[1] / 2.0],
                [0.0, 0.0, 1.0],
            ]),
        }
    }

    /// The same camera slightly tilted: a perspective term `(px, py)` per pixel about the image
    /// centre (1e-5 is a mild tilt).
    pub fn tilted(self, px: f64, py: f64) -> CameraModel {
        let (cx, cy) = (self.width as f64 / 2.0, self.height as f64 / 2.0);
        let t = Homography([[1.0, 0.0, cx], [0.0, 1.0, cy], [0.0, 0.0, 1.0]]);
        let t_inv = Homography([[1.0, 0.0, -cx], [0.0, 1.0, -cy], [0.0, 0.0, 1.0]]);
        let p = Homography([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [px, py, 1.0]]);
        CameraModel {
            table_to_pixel: t.compose(&p).compose(&t_inv).compose(&self.table_to_pixel),
            ..self
        }
    }
}

/// Ground truth of one marker in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MarkerTruth {
    /// The placement drawn.
    pub marker: MarkerPlacement,
    /// Corners of the black square in pixels: printed bottom-left, bottom-right, top-right,
    /// top-left.
    pub corners_px: [[f64; 2]; 4],
    /// Centre in pixels.
    pub centre_px: [f64; 2],
    /// Whether the whole marker, quiet zone included, lies inside the image.
    pub fully_visible: bool,
}

/// The header line sent before each frame's pixels.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct FrameHeader {
    /// Frame number.
    pub seq: u64,
    /// Simulated time of exposure, seconds.
    pub time: f64,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Pixel format: always `"gray8"`.
    pub format: String,
    /// Ground truth of the markers drawn.
    #[serde(default)]
    pub truth: Vec<MarkerTruth>,
}
