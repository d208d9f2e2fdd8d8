//! Drawing one frame's irradiance: the table, the polygons and the markers of each view of the
//! scene over the exposure, averaged (motion blur: what moved between the views smears as a
//! real sensor integrates it), the overlays between the camera and the table on top, then the
//! optics' blur and the lens's distortion. Markers and overlays at a height are drawn on their
//! own plane in perspective when the camera knows its place (from its lens).

use super::render::{self, Canvas};
use super::{Camera, CameraError, MarkerPlacement, MarkerTruth, Polygon, Still};

/// The scene at one instant of the exposure: polygons in drawing order, then markers.
#[derive(Debug, Clone, Copy)]
pub struct View<'a> {
    /// Filled polygons on the table, drawn in order.
    pub polygons: &'a [Polygon],
    /// Markers, drawn after the polygons.
    pub markers: &'a [MarkerPlacement],
}

/// Something between the camera and the table (a hand): a polygon on the plane `height` m
/// above the table, drawn over everything.
#[derive(Debug, Clone, PartialEq)]
pub struct Overlay {
    /// Outline (table x, y in metres, on its plane) and reflectance.
    pub polygon: Polygon,
    /// Height of its plane above the table, metres.
    pub height: f64,
}

impl Camera {
    /// The homography of the plane `height` above the table: the table's own for an ideal
    /// overhead camera without a lens (its height unknown: drawn flat).
    pub(super) fn plane(&self, height: f64, what: &str) -> Result<render::Homography, CameraError> {
        let table = self.config.model.table_to_pixel;
        match (&self.pose, &self.config.lens) {
            (Some(pose), Some(lens)) if height != 0.0 => {
                if pose.centre()[2] <= height {
                    return Err(CameraError::Invalid(format!("{what} is above the camera")));
                }
                pose.plane_homography(lens, height)
                    .ok_or_else(|| CameraError::Invalid(format!("{what}: singular homography")))
            }
            _ => Ok(table),
        }
    }

    /// Draw marker `m` on `canvas`, on its own plane.
    pub(super) fn draw_marker(
        &self,
        canvas: &mut Canvas,
        m: &MarkerPlacement,
    ) -> Result<(), CameraError> {
        let im = &self.config.imaging;
        let plane = self.to_canvas(self.plane(m.height, &format!("marker {}", m.id))?);
        canvas
            .set_homography(plane)
            .ok_or_else(|| CameraError::Invalid("singular homography".into()))?;
        canvas
            .marker(
                &self.codes,
                m,
                im.quiet_cells,
                im.supersample.max(1),
                im.ink[0],
                im.ink[1],
            )
            .map_err(CameraError::Invalid)?;
        canvas.set_homography(self.to_canvas(self.config.model.table_to_pixel));
        Ok(())
    }

    /// The ideal image's size: the frame's, or the lens warp's larger one.
    pub(super) fn canvas_size(&self) -> (usize, usize) {
        match &self.warp {
            Some(w) => (w.ideal_size()[0], w.ideal_size()[1]),
            None => (
                self.config.model.width as usize,
                self.config.model.height as usize,
            ),
        }
    }

    /// A homography to ideal pixels, made to draw on the ideal image (whose origin a lens
    /// warp may move).
    pub(super) fn to_canvas(&self, h: render::Homography) -> render::Homography {
        match &self.warp {
            Some(w) => w.onto_ideal_image(&h),
            None => h,
        }
    }

    /// Where an ideal pixel appears in the frame (through the lens's distortion, if any).
    fn distorted(&self, ideal: [f64; 2]) -> [f64; 2] {
        match &self.warp {
            Some(w) => w.distort_pixel(ideal),
            None => ideal,
        }
    }

    /// Draw `views` (averaged) and `overlays`, blur them as the optics do and distort them as
    /// the lens does; the ground truth is the middle view's markers.
    pub(super) fn draw(
        &self,
        views: &[View<'_>],
        overlays: &[super::Overlay],
    ) -> Result<Still, CameraError> {
        let cfg = &self.config;
        let im = &cfg.imaging;
        let h_tp = cfg.model.table_to_pixel;
        let Some(middle) = views.get(views.len() / 2) else {
            return Err(CameraError::Invalid("nothing to draw".into()));
        };
        let n = im.supersample.max(1);
        let table = self.table();
        // The ideal image: the frame, or larger where a lens sees past it.
        let (cw, ch) = self.canvas_size();
        let h_tp = self.to_canvas(h_tp);
        let mut base = Canvas::new(cw, ch, h_tp, im.floor_shade)
            .ok_or_else(|| CameraError::Invalid("singular homography".into()))?;
        base.polygon(&table, n);
        // A still scene is drawn whole and in order. Of a moving one, the polygons and markers
        // that are the same in every view are drawn once, on the base, and the moving ones over
        // it, once per view.
        let moving = views.len() > 1;
        let fixed_polys = fixed(views, |v| v.polygons);
        let fixed_markers = fixed(views, |v| v.markers);
        if moving {
            for (p, _) in middle.polygons.iter().zip(&fixed_polys).filter(|f| *f.1) {
                base.polygon(p, n);
            }
            for (m, _) in middle.markers.iter().zip(&fixed_markers).filter(|f| *f.1) {
                self.draw_marker(&mut base, m)?;
            }
        }
        let mut acc: Option<Vec<f32>> = None;
        for view in views {
            let mut canvas = base.clone();
            for (p, _) in view
                .polygons
                .iter()
                .zip(&fixed_polys)
                .filter(|f| !(moving && *f.1))
            {
                canvas.polygon(p, n);
            }
            for (m, _) in view
                .markers
                .iter()
                .zip(&fixed_markers)
                .filter(|f| !(moving && *f.1))
            {
                self.draw_marker(&mut canvas, m)?;
            }
            match acc.as_mut() {
                None => acc = Some(canvas.data),
                Some(a) => a.iter_mut().zip(&canvas.data).for_each(|(a, c)| *a += c),
            }
        }
        let mut data = acc.unwrap_or_default();
        if views.len() > 1 {
            let k = 1.0 / views.len() as f32;
            data.iter_mut().for_each(|v| *v *= k);
        }
        let mut canvas = Canvas::new(cw, ch, h_tp, 0.0)
            .ok_or_else(|| CameraError::Invalid("singular homography".into()))?;
        canvas.data = data;
        for o in overlays {
            canvas.set_homography(self.to_canvas(self.plane(o.height, "an occluder")?));
            canvas.polygon(&o.polygon, n);
        }
        let truth = middle
            .markers
            .iter()
            .map(|m| self.truth(m))
            .collect::<Result<Vec<_>, _>>()?;
        // Of one view, the image before the blur is kept to draw the next frame where it
        // changed ([`Camera::redraw`]).
        let sharp = canvas.data;
        let mut blurred = vec![0.0f32; sharp.len()];
        let window = render::Window::full(cw, ch);
        super::blur::gaussian_blur_window(&sharp, &mut blurred, cw, ch, im.blur_sigma_px, window);
        let (irradiance, blurred) = match &self.warp {
            Some(warp) => (
                warp.apply(&blurred, cw, ch, im.floor_shade as f32),
                Some(blurred),
            ),
            None => (blurred, None),
        };
        Ok(Still {
            polygons: middle.polygons.to_vec(),
            markers: middle.markers.to_vec(),
            overlays: overlays.to_vec(),
            irradiance,
            truth,
            sharp: (views.len() == 1).then_some(super::Sharp {
                data: sharp,
                blurred,
            }),
        })
    }

    /// The table top, as the first polygon of every frame.
    pub(super) fn table(&self) -> Polygon {
        let [tw, th] = self.config.table;
        Polygon {
            points: vec![[0.0, 0.0], [tw, 0.0], [tw, th], [0.0, th]],
            shade: self.config.imaging.table_shade,
        }
    }

    /// Marker `m` with its quiet zone: the square its drawing covers.
    pub(super) fn outer(&self, m: &MarkerPlacement) -> Result<MarkerPlacement, CameraError> {
        let (_, tw, wab) = self.codes.pattern(m.family, m.id).ok_or_else(|| {
            CameraError::Invalid(format!("{} has no id {}", m.family.name(), m.id))
        })?;
        Ok(MarkerPlacement {
            side: m.side * (tw as f64 + 2.0 * self.config.imaging.quiet_cells) / wab as f64,
            ..*m
        })
    }

    /// A marker's ground truth: its corners and centre in the frame, and whether it is wholly
    /// inside it (its quiet zone too).
    pub(super) fn truth(&self, m: &MarkerPlacement) -> Result<MarkerTruth, CameraError> {
        let (w, h) = (
            f64::from(self.config.model.width),
            f64::from(self.config.model.height),
        );
        let plane = self.plane(m.height, &format!("marker {}", m.id))?;
        let px = |p: [f64; 2]| self.distorted(plane.apply(p).unwrap_or([f64::NAN; 2]));
        let outer = self.outer(m)?;
        let fully_visible = outer.corners().iter().all(|&p| {
            let q = px(p);
            q[0] >= 1.0 && q[1] >= 1.0 && q[0] <= w - 1.0 && q[1] <= h - 1.0
        });
        Ok(MarkerTruth {
            marker: *m,
            corners_px: m.corners().map(px),
            centre_px: px(m.centre),
            fully_visible,
        })
    }
}

/// Which items (by index) are the same in every view; every item counts as moving when the
/// views do not list the same number of them.
fn fixed<'a, T: PartialEq + 'a>(
    views: &[View<'a>],
    items: impl Fn(&View<'a>) -> &'a [T],
) -> Vec<bool> {
    let first = items(&views[0]);
    if views.iter().any(|v| items(v).len() != first.len()) {
        return vec![false; first.len()];
    }
    (0..first.len())
        .map(|i| views.iter().all(|v| items(v)[i] == first[i]))
        .collect()
}
