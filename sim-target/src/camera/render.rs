//! Anti-aliased rendering of the table seen from above: polygons (table, bodies) and AprilTag
//! markers drawn with their exact area coverage of each pixel (scanlines: sub-rows with exact
//! horizontal coverage), on the whole canvas or within a [`Window`] of it. The optics' blur is
//! [`super::blur`], the sensor (exposure, noise, 8-bit quantisation) [`super::sensor`].
//!
//! Marker bit patterns come from the AprilTag library's family data ([`super::families`]), laid
//! out exactly as its `apriltag_to_image` does.

use super::families::{FamilyData, TAG25H9, TAG36H11};
use serde::{Deserialize, Serialize};

pub use pushbot_world::camera::{Homography, MarkerFamily, MarkerPlacement};

/// A filled polygon on the table plane (table metres) with its reflectance in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Polygon {
    /// Vertices in order (either winding); the even-odd rule decides inside.
    pub points: Vec<[f64; 2]>,
    /// Reflectance: 0 black, 1 white.
    pub shade: f64,
}

/// Bit patterns of the supported families.
#[derive(Debug, Clone, Copy, Default)]
pub struct TagCodes;

impl TagCodes {
    /// The family tables.
    pub fn new() -> Result<TagCodes, String> {
        Ok(TagCodes)
    }

    fn family(&self, f: MarkerFamily) -> &'static FamilyData {
        match f {
            MarkerFamily::Tag36h11 => &TAG36H11,
            MarkerFamily::Tag25h9 => &TAG25H9,
        }
    }

    /// Number of ids in a family.
    pub fn len(&self, f: MarkerFamily) -> usize {
        self.family(f).codes.len()
    }

    /// Whether a family has no ids (never, for the built-in ones).
    pub fn is_empty(&self, f: MarkerFamily) -> bool {
        self.len(f) == 0
    }

    /// The tag's black cells as runs along its rows: `(row, first column, end column)` (end
    /// exclusive), row 0 at the top; drawn or printed as one rectangle each.
    pub fn black_runs(pattern: &[bool], tw: usize) -> Vec<(usize, usize, usize)> {
        let mut runs = Vec::new();
        for (row, cells) in pattern.chunks_exact(tw.max(1)).enumerate().take(tw) {
            let mut col = 0;
            while col < cells.len() {
                if cells[col] {
                    col += 1;
                    continue;
                }
                let start = col;
                while col < cells.len() && !cells[col] {
                    col += 1;
                }
                runs.push((row, start, col));
            }
        }
        runs
    }

    /// The tag's image, `total_width`² cells row-major (row 0 at the top of the printed tag),
    /// `true` = white, and the width of its black square in cells; as `apriltag_to_image`.
    pub fn pattern(&self, f: MarkerFamily, id: u32) -> Option<(Vec<bool>, usize, usize)> {
        let fam = self.family(f);
        let code = *fam.codes.get(id as usize)?;
        let tw = fam.total_width;
        let mut im = vec![false; tw * tw];
        let wbw = fam.width_at_border + if fam.reversed_border { 0 } else { 2 };
        let wbs = (tw - wbw) / 2;
        for i in 0..wbw.saturating_sub(1) {
            im[wbs * tw + wbs + i] = true;
            im[(wbs + i) * tw + tw - 1 - wbs] = true;
            im[(tw - 1 - wbs) * tw + wbs + i + 1] = true;
            im[(wbs + 1 + i) * tw + wbs] = true;
        }
        let bs = (tw - fam.width_at_border) / 2;
        for (i, (&bx, &by)) in fam.bit_x.iter().zip(fam.bit_y).enumerate().take(fam.nbits) {
            if code & (1u64 << (fam.nbits - i - 1)) != 0 {
                let x = bx as isize + bs as isize;
                let y = by as isize + bs as isize;
                if (0..tw as isize).contains(&x) && (0..tw as isize).contains(&y) {
                    im[y as usize * tw + x as usize] = true;
                }
            }
        }
        Some((im, tw, fam.width_at_border))
    }
}

/// A grayscale reflectance image, row-major, `width × height`.
#[derive(Debug, Clone)]
pub struct Canvas {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Reflectance per pixel.
    pub data: Vec<f32>,
    pixel_to_table: Homography,
    table_to_pixel: Homography,
    /// Only the pixels of this window are drawn ([`Self::clip_to`]); the whole canvas at first.
    clip: Window,
}

/// A rectangle of pixels: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// Column past the last.
    pub x1: usize,
    /// Row past the last.
    pub y1: usize,
}

impl Window {
    /// The whole of a `width × height` image.
    pub fn full(width: usize, height: usize) -> Window {
        Window {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Whether it holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// The smallest window holding both (either may be empty).
    pub fn union(&self, other: &Window) -> Window {
        match (self.is_empty(), other.is_empty()) {
            (true, _) => *other,
            (_, true) => *self,
            _ => Window {
                x0: self.x0.min(other.x0),
                y0: self.y0.min(other.y0),
                x1: self.x1.max(other.x1),
                y1: self.y1.max(other.y1),
            },
        }
    }

    /// Grown by `by` pixels on every side, within a `width × height` image.
    pub fn grown(&self, by: usize, width: usize, height: usize) -> Window {
        Window {
            x0: self.x0.saturating_sub(by),
            y0: self.y0.saturating_sub(by),
            x1: (self.x1 + by).min(width),
            y1: (self.y1 + by).min(height),
        }
    }

    /// The pixels a fill of points with these pixel coordinates may touch, within a
    /// `width × height` image (as [`Canvas`] covers them); `None` when a point is not finite.
    pub fn covering<'a>(
        points: impl IntoIterator<Item = &'a [f64; 2]>,
        width: usize,
        height: usize,
    ) -> Option<Window> {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for q in points {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if !(lo.iter().chain(&hi).all(|v| v.is_finite())) {
            return None;
        }
        Some(Window {
            x0: lo[0].floor().max(0.0) as usize,
            y0: lo[1].floor().max(0.0) as usize,
            x1: (hi[0].ceil() + 1.0).clamp(0.0, width as f64) as usize,
            y1: (hi[1].ceil() + 1.0).clamp(0.0, height as f64) as usize,
        })
    }
}

impl Canvas {
    /// A canvas of uniform reflectance `fill` seen through `table_to_pixel`.
    pub fn new(
        width: usize,
        height: usize,
        table_to_pixel: Homography,
        fill: f64,
    ) -> Option<Canvas> {
        Some(Canvas {
            width,
            height,
            data: vec![fill as f32; width * height],
            pixel_to_table: table_to_pixel.inverse()?,
            table_to_pixel,
            clip: Window::full(width, height),
        })
    }

    /// A canvas of the reflectances `data` (`width × height`, row-major) seen through
    /// `table_to_pixel`; `None` when the sizes disagree or the homography is singular.
    pub fn over(
        data: Vec<f32>,
        width: usize,
        height: usize,
        table_to_pixel: Homography,
    ) -> Option<Canvas> {
        (data.len() == width * height).then_some(())?;
        Some(Canvas {
            width,
            height,
            data,
            pixel_to_table: table_to_pixel.inverse()?,
            table_to_pixel,
            clip: Window::full(width, height),
        })
    }

    /// Draw only within `window` from now on (the whole canvas when it reaches past it): a
    /// pixel inside is drawn exactly as without the clip.
    pub fn clip_to(&mut self, window: Window) {
        let full = Window::full(self.width, self.height);
        self.clip = Window {
            x0: window.x0.min(full.x1),
            y0: window.y0.min(full.y1),
            x1: window.x1.min(full.x1),
            y1: window.y1.min(full.y1),
        };
    }

    /// See the table through another homography from now on (a marker raised above the table is
    /// a plane of its own); `None` (and no change) if it is singular.
    pub fn set_homography(&mut self, table_to_pixel: Homography) -> Option<()> {
        self.pixel_to_table = table_to_pixel.inverse()?;
        self.table_to_pixel = table_to_pixel;
        Some(())
    }

    /// Draw a filled polygon (even-odd rule) of table points.
    pub fn polygon(&mut self, poly: &Polygon, n: usize) {
        if poly.points.len() < 3 {
            return;
        }
        let Some(px) = poly
            .points
            .iter()
            .map(|p| self.table_to_pixel.apply(*p))
            .collect::<Option<Vec<_>>>()
        else {
            return;
        };
        self.fill(&[px], poly.shade as f32, n);
    }

    /// Fill the even-odd union of `rings` (pixel coordinates; rings that only share edges make
    /// their union) with `shade`, blended by the covered fraction of each pixel. A homography
    /// maps lines to lines, so what was a polygon on the table is one in pixels and is covered
    /// scanline by scanline: `n` sub-rows per pixel row, each with exact horizontal coverage.
    fn fill(&mut self, rings: &[Vec<[f64; 2]>], shade: f32, n: usize) {
        let Some(w) = Window::covering(rings.iter().flatten(), self.width, self.height) else {
            return;
        };
        let c = self.clip;
        let (x0, y0) = (w.x0.max(c.x0), w.y0.max(c.y0));
        let (x1, y1) = (w.x1.min(c.x1), w.y1.min(c.y1));
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        // Edges that a scanline can cross: (y of one end, y of the other, x at the first, dx/dy).
        let edges: Vec<[f64; 4]> = rings
            .iter()
            .filter(|r| r.len() >= 3)
            .flat_map(|r| (0..r.len()).map(move |i| (r[i], r[(i + 1) % r.len()])))
            .filter(|(a, b)| a[1] != b[1])
            .map(|(a, b)| [a[1], b[1], a[0], (b[0] - a[0]) / (b[1] - a[1])])
            .collect();
        let n = n.max(1);
        // Per pixel of a row: the fractional coverage of spans' ends, and the sub-rows whose
        // spans cover it whole (as a difference array: +1 where a run of whole pixels starts,
        // −1 past its end), so a span costs its two ends, not its length.
        let mut frac = vec![0.0f64; x1 - x0];
        let mut runs = vec![0i32; x1 - x0 + 1];
        let mut xs: Vec<f64> = Vec::new();
        let mut row_edges: Vec<[f64; 4]> = Vec::new();
        for y in y0..y1 {
            let (top, bottom) = (y as f64, (y + 1) as f64);
            row_edges.clear();
            row_edges.extend(
                edges
                    .iter()
                    .filter(|e| e[0].min(e[1]) < bottom && e[0].max(e[1]) > top),
            );
            if row_edges.is_empty() {
                continue;
            }
            frac.iter_mut().for_each(|c| *c = 0.0);
            runs.iter_mut().for_each(|c| *c = 0);
            for j in 0..n {
                let yy = y as f64 + (j as f64 + 0.5) / n as f64;
                xs.clear();
                for &[ya, yb, xa, slope] in &row_edges {
                    if (ya > yy) != (yb > yy) {
                        xs.push(xa + (yy - ya) * slope);
                    }
                }
                xs.sort_by(|a, b| a.total_cmp(b));
                for span in xs.chunks_exact(2) {
                    let (xa, xb) = (span[0].max(x0 as f64), span[1].min(x1 as f64));
                    if xb <= xa {
                        continue;
                    }
                    let (ia, ib) = (xa.floor() as usize, xb.floor() as usize);
                    if ia == ib {
                        frac[ia - x0] += xb - xa;
                        continue;
                    }
                    frac[ia - x0] += (ia + 1) as f64 - xa;
                    let (start, end) = (ia + 1 - x0, ib.min(x1) - x0);
                    if start < end {
                        runs[start] += 1;
                        runs[end] -= 1;
                    }
                    if ib < x1 {
                        frac[ib - x0] += xb - ib as f64;
                    }
                }
            }
            let row = &mut self.data[y * self.width + x0..y * self.width + x1];
            let mut whole = 0i32;
            for ((v, f), r) in row.iter_mut().zip(&frac).zip(&runs) {
                whole += r;
                let covered = f + f64::from(whole);
                if covered > 0.0 {
                    let c = (covered / n as f64) as f32;
                    *v = *v * (1.0 - c) + shade * c;
                }
            }
        }
    }

    /// Draw a marker with a white quiet zone `quiet_cells` wide around the tag image (beyond the
    /// family's own one-cell white border), `n` sub-rows per pixel row; `black`/`white` reflectances.
    #[allow(clippy::too_many_arguments)]
    pub fn marker(
        &mut self,
        codes: &TagCodes,
        m: &MarkerPlacement,
        quiet_cells: f64,
        n: usize,
        black: f64,
        white: f64,
    ) -> Result<(), String> {
        let (pattern, tw, wab) = codes
            .pattern(m.family, m.id)
            .ok_or_else(|| format!("{} has no id {}", m.family.name(), m.id))?;
        if !(m.side > 0.0 && m.side.is_finite()) {
            return Err(format!("marker {} has side {}", m.id, m.side));
        }
        let cell = m.side / wab as f64;
        let half = (tw as f64 / 2.0 + quiet_cells) * cell;
        if !(half > 0.0 && half.is_finite()) {
            return Err(format!(
                "marker {} has a quiet zone of {quiet_cells} cells",
                m.id
            ));
        }
        // Marker frame (a to the right, b up, metres from the centre) to pixels.
        let (s, c) = m.heading.sin_cos();
        let h = self.table_to_pixel;
        let to_px =
            |a: f64, b: f64| h.apply([m.centre[0] + c * a - s * b, m.centre[1] + s * a + c * b]);
        let rect = |a0: f64, a1: f64, b0: f64, b1: f64| -> Option<Vec<[f64; 2]>> {
            let (a0, a1) = (a0.max(-half), a1.min(half));
            let (b0, b1) = (b0.max(-half), b1.min(half));
            if a0 >= a1 || b0 >= b1 {
                return Some(Vec::new());
            }
            Some(vec![
                to_px(a0, b0)?,
                to_px(a1, b0)?,
                to_px(a1, b1)?,
                to_px(a0, b1)?,
            ])
        };
        // The white square (tag image and quiet zone), then the black cells over it: each row's
        // runs of black cells as rectangles, filled together so that shared edges leave no seam.
        let Some(square) = rect(-half, half, -half, half) else {
            return Ok(());
        };
        let t2 = tw as f64 / 2.0;
        let mut black_rings = Vec::new();
        for (row, start, end) in TagCodes::black_runs(&pattern, tw) {
            let (a0, a1) = ((start as f64 - t2) * cell, (end as f64 - t2) * cell);
            let (b0, b1) = ((t2 - row as f64 - 1.0) * cell, (t2 - row as f64) * cell);
            let Some(r) = rect(a0, a1, b0, b1) else {
                return Ok(());
            };
            black_rings.push(r);
        }
        self.fill(&[square], white as f32, n);
        self.fill(&black_rings, black as f32, n);
        Ok(())
    }
}

/// Even-odd point-in-polygon test.
pub fn point_in_polygon(pts: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let mut j = pts.len() - 1;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            inside = !inside;
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn homography_inverse_round_trips() {
        let h = Homography([
            [700.0, 3.0, 20.0],
            [-2.0, -690.0, 700.0],
            [1e-4, -2e-4, 1.0],
        ]);
        let inv = h.inverse().unwrap();
        for p in [[0.1, 0.2], [1.1, 0.85], [0.6, 0.0]] {
            let q = inv.apply(h.apply(p).unwrap()).unwrap();
            assert!((q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1]).abs() < 1e-12);
        }
    }

    /// The rendered tag36h11 id 0 matches the published tag image (first rows of
    /// tag36_11_00000.png: white border, black ring, then the code bits).
    #[test]
    fn tag36h11_pattern_has_border_and_ring() {
        let codes = TagCodes::new().unwrap();
        let (p, tw, wab) = codes.pattern(MarkerFamily::Tag36h11, 0).unwrap();
        assert_eq!((tw, wab), (10, 8));
        for i in 0..tw {
            assert!(
                p[i] && p[(tw - 1) * tw + i] && p[i * tw] && p[i * tw + tw - 1],
                "white border"
            );
        }
        for i in 1..tw - 1 {
            assert!(
                !p[tw + i] && !p[(tw - 2) * tw + i] && !p[i * tw + 1] && !p[i * tw + tw - 2],
                "black ring"
            );
        }
        // Bits read back in the family's order give the code.
        let fam = &TAG36H11;
        let mut code = 0u64;
        for (&bx, &by) in fam.bit_x.iter().zip(fam.bit_y) {
            let (x, y) = (bx as usize + 1, by as usize + 1);
            code = (code << 1) | p[y * tw + x] as u64;
        }
        assert_eq!(code, fam.codes[0]);
        assert_eq!(code, 0x0000000d7e00984b, "tag36h11 id 0 as published");
        assert!(codes.pattern(MarkerFamily::Tag36h11, 587).is_none());
    }

    /// A half-plane edge at a sub-pixel position is rendered with the exact area coverage.
    #[test]
    fn edge_coverage_is_subpixel_exact() {
        let mut c = Canvas::new(8, 4, Homography::IDENTITY, 0.0).unwrap();
        let poly = Polygon {
            points: vec![[0.0, 0.0], [3.25, 0.0], [3.25, 4.0], [0.0, 4.0]],
            shade: 1.0,
        };
        c.polygon(&poly, 8);
        assert_eq!(c.data[2], 1.0);
        assert!((c.data[3] - 0.25).abs() < 1e-6, "{}", c.data[3]);
        assert_eq!(c.data[4], 0.0);
    }

    /// A homography with perspective, and a turned marker 8 cm wide seen through it.
    fn turned_marker_in_perspective() -> (Homography, MarkerPlacement) {
        let h = Homography([[600.0, 40.0, 10.0], [-30.0, 580.0, 15.0], [0.3, 0.2, 1.0]]);
        let m = MarkerPlacement {
            id: 7,
            family: MarkerFamily::Tag36h11,
            centre: [0.07, 0.07],
            heading: 0.4,
            side: 0.08,
            height: 0.0,
        };
        (h, m)
    }

    /// A marker turned and seen in perspective: each pixel is its exact coverage, as a
    /// brute-force sampling of 48 × 48 points in every pixel finds it; no seam where black
    /// cells of neighbouring rows meet.
    #[test]
    fn a_marker_is_drawn_with_its_coverage_of_each_pixel() {
        let (h, m) = turned_marker_in_perspective();
        let (black, white, quiet, old) = (0.04f32, 0.95f32, 1.0, 0.5f32);
        let codes = TagCodes::new().unwrap();
        let mut c = Canvas::new(110, 110, h, f64::from(old)).unwrap();
        c.marker(&codes, &m, quiet, 64, f64::from(black), f64::from(white))
            .unwrap();
        let (pattern, tw, wab) = codes.pattern(m.family, m.id).unwrap();
        let cell = m.side / wab as f64;
        let half = (tw as f64 / 2.0 + quiet) * cell;
        let inv = h.inverse().unwrap();
        let (s, co) = m.heading.sin_cos();
        let shade = |u: f64, v: f64| {
            let p = inv.apply([u, v]).unwrap();
            let d = [p[0] - m.centre[0], p[1] - m.centre[1]];
            let (a, b) = (co * d[0] + s * d[1], -s * d[0] + co * d[1]);
            if a.abs() >= half || b.abs() >= half {
                return old;
            }
            let col = a / cell + tw as f64 / 2.0;
            let row = tw as f64 / 2.0 - b / cell;
            if col < 0.0 || row < 0.0 || col >= tw as f64 || row >= tw as f64 {
                return white;
            }
            if pattern[row as usize * tw + col as usize] {
                white
            } else {
                black
            }
        };
        let (mut worst, mut sum, mut blacks) = (0.0f32, 0.0f32, 0);
        let k = 48;
        for y in 0..110 {
            for x in 0..110 {
                let mut r = 0.0f32;
                for j in 0..k {
                    for i in 0..k {
                        let u = x as f64 + (i as f64 + 0.5) / k as f64;
                        let v = y as f64 + (j as f64 + 0.5) / k as f64;
                        r += shade(u, v);
                    }
                }
                r /= (k * k) as f32;
                let d = (c.data[y * 110 + x] - r).abs();
                worst = worst.max(d);
                sum += d;
                blacks += usize::from((r - black).abs() < 1e-4);
            }
        }
        assert!(
            blacks > 300,
            "the marker is in the image ({blacks} black pixels)"
        );
        assert!(
            c.data[0] == old && c.data[110 * 110 - 1] == old,
            "the marker is inside"
        );
        assert!(worst < 0.03, "worst pixel off by {worst}");
        let mean = sum / (110.0 * 110.0);
        assert!(mean < 1e-3, "mean error {mean}");
    }

    /// A clipped canvas draws the pixels of its window exactly as an unclipped one, and no
    /// other.
    #[test]
    fn a_clipped_canvas_draws_its_window_alone() {
        let (h, m) = turned_marker_in_perspective();
        let codes = TagCodes::new().unwrap();
        let poly = Polygon {
            points: vec![[0.01, 0.02], [0.15, 0.03], [0.1, 0.16]],
            shade: 0.8,
        };
        let draw = |clip: Option<Window>| {
            let mut c = Canvas::new(110, 110, h, 0.5).unwrap();
            if let Some(w) = clip {
                c.clip_to(w);
            }
            c.polygon(&poly, 8);
            c.marker(&codes, &m, 1.0, 8, 0.04, 0.95).unwrap();
            c.data
        };
        let whole = draw(None);
        let win = Window {
            x0: 30,
            y0: 41,
            x1: 77,
            y1: 60,
        };
        let part = draw(Some(win));
        let mut differs = 0;
        for y in 0..110 {
            for x in 0..110 {
                let i = y * 110 + x;
                if (win.x0..win.x1).contains(&x) && (win.y0..win.y1).contains(&y) {
                    assert_eq!(part[i], whole[i], "({x}, {y})");
                    differs += usize::from(whole[i] != 0.5);
                } else {
                    assert_eq!(part[i], 0.5, "({x}, {y}) outside the window");
                }
            }
        }
        assert!(differs > 200, "the window holds drawing ({differs} pixels)");
    }
}
