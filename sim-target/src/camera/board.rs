//! Views of a lens-calibration board ([`pushbot_world::board`]) as a real camera takes them: the
//! flat board at any 3-D pose in front of a camera with given intrinsics. The board plane maps to
//! the ideal pinhole image through the homography K [r1 r2 t] (Zhang 2000, eq. 2), is drawn there
//! with the table renderer ([`super::render`]), blurred, warped through the lens's `plumb_bob`
//! distortion ([`super::lens::LensWarp`]) and developed with the sensor's noise, as
//! [`super::Camera`] does. Every view carries the true pixel of every tag corner (distorted as
//! the image is), so calibration can be checked against the truth.

use nalgebra::{Isometry3, Matrix3, Point3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use pushbot_world::board::{BoardLayout, family_cells};
use pushbot_world::camera::Homography;
use pushbot_world::lens::Intrinsics;

use super::lens::LensWarp;
use super::render::{Canvas, Polygon, TagCodes};
use super::{CameraError, Imaging};

/// White paper around the tags, metres beyond the black squares' extent.
pub const PAPER_MARGIN: f64 = 0.015;

/// One rendered view of the board.
#[derive(Debug, Clone)]
pub struct BoardView {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Gray levels, row-major.
    pub pixels: Vec<u8>,
    /// Every tag's id and its black square's corners in pixels (bottom-left, bottom-right,
    /// top-right, top-left of the printed tag), through the lens; tags partly or wholly outside
    /// the image are left out.
    pub corners: Vec<(u32, [[f64; 2]; 4])>,
}

/// A camera with a lens that photographs a calibration board.
#[derive(Debug)]
pub struct BoardCamera {
    lens: Intrinsics,
    warp: LensWarp,
    imaging: Imaging,
    codes: TagCodes,
    rng: ChaCha8Rng,
}

impl BoardCamera {
    /// A camera with `lens` (its image size is the frames'), optics and sensor `imaging`, noise
    /// seeded from `seed`.
    pub fn new(lens: Intrinsics, imaging: Imaging, seed: u64) -> Result<BoardCamera, CameraError> {
        Ok(BoardCamera {
            warp: LensWarp::new(lens, lens.width, lens.height).map_err(CameraError::Invalid)?,
            lens,
            imaging,
            codes: TagCodes::new().map_err(CameraError::Invalid)?,
            rng: ChaCha8Rng::seed_from_u64(seed),
        })
    }

    /// The board → ideal pixel homography K [r1 r2 t] of a board at `board_to_camera`.
    pub fn homography(&self, board_to_camera: &Isometry3<f64>) -> Homography {
        let l = &self.lens;
        let k = Matrix3::new(l.fx, 0.0, l.cx, 0.0, l.fy, l.cy, 0.0, 0.0, 1.0);
        let r = board_to_camera.rotation.to_rotation_matrix();
        let t = board_to_camera.translation.vector;
        let m = k * Matrix3::from_columns(&[
            r.matrix().column(0).clone_owned(),
            r.matrix().column(1).clone_owned(),
            t,
        ]);
        Homography([
            [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
            [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
            [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
        ])
    }

    /// Photograph `board` at `board_to_camera` (board frame → camera frame: z along the optical
    /// axis, x right, y down); the board must be wholly in front of the camera.
    pub fn view(
        &mut self,
        board: &BoardLayout,
        board_to_camera: &Isometry3<f64>,
    ) -> Result<BoardView, CameraError> {
        if let Some(p) = board.problem() {
            return Err(CameraError::Invalid(format!("board: {p}")));
        }
        let [bw, bh] = board.size();
        let m = PAPER_MARGIN;
        let paper = [[-m, -m], [bw + m, -m], [bw + m, bh + m], [-m, bh + m]];
        for p in paper {
            let c = board_to_camera * Point3::new(p[0], p[1], 0.0);
            if c.z < 0.05 {
                return Err(CameraError::Invalid(
                    "the board is not wholly in front of the camera".into(),
                ));
            }
        }
        let im = &self.imaging;
        let (w, h) = (self.lens.width as usize, self.lens.height as usize);
        let hom = self.homography(board_to_camera);
        // The ideal image reaches past the frame where the lens sees past it.
        let [cw, ch] = self.warp.ideal_size();
        let mut canvas = Canvas::new(cw, ch, self.warp.onto_ideal_image(&hom), im.floor_shade)
            .ok_or_else(|| CameraError::Invalid("the board is seen edge-on".into()))?;
        let n = im.supersample.max(1);
        canvas.polygon(
            &Polygon {
                points: paper.to_vec(),
                shade: im.ink[1],
            },
            n,
        );
        let (black, whole) = family_cells(board.family);
        // The gap beyond each tag's own white border, in cells, is white paper too.
        let quiet = (board.gap * f64::from(black) / board.tag_side - f64::from(whole - black))
            .max(0.0)
            / 2.0;
        let mut corners = Vec::with_capacity(board.len());
        for tag in board.placements() {
            canvas
                .marker(&self.codes, &tag, quiet, n, im.ink[0], im.ink[1])
                .map_err(CameraError::Invalid)?;
            let px = tag
                .corners()
                .map(|p| hom.apply(p).map(|q| self.warp.distort_pixel(q)));
            if px.iter().all(|q| {
                q.is_some_and(|q| {
                    q[0] >= 1.0 && q[1] >= 1.0 && q[0] <= w as f64 - 1.0 && q[1] <= h as f64 - 1.0
                })
            }) {
                corners.push((tag.id, px.map(|q| q.unwrap_or([f64::NAN; 2]))));
            }
        }
        super::blur::gaussian_blur(&mut canvas.data, cw, ch, im.blur_sigma_px);
        let irradiance = self.warp.apply(&canvas.data, cw, ch, im.floor_shade as f32);
        let pixels = super::sensor::develop(
            &irradiance,
            im.exposure,
            im.black_level,
            im.white_level,
            im.noise_sigma,
            &mut self.rng,
        );
        Ok(BoardView {
            width: self.lens.width,
            height: self.lens.height,
            pixels,
            corners,
        })
    }
}

/// A board pose for a view: the board's centre at `centre` (camera frame, metres), facing the
/// camera and turned `tilt` radians about the camera's x axis, `pan` about its y axis and
/// `roll` about its optical axis.
pub fn board_pose(
    board: &BoardLayout,
    centre: [f64; 3],
    tilt: f64,
    pan: f64,
    roll: f64,
) -> Isometry3<f64> {
    use nalgebra::{Translation3, UnitQuaternion, Vector3};
    // Facing the camera: board x → camera x, board y → camera −y, board z → camera −z.
    let facing = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    let turn = UnitQuaternion::from_euler_angles(tilt, pan, roll);
    let rot = turn * facing;
    let [bw, bh] = board.size();
    let mid = rot * Vector3::new(bw / 2.0, bh / 2.0, 0.0);
    Isometry3::from_parts(
        Translation3::new(centre[0] - mid.x, centre[1] - mid.y, centre[2] - mid.z),
        rot,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_world::lens::Distortion;

    fn webcam() -> Intrinsics {
        Intrinsics {
            width: 320,
            height: 240,
            fx: 240.0,
            fy: 240.0,
            cx: 160.0,
            cy: 120.0,
            distortion: Distortion {
                k1: -0.08,
                ..Distortion::NONE
            },
        }
    }

    #[test]
    fn a_frontal_board_is_centred_and_its_corners_are_dark_inside() {
        let board = BoardLayout::default();
        let mut cam = BoardCamera::new(webcam(), Imaging::default(), 3).unwrap();
        let pose = board_pose(&board, [0.0, 0.0, 0.3], 0.0, 0.0, 0.0);
        let v = cam.view(&board, &pose).unwrap();
        assert_eq!(v.corners.len(), 48);
        // The top-left tag (id 100) is at the image's top left.
        let (id, c) = v.corners[0];
        assert_eq!(id, 100);
        assert!(c[3][0] < 160.0 && c[3][1] < 120.0, "{c:?}");
        // Bottom-left below top-left in the image (y down).
        assert!(c[0][1] > c[3][1]);
        // The black ring just inside a corner is dark, the paper between tags light.
        let g = |p: [f64; 2]| v.pixels[p[1] as usize * 320 + p[0] as usize];
        let mid_x = (c[0][0] + c[1][0]) / 2.0;
        let below = [mid_x, c[0][1] + 0.125 * (c[0][1] - c[3][1])];
        assert!(g(below) > 150, "white gap below the tag: {}", g(below));
        let ring = [0.9 * c[0][0] + 0.1 * c[2][0], 0.9 * c[0][1] + 0.1 * c[2][1]];
        assert!(g(ring) < 90, "black ring: {}", g(ring));
    }

    #[test]
    fn a_board_behind_the_camera_is_refused() {
        let board = BoardLayout::default();
        let mut cam = BoardCamera::new(webcam(), Imaging::default(), 3).unwrap();
        let pose = board_pose(&board, [0.0, 0.0, -0.4], 0.0, 0.0, 0.0);
        assert!(cam.view(&board, &pose).is_err());
    }
}
