//! Drawing a frame again only where the scene changed: of two frames of one instant each, the
//! pixels that differ are those a moved body covered in either, widened by the optics' blur.
//! There the ideal image is drawn anew — the table, then every polygon and marker in order,
//! clipped to the window, so each pixel is exactly what a whole drawing gives it — then blurred
//! and, through a lens, warped there alone. A robot between its moves and the object it
//! pushes cover a few hundredths of a frame, so most of a drawing's time (coverage of the whole
//! table, the blur of every pixel) is saved and the image is the same.

use super::blur::gaussian_blur_window;
use super::render::{Canvas, Window};
use super::{Camera, CameraError, MarkerPlacement, Overlay, Polygon, Still, View};

impl Camera {
    /// Draw `view` with `overlays` over the still `s` where they differ from what it shows;
    /// false (and `s` unchanged) when that cannot be done and the frame must be drawn whole:
    /// `s` was drawn from several views, the overlays changed, or the scene has other items.
    pub(super) fn redraw(
        &self,
        s: &mut Still,
        view: &View<'_>,
        overlays: &[Overlay],
    ) -> Result<bool, CameraError> {
        if s.sharp.is_none()
            || s.overlays != overlays
            || s.polygons.len() != view.polygons.len()
            || s.markers.len() != view.markers.len()
        {
            return Ok(false);
        }
        let (cw, ch) = self.canvas_size();
        let Some(changed) = self.changed(s, view, cw, ch)? else {
            return Ok(false);
        };
        if !changed.is_empty() {
            let Some(sharp) = s.sharp.as_mut() else {
                return Ok(false);
            };
            let im = &self.config.imaging;
            let window = changed.grown(1, cw, ch);
            // The ideal image there, drawn anew in the order of a whole drawing.
            let mut data = std::mem::take(&mut sharp.data);
            let floor = im.floor_shade as f32;
            for y in window.y0..window.y1 {
                data[y * cw + window.x0..y * cw + window.x1].fill(floor);
            }
            let h_tp = self.to_canvas(self.config.model.table_to_pixel);
            let mut canvas = Canvas::over(data, cw, ch, h_tp)
                .ok_or_else(|| CameraError::Invalid("singular homography".into()))?;
            canvas.clip_to(window);
            let n = im.supersample.max(1);
            canvas.polygon(&self.table(), n);
            for p in view.polygons {
                canvas.polygon(p, n);
            }
            for m in view.markers {
                self.draw_marker(&mut canvas, m)?;
            }
            for o in overlays {
                canvas.set_homography(self.to_canvas(self.plane(o.height, "an occluder")?));
                canvas.polygon(&o.polygon, n);
            }
            sharp.data = canvas.data;
            // The blur reaches 3σ from what changed.
            let sigma = im.blur_sigma_px;
            let reach = if sigma > 0.0 {
                (3.0 * sigma).ceil() as usize
            } else {
                0
            };
            let blurred = window.grown(reach, cw, ch);
            match (&self.warp, sharp.blurred.as_mut()) {
                (Some(warp), Some(b)) => {
                    gaussian_blur_window(&sharp.data, b, cw, ch, sigma, blurred);
                    warp.apply_within(b, cw, ch, floor, blurred, &mut s.irradiance);
                }
                (None, _) => {
                    gaussian_blur_window(&sharp.data, &mut s.irradiance, cw, ch, sigma, blurred)
                }
                (Some(_), None) => return Err(CameraError::Invalid("no blurred image".into())),
            }
        }
        s.truth = view
            .markers
            .iter()
            .map(|m| self.truth(m))
            .collect::<Result<Vec<_>, _>>()?;
        s.polygons = view.polygons.to_vec();
        s.markers = view.markers.to_vec();
        Ok(true)
    }

    /// The pixels of the ideal image that the items of `view` differing from `s`'s cover in
    /// either (empty when none differs); `None` when one does not map to finite pixels.
    fn changed(
        &self,
        s: &Still,
        view: &View<'_>,
        cw: usize,
        ch: usize,
    ) -> Result<Option<Window>, CameraError> {
        let h_tp = self.to_canvas(self.config.model.table_to_pixel);
        let polygon = |p: &Polygon| -> Option<Window> {
            let px: Option<Vec<[f64; 2]>> = p.points.iter().map(|q| h_tp.apply(*q)).collect();
            Window::covering(&px?, cw, ch)
        };
        let mut changed = Window {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        for (a, b) in s.polygons.iter().zip(view.polygons) {
            if a != b {
                let (Some(wa), Some(wb)) = (polygon(a), polygon(b)) else {
                    return Ok(None);
                };
                changed = changed.union(&wa).union(&wb);
            }
        }
        for (a, b) in s.markers.iter().zip(view.markers) {
            if a != b {
                let (Some(wa), Some(wb)) = (self.covered(a, cw, ch)?, self.covered(b, cw, ch)?)
                else {
                    return Ok(None);
                };
                changed = changed.union(&wa).union(&wb);
            }
        }
        Ok(Some(changed))
    }

    /// The pixels of the ideal image marker `m` (with its quiet zone) covers.
    fn covered(
        &self,
        m: &MarkerPlacement,
        cw: usize,
        ch: usize,
    ) -> Result<Option<Window>, CameraError> {
        let plane = self.to_canvas(self.plane(m.height, &format!("marker {}", m.id))?);
        let px: Option<Vec<[f64; 2]>> = self
            .outer(m)?
            .corners()
            .iter()
            .map(|q| plane.apply(*q))
            .collect();
        Ok(px.and_then(|px| Window::covering(&px, cw, ch)))
    }
}

#[cfg(test)]
mod tests {
    use super::super::scene_view::{scene_camera_config, scene_view};
    use super::super::{Camera, Imaging, View};
    use crate::robot::Pose;
    use crate::scene::Scene;
    use pushbot_world::lens::{Distortion, Intrinsics};

    /// Frames of a robot pushing an object, each drawn again only where it changed, are the
    /// frames a fresh camera draws whole, to the last bit of every pixel's irradiance — with
    /// an ideal camera and through a lens.
    #[test]
    fn frames_redrawn_where_they_changed_are_the_frames_drawn_whole() {
        let webcam = Intrinsics {
            width: 960,
            height: 720,
            fx: 700.0,
            fy: 700.0,
            cx: 480.0,
            cy: 360.0,
            distortion: Distortion {
                k1: -0.08,
                ..Distortion::NONE
            },
        };
        for lens in [None, Some(webcam)] {
            let mut scene = Scene::preset("lau-snake").expect("preset");
            scene.camera.lens = lens;
            let imaging = Imaging {
                noise_sigma: 0.0,
                ..Imaging::default()
            };
            let cfg = scene_camera_config(&scene, imaging);
            let mut cam = Camera::new(cfg, 1).expect("camera");
            let object = scene.objects[0].pose;
            let step = |k: f64| {
                let robot = Pose::new(0.3 + 0.02 * k, 0.9, 0.1 * k);
                let moved = Pose::new(object.x + 0.02 * k, object.y, object.theta + 0.05 * k);
                scene_view(&scene, &robot, &[("object".to_string(), moved)])
            };
            let (p, m) = step(0.0);
            let first = cam.capture(0.0, &p, &m).expect("frame");
            for k in 1..4 {
                let (p, m) = step(f64::from(k));
                let mut still = cam.still.take().expect("a still");
                let view = View {
                    polygons: &p,
                    markers: &m,
                };
                assert!(cam.redraw(&mut still, &view, &[]).expect("redraw"));
                let whole = Camera::new(cfg, 1)
                    .expect("camera")
                    .draw(&[view], &[])
                    .expect("drawing");
                assert!(
                    still.irradiance == whole.irradiance,
                    "lens {lens:?}, step {k}: the redrawn frame differs"
                );
                assert_eq!(still.truth, whole.truth);
                cam.still = Some(still);
            }
            let (p, m) = step(3.0);
            let last = cam.capture(1.0, &p, &m).expect("frame");
            let moved = first
                .pixels
                .iter()
                .zip(&last.pixels)
                .filter(|(a, b)| a != b)
                .count();
            assert!(moved > 2_000, "lens {lens:?}: {moved} pixels changed");
        }
    }
}
