//! Anti-aliased rendering of the table seen from above: polygons (table, bodies) and AprilTag
//! markers drawn with their exact area coverage of each pixel (scanlines: sub-rows with exact
//! horizontal coverage), then the optics' Gaussian blur. The sensor (exposure, noise, 8-bit
//! quantisation) is [`super::sensor`].
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
        })
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
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for q in rings.iter().flatten() {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if !(lo.iter().chain(&hi).all(|v| v.is_finite())) {
            return;
        }
        let x0 = lo[0].floor().max(0.0) as usize;
        let y0 = lo[1].floor().max(0.0) as usize;
        let x1 = (hi[0].ceil() + 1.0).clamp(0.0, self.width as f64) as usize;
        let y1 = (hi[1].ceil() + 1.0).clamp(0.0, self.height as f64) as usize;
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
        let mut cov = vec![0.0f64; x1 - x0];
        let mut xs: Vec<f64> = Vec::new();
        for y in y0..y1 {
            cov.iter_mut().for_each(|c| *c = 0.0);
            for j in 0..n {
                let yy = y as f64 + (j as f64 + 0.5) / n as f64;
                xs.clear();
                for &[ya, yb, xa, slope] in &edges {
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
                        cov[ia - x0] += xb - xa;
                        continue;
                    }
                    cov[ia - x0] += (ia + 1) as f64 - xa;
                    for c in &mut cov[ia + 1 - x0..ib.min(x1) - x0] {
                        *c += 1.0;
                    }
                    if ib < x1 {
                        cov[ib - x0] += xb - ib as f64;
                    }
                }
            }
            let row = &mut self.data[y * self.width + x0..y * self.width + x1];
            for (v, c) in row.iter_mut().zip(&cov) {
                let c = (*c / n as f64) as f32;
                *v = *v * (1.0 - c) + shade * c;
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

/// Separable Gaussian blur with standard deviation `sigma` pixels (edges clamped). Both passes
/// run along rows (the vertical one adds whole shifted rows), so the inner loops vectorise.
pub fn gaussian_blur(data: &mut [f32], width: usize, height: usize, sigma: f64) {
    if sigma <= 0.0 || width == 0 || height == 0 || data.len() < width * height {
        return;
    }
    let r = (3.0 * sigma).ceil() as usize;
    let mut k: Vec<f32> = (0..=2 * r)
        .map(|i| {
            let d = i as f64 - r as f64;
            (-(d * d) / (2.0 * sigma * sigma)).exp() as f32
        })
        .collect();
    let sum: f32 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
    // Horizontal: each row padded with its edge values, then a dense convolution.
    let mut padded = vec![0.0f32; width + 2 * r];
    let mut tmp = vec![0.0f32; width * height];
    for (row, out) in data
        .chunks_exact(width)
        .zip(tmp.chunks_exact_mut(width))
        .take(height)
    {
        padded[..r].fill(row[0]);
        padded[r..r + width].copy_from_slice(row);
        padded[r + width..].fill(row[width - 1]);
        for (t, &kv) in k.iter().enumerate() {
            for (o, &v) in out.iter_mut().zip(&padded[t..t + width]) {
                *o += kv * v;
            }
        }
    }
    // Vertical: output row y is the weighted sum of rows y − r … y + r (clamped).
    for y in 0..height {
        let out = &mut data[y * width..(y + 1) * width];
        out.fill(0.0);
        for (t, &kv) in k.iter().enumerate() {
            let yy = (y + t).saturating_sub(r).min(height - 1);
            let src = &tmp[yy * width..(yy + 1) * width];
            for (o, &v) in out.iter_mut().zip(src) {
                *o += kv * v;
            }
        }
    }
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

    /// A marker turned and seen in perspective: each pixel is its exact coverage, as a
    /// brute-force sampling of 48 × 48 points in every pixel finds it; no seam where black
    /// cells of neighbouring rows meet.
    #[test]
    fn a_marker_is_drawn_with_its_coverage_of_each_pixel() {
        let h = Homography([[600.0, 40.0, 10.0], [-30.0, 580.0, 15.0], [0.3, 0.2, 1.0]]);
        let m = MarkerPlacement {
            id: 7,
            family: MarkerFamily::Tag36h11,
            centre: [0.07, 0.07],
            heading: 0.4,
            side: 0.08,
            height: 0.0,
        };
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

    #[test]
    fn blur_keeps_mean() {
        let mut d = vec![0.0f32; 100];
        d[55] = 1.0;
        gaussian_blur(&mut d, 10, 10, 0.8);
        let s: f32 = d.iter().sum();
        assert!((s - 1.0).abs() < 1e-4);
        assert!(d[55] < 0.5 && d[54] > 0.0);
    }

    /// The separable blur equals the direct 2-D convolution with clamped edges, at the edges
    /// too.
    #[test]
    fn blur_matches_the_direct_convolution() {
        use rand::{Rng, SeedableRng};
        let (w, h, sigma) = (13usize, 9usize, 0.9);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let img: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
        let mut fast = img.clone();
        gaussian_blur(&mut fast, w, h, sigma);
        let r = (3.0 * sigma).ceil() as isize;
        let g = |d: isize| (-((d * d) as f64) / (2.0 * sigma * sigma)).exp();
        let norm: f64 = (-r..=r).map(g).sum();
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut acc = 0.0;
                for dy in -r..=r {
                    for dx in -r..=r {
                        let xx = (x + dx).clamp(0, w as isize - 1) as usize;
                        let yy = (y + dy).clamp(0, h as isize - 1) as usize;
                        acc += g(dx) * g(dy) * f64::from(img[yy * w + xx]);
                    }
                }
                let want = acc / (norm * norm);
                let got = f64::from(fast[y as usize * w + x as usize]);
                assert!((got - want).abs() < 1e-5, "({x}, {y}): {got} vs {want}");
            }
        }
    }
}
