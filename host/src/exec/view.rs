//! The live view: a page in a folder that a browser shows while a run goes on — the latest
//! camera frame with every detected marker outlined and every tracked body drawn where the
//! tracker puts it (heading arrow, name), the current plan or path if one is set, refreshed
//! after every look.
//!
//! Why a folder and not a window or a Rerun recording: it needs nothing installed and no
//! display (it works from a headless machine, over ssh with the folder synced or served by any
//! static file server), the camera image and overlay are plain PNG and SVG that stay in the
//! report afterwards, and it adds no heavy dependency to the host build.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::plot::svg::{Doc, Draw, Style};
use crate::vision::FrameResult;
use crate::vision::calibration::Calibration;
use crate::vision::source::Frame;

/// Writes `live.html`, `camera.png` and `overlay.svg` into a folder.
#[derive(Debug, Clone)]
pub struct LiveView {
    dir: PathBuf,
    updates: u64,
    /// A polyline to draw (table metres): the current plan or global path.
    pub plan: Vec<[f64; 2]>,
}

impl LiveView {
    /// Create the folder and the page.
    pub fn create(dir: &Path) -> Result<LiveView> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the live view folder {}", dir.display()))?;
        let page = r#"<!doctype html><html><head><meta charset="utf-8"><title>pushbot live</title>
<style>body{margin:0;background:#222;color:#eee;font-family:sans-serif}
#v{position:relative;display:inline-block}#v img{display:block;max-width:100vw}
#v object{position:absolute;left:0;top:0;width:100%;height:100%}</style></head><body>
<div id="v"><img id="cam" src="camera.png"><object id="ov" data="overlay.svg" type="image/svg+xml"></object></div>
<script>setInterval(()=>{const t=Date.now();document.getElementById('cam').src='camera.png?'+t;
document.getElementById('ov').data='overlay.svg?'+t;},500);</script></body></html>
"#;
        let path = dir.join("live.html");
        std::fs::write(&path, page).with_context(|| format!("writing {}", path.display()))?;
        Ok(LiveView {
            dir: dir.to_path_buf(),
            updates: 0,
            plan: Vec::new(),
        })
    }

    /// The page to open.
    pub fn page(&self) -> PathBuf {
        self.dir.join("live.html")
    }

    /// Updates written so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// Show `frame` and what the pipeline made of it.
    pub fn update(&mut self, frame: &Frame, result: &FrameResult, cal: &Calibration) -> Result<()> {
        let img = image::GrayImage::from_raw(frame.width, frame.height, frame.pixels.clone())
            .context("frame size does not match its pixels")?;
        // Write then rename, so a browser never reads half a file.
        let tmp = self.dir.join("camera.png.tmp");
        img.save_with_format(&tmp, image::ImageFormat::Png)
            .context("writing the camera image")?;
        std::fs::rename(&tmp, self.dir.join("camera.png")).context("writing the camera image")?;
        let svg = overlay_svg(frame, result, cal, &self.plan);
        let tmp = self.dir.join("overlay.svg.tmp");
        std::fs::write(&tmp, svg).context("writing the overlay")?;
        std::fs::rename(&tmp, self.dir.join("overlay.svg")).context("writing the overlay")?;
        self.updates += 1;
        Ok(())
    }
}

/// The overlay in the frame's pixel coordinates.
pub fn overlay_svg(
    frame: &Frame,
    result: &FrameResult,
    cal: &Calibration,
    plan: &[[f64; 2]],
) -> String {
    let mut d = Doc::new(f64::from(frame.width), f64::from(frame.height));
    for det in &result.detections {
        d.polygon(&det.corners, &Style::outline("lime", 2.0));
    }
    let px = |x: f64, y: f64| cal.table_to_pixel.apply([x, y]);
    if plan.len() >= 2 {
        let pts: Vec<[f64; 2]> = plan.iter().filter_map(|p| px(p[0], p[1])).collect();
        d.polyline(&pts, &Style::outline("orange", 3.0).dash("8,6"));
    }
    let mut marks = Vec::new();
    for t in &result.tracked {
        let (Some(a), Some(b)) = (
            px(t.pose.x, t.pose.y),
            px(
                t.pose.x + 0.06 * t.pose.theta.cos(),
                t.pose.y + 0.06 * t.pose.theta.sin(),
            ),
        ) else {
            continue;
        };
        let colour = if t.seen { "#ff3b30" } else { "#999" };
        d.circle(a, 5.0, &Style::new().fill(colour));
        d.line(a, b, &Style::new().stroke(colour).width(3.0));
        let label = format!(
            "{} ({:.3}, {:.3}, {:.0}°)",
            t.body,
            t.pose.x,
            t.pose.y,
            t.pose.theta.to_degrees()
        );
        marks.push((a, label, colour));
    }
    let spots = place_labels(
        &marks
            .iter()
            .map(|(a, l, _)| (*a, l.chars().count()))
            .collect::<Vec<_>>(),
        LABEL_FONT,
    );
    for ((a, label, colour), at) in marks.iter().zip(spots) {
        // A leader line from the body to a label moved away from it.
        if (at[0] - a[0]).abs() > 12.0 || (at[1] - a[1]).abs() > 2.0 * LABEL_FONT {
            d.line(
                *a,
                [at[0], at[1] - LABEL_FONT * 0.4],
                &Style::new().stroke(colour).width(1.0),
            );
        }
        d.text(at, label, &Style::new().fill(colour).font_size(LABEL_FONT));
    }
    d.caption(
        &format!("t = {:.2} s, frame {}", result.time, result.seq),
        18.0,
        &Style::new().fill("yellow"),
    );
    d.to_string()
}

/// Font size of the live view's labels, pixels.
const LABEL_FONT: f64 = 16.0;

/// Where to put each label so that none overlaps another: `anchors` are the labelled points
/// (pixels) with the label's length in characters; returns each label's text origin (left end
/// of its baseline). A label goes to the first free spot of a few around its point (up-right,
/// down-right, up-left, down-left), then further down in steps of a line until it is free.
/// Pure: used by the live page and the recording's image annotations.
pub fn place_labels(anchors: &[([f64; 2], usize)], font: f64) -> Vec<[f64; 2]> {
    let h = font * 1.25;
    let mut boxes: Vec<[f64; 4]> = Vec::new();
    let mut out = Vec::with_capacity(anchors.len());
    let overlaps = |b: &[f64; 4], boxes: &[[f64; 4]]| {
        boxes
            .iter()
            .any(|o| b[0] < o[2] && o[0] < b[2] && b[1] < o[3] && o[1] < b[3])
    };
    for &(p, chars) in anchors {
        let w = font * 0.6 * chars as f64;
        let candidates = [
            [p[0] + 8.0, p[1] - 8.0],
            [p[0] + 8.0, p[1] + 8.0 + h],
            [p[0] - 8.0 - w, p[1] - 8.0],
            [p[0] - 8.0 - w, p[1] + 8.0 + h],
        ];
        let bx = |o: [f64; 2]| [o[0], o[1] - font, o[0] + w, o[1] - font + h];
        let spot = candidates
            .iter()
            .copied()
            .find(|&o| !overlaps(&bx(o), &boxes))
            .unwrap_or_else(|| {
                let mut o = candidates[1];
                while overlaps(&bx(o), &boxes) {
                    o[1] += h;
                }
                o
            });
        boxes.push(bx(spot));
        out.push(spot);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::place_labels;

    #[test]
    fn labels_of_close_bodies_do_not_overlap() {
        // Four bodies within a few pixels of each other, long labels.
        let anchors: Vec<([f64; 2], usize)> = (0..4)
            .map(|i| ([100.0 + 3.0 * f64::from(i), 100.0 + 2.0 * f64::from(i)], 30))
            .collect();
        let spots = place_labels(&anchors, 16.0);
        let w = 16.0 * 0.6 * 30.0;
        let h = 16.0 * 1.25;
        for i in 0..spots.len() {
            for j in 0..i {
                let (a, b) = (spots[i], spots[j]);
                let apart = (a[0] - b[0]).abs() >= w - 1e-9 || (a[1] - b[1]).abs() >= h - 1e-9;
                assert!(apart, "labels {i} and {j} overlap: {a:?} {b:?}");
            }
        }
        // A lone label stays next to its point.
        let one = place_labels(&[([50.0, 60.0], 5)], 16.0);
        assert_eq!(one, vec![[58.0, 52.0]]);
    }
}
