//! The camera's lens in the rendered image: the scene is drawn through the ideal pinhole (the
//! table→pixel homography), then warped through the lens's `plumb_bob` distortion
//! ([`pushbot_world::lens`]) — each output pixel takes the ideal image's irradiance where its
//! undistorted ray falls (bilinear), from a map computed once per camera, as OpenCV's
//! `initUndistortRectifyMap` + `remap` do the other way round. Marker corners in the ground
//! truth go through the same distortion.

use pushbot_world::camera::Homography;
use pushbot_world::lens::Intrinsics;

use super::render::Window;

/// Where each output pixel samples the ideal image (its index-space x, y; NaN: nowhere). The
/// ideal image is drawn larger than the frame where the lens needs it (a barrel lens sees past
/// the ideal frame's edges): [`LensWarp::ideal_origin`] and [`LensWarp::ideal_size`].
#[derive(Debug, Clone)]
pub struct LensWarp {
    lens: Intrinsics,
    map: Vec<[f32; 2]>,
    origin: [f64; 2],
    size: [usize; 2],
}

/// The ideal image is at most this many times the frame on each side.
const MAX_GROWTH: f64 = 3.0;

impl LensWarp {
    /// The warp of a `width`×`height` image through `lens`, which must be made for that size.
    pub fn new(lens: Intrinsics, width: u32, height: u32) -> Result<LensWarp, String> {
        if (lens.width, lens.height) != (width, height) {
            return Err(format!(
                "the lens is calibrated for {}×{} frames, the camera renders {width}×{height}",
                lens.width, lens.height
            ));
        }
        if let Some(p) = lens.problem() {
            return Err(format!("lens: {p}"));
        }
        let mut ideal = Vec::with_capacity(width as usize * height as usize);
        let (mut lo, mut hi) = ([0.0f64, 0.0], [f64::from(width), f64::from(height)]);
        for j in 0..height {
            for i in 0..width {
                let px = [f64::from(i) + 0.5, f64::from(j) + 0.5];
                let q = lens.undistort_pixel(px);
                if let Some(q) = q {
                    for k in 0..2 {
                        lo[k] = lo[k].min(q[k].floor() - 1.0);
                        hi[k] = hi[k].max(q[k].ceil() + 1.0);
                    }
                }
                ideal.push(q);
            }
        }
        // The ideal image covers every ray the frame sees, within reason.
        let (w, h) = (f64::from(width), f64::from(height));
        let grow = (MAX_GROWTH - 1.0) / 2.0;
        let lo = [lo[0].max(-grow * w), lo[1].max(-grow * h)];
        let hi = [hi[0].min(w + grow * w), hi[1].min(h + grow * h)];
        let map = ideal
            .into_iter()
            .map(|q| match q {
                Some([u, v]) => [(u - 0.5 - lo[0]) as f32, (v - 0.5 - lo[1]) as f32],
                None => [f32::NAN; 2],
            })
            .collect();
        Ok(LensWarp {
            lens,
            map,
            origin: lo,
            size: [(hi[0] - lo[0]) as usize, (hi[1] - lo[1]) as usize],
        })
    }

    /// Where the ideal image's top-left corner is in the ideal pixel frame (≤ 0).
    pub fn ideal_origin(&self) -> [f64; 2] {
        self.origin
    }

    /// `h` (anything → ideal pixels) made to draw on the ideal image, whose top-left corner is
    /// [`LensWarp::ideal_origin`].
    pub fn onto_ideal_image(&self, h: &Homography) -> Homography {
        let [ox, oy] = self.origin;
        Homography([[1.0, 0.0, -ox], [0.0, 1.0, -oy], [0.0, 0.0, 1.0]]).compose(h)
    }

    /// The ideal image's size, pixels.
    pub fn ideal_size(&self) -> [usize; 2] {
        self.size
    }

    /// Where an ideal pixel (the homography's) appears in the distorted image.
    pub fn distort_pixel(&self, ideal: [f64; 2]) -> [f64; 2] {
        self.lens.distort_pixel(ideal)
    }

    /// The distorted image of an ideal one (`background` where the lens sees past it).
    pub fn apply(&self, ideal: &[f32], width: usize, height: usize, background: f32) -> Vec<f32> {
        self.map
            .iter()
            .map(|&uv| sample(ideal, width, height, background, uv))
            .collect()
    }

    /// Update `out` (a distorted image of an earlier `ideal`) where it samples `window` of the
    /// ideal image, the only part that changed: each updated pixel exactly as [`Self::apply`]
    /// gives it.
    pub fn apply_within(
        &self,
        ideal: &[f32],
        width: usize,
        height: usize,
        background: f32,
        window: Window,
        out: &mut [f32],
    ) {
        // A pixel reads ideal pixels floor(u) and floor(u) + 1 (and the same in v).
        let (x0, y0) = (window.x0 as f32 - 1.0, window.y0 as f32 - 1.0);
        let (x1, y1) = (window.x1 as f32, window.y1 as f32);
        for (o, &[u, v]) in out.iter_mut().zip(&self.map) {
            if u >= x0 && u < x1 && v >= y0 && v < y1 {
                *o = sample(ideal, width, height, background, [u, v]);
            }
        }
    }
}

/// The ideal image's irradiance at index-space `[u, v]`, bilinear; `background` outside it.
fn sample(ideal: &[f32], width: usize, height: usize, background: f32, [u, v]: [f32; 2]) -> f32 {
    let at = |x: usize, y: usize| ideal.get(y * width + x).copied().unwrap_or(background);
    if !(u.is_finite() && v.is_finite())
        || u < 0.0
        || v < 0.0
        || u > (width - 1) as f32
        || v > (height - 1) as f32
    {
        return background;
    }
    let (x0, y0) = (u.floor() as usize, v.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(width - 1), (y0 + 1).min(height - 1));
    let (fx, fy) = (u - x0 as f32, v - y0 as f32);
    let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
    let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
    top * (1.0 - fy) + bottom * fy
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_world::lens::Distortion;

    fn lens(k1: f64) -> Intrinsics {
        Intrinsics {
            width: 64,
            height: 48,
            fx: 50.0,
            fy: 50.0,
            cx: 32.0,
            cy: 24.0,
            distortion: Distortion {
                k1,
                ..Distortion::NONE
            },
        }
    }

    #[test]
    fn a_bright_spot_moves_where_the_lens_puts_it() {
        let (w, h) = (64usize, 48usize);
        let warp = LensWarp::new(lens(-0.3), 64, 48).unwrap();
        // The ideal image reaches past the frame: a barrel lens sees more.
        let [ox, oy] = warp.ideal_origin();
        let [iw, ih] = warp.ideal_size();
        assert!(
            ox < 0.0 && oy < 0.0 && iw > w && ih > h,
            "{ox} {oy} {iw} {ih}"
        );
        // A 2×2 bright square in the ideal image near a corner.
        let mut ideal = vec![0.0f32; iw * ih];
        for (x, y) in [(8, 6), (9, 6), (8, 7), (9, 7)] {
            ideal[(y - oy as i64) as usize * iw + (x - ox as i64) as usize] = 1.0;
        }
        let out = warp.apply(&ideal, iw, ih, 0.0);
        let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
        for (k, v) in out.iter().enumerate() {
            sx += f64::from(*v) * ((k % w) as f64 + 0.5);
            sy += f64::from(*v) * ((k / w) as f64 + 0.5);
            s += f64::from(*v);
        }
        let seen = [sx / s, sy / s];
        let want = warp.distort_pixel([9.0, 7.0]);
        assert!(
            (seen[0] - want[0]).hypot(seen[1] - want[1]) < 0.35,
            "spot at {seen:?}, the lens puts it at {want:?}"
        );
        // Barrel: pulled towards the centre.
        assert!(want[0] > 9.0 && want[1] > 7.0, "{want:?}");
    }

    /// Warping again only where a window of the ideal image changed gives the warp of the
    /// whole changed image.
    #[test]
    fn a_changed_window_warps_as_the_whole_image() {
        use rand::{Rng, SeedableRng};
        let warp = LensWarp::new(lens(-0.3), 64, 48).unwrap();
        let [iw, ih] = warp.ideal_size();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let mut ideal: Vec<f32> = (0..iw * ih).map(|_| rng.random_range(0.0..1.0)).collect();
        let mut out = warp.apply(&ideal, iw, ih, 0.1);
        let (cx, cy) = (iw / 2, ih / 2);
        let win = Window {
            x0: cx - 10,
            y0: cy - 7,
            x1: cx + 11,
            y1: cy + 8,
        };
        for y in win.y0..win.y1 {
            for x in win.x0..win.x1 {
                ideal[y * iw + x] = rng.random_range(0.0..1.0);
            }
        }
        let before = out.clone();
        warp.apply_within(&ideal, iw, ih, 0.1, win, &mut out);
        assert_eq!(out, warp.apply(&ideal, iw, ih, 0.1));
        assert!(out != before, "the window is in the frame");
    }

    #[test]
    fn a_lens_for_other_frames_is_refused() {
        let e = LensWarp::new(lens(-0.1), 960, 720).unwrap_err();
        assert!(e.contains("64×48"), "{e}");
    }
}
