//! The printable calibration board: an SVG at true size (millimetres) of a
//! [`BoardLayout`], each tag's bit pattern from the simulated camera's family tables
//! ([`crate::sim::synth::TagCodes`], the AprilTag library's data, from the simulator's renderer), with the layout described
//! on the sheet and a 100 mm scale bar to check the print's scale.

use crate::sim::synth::TagCodes;
use pushbot_world::board::BoardLayout;
use svg::Node;
use svg::node::element::Element;

/// White paper around the tags, millimetres.
pub const MARGIN_MM: f64 = 15.0;
/// The band below the tags with the description and the scale bar, millimetres.
pub const LEGEND_MM: f64 = 14.0;

fn rect(x: f64, y: f64, w: f64, h: f64, fill: &str) -> Element {
    let mut e = Element::new("rect");
    for (k, v) in [("x", x), ("y", y), ("width", w), ("height", h)] {
        e.assign(k, format!("{v:.4}"));
    }
    e.assign("fill", fill);
    e
}

fn text(x: f64, y: f64, size: f64, content: &str) -> Element {
    let mut e = Element::new("text");
    e.assign("x", format!("{x:.3}"));
    e.assign("y", format!("{y:.3}"));
    e.assign("font-size", format!("{size:.2}"));
    e.assign("font-family", "sans-serif");
    e.append(svg::node::Text::new(content));
    e
}

/// The board as an SVG document (mm units), or why it cannot be drawn.
pub fn board_svg(board: &BoardLayout) -> Result<String, String> {
    if let Some(p) = board.problem() {
        return Err(p);
    }
    let codes = TagCodes::new()?;
    let [bw, bh] = board.size().map(|v| v * 1e3);
    let (w, h) = (bw + 2.0 * MARGIN_MM, bh + 2.0 * MARGIN_MM + LEGEND_MM);
    let mut doc = svg::Document::new()
        .set("width", format!("{w:.3}mm"))
        .set("height", format!("{h:.3}mm"))
        .set("viewBox", format!("0 0 {w:.3} {h:.3}"));
    let mut title = Element::new("title");
    title.append(svg::node::Text::new(board.describe()));
    doc.append(title);
    doc.append(rect(0.0, 0.0, w, h, "white"));
    for tag in board.placements() {
        let (pattern, tw, wab) = codes
            .pattern(tag.family, tag.id)
            .ok_or_else(|| format!("{} has no id {}", tag.family.name(), tag.id))?;
        let cell = tag.side * 1e3 / wab as f64;
        // Page coordinates: y down from the top of the sheet.
        let x0 = MARGIN_MM + tag.centre[0] * 1e3 - tw as f64 / 2.0 * cell;
        let y0 = MARGIN_MM + bh - tag.centre[1] * 1e3 - tw as f64 / 2.0 * cell;
        let mut g = Element::new("g");
        g.assign("id", format!("tag{}", tag.id));
        for (row, start, end) in TagCodes::black_runs(&pattern, tw) {
            g.append(rect(
                x0 + start as f64 * cell,
                y0 + row as f64 * cell,
                (end - start) as f64 * cell,
                cell,
                "black",
            ));
        }
        doc.append(g);
    }
    let y = MARGIN_MM + bh + MARGIN_MM * 0.5;
    doc.append(text(MARGIN_MM, y + 3.0, 3.0, &board.describe()));
    doc.append(text(
        MARGIN_MM,
        y + 7.5,
        2.6,
        "Print at 100 % (no fit to page), glue flat on a rigid board. The bar is 100 mm: \
         if it is not, put the measured tag side in the layout file.",
    ));
    let bar = 100.0f64.min(bw);
    doc.append(rect(MARGIN_MM, y + 9.5, bar, 1.0, "black"));
    Ok(doc.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sheet_is_at_true_size_with_every_tag_and_its_description() {
        let board = BoardLayout::default();
        let s = board_svg(&board).unwrap();
        assert!(s.contains("width=\"264.000mm\""), "{}", &s[..300]);
        assert!(s.contains("height=\"218.000mm\""), "{}", &s[..300]);
        for id in [100, 123, 147] {
            assert!(s.contains(&format!("id=\"tag{id}\"")), "tag {id}");
        }
        assert!(!s.contains("id=\"tag148\""));
        assert!(s.contains(&board.describe()));
        let bad = BoardLayout {
            columns: 0,
            ..board
        };
        assert!(board_svg(&bad).is_err());
    }

    /// The printed sheet, rasterised (at 96 dpi), is read by the detector: every tag with its
    /// id where the layout puts it, corners in the layout's order.
    #[test]
    fn the_detector_reads_the_printed_sheet_as_the_layout_says() {
        use crate::vision::detect::Detector;
        let board = BoardLayout::default();
        let png = crate::plot::render_png(&board_svg(&board).unwrap(), 1.0).unwrap();
        let gray = image::load_from_memory(&png).unwrap().into_luma8();
        let (width, height) = gray.dimensions();
        let frame = crate::vision::frame::Frame {
            seq: 0,
            time: 0.0,
            width,
            height,
            pixels: gray.into_raw(),
        };
        let mut det =
            crate::vision::apriltag::AprilTagC::new(&[board.family], &Default::default()).unwrap();
        let dets = det.detect(&frame).unwrap();
        assert_eq!(dets.len(), 48);
        let [bw, bh] = board.size();
        let px_per_mm = f64::from(width) / (bw * 1e3 + 2.0 * MARGIN_MM);
        assert!((px_per_mm - 96.0 / 25.4).abs() < 0.01, "{px_per_mm}");
        for d in &dets {
            let want = board.corners(d.family, d.id).expect("a board id");
            for (c, w) in d.corners.iter().zip(want) {
                let mm = [c[0] / px_per_mm, c[1] / px_per_mm];
                let page = [MARGIN_MM + w[0] * 1e3, MARGIN_MM + (bh - w[1]) * 1e3];
                assert!(
                    (mm[0] - page[0]).hypot(mm[1] - page[1]) < 0.3,
                    "tag {} corner at {mm:?} mm, the layout says {page:?}",
                    d.id
                );
            }
        }
    }
}
