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
        d.text(
            [a[0] + 8.0, a[1] - 8.0],
            &label,
            &Style::new().fill(colour).font_size(16.0),
        );
    }
    d.caption(
        &format!("t = {:.2} s, frame {}", result.time, result.seq),
        18.0,
        &Style::new().fill("yellow"),
    );
    d.to_string()
}
