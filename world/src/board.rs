//! A lens-calibration board: a grid of AprilTags printed on a flat sheet (`columns × rows` tags
//! of one family, ids counting from `first_id` left to right, top row first, as the sheet is
//! read), and its layout file (TOML).
//!
//! The board frame lies in the sheet: origin at the bottom-left corner of the bottom-left tag's
//! black square, x to the right, y up the printed sheet, z out of it towards the viewer, metres.
//! Tag corners are given in the order the detectors give them (bottom-left, bottom-right,
//! top-right, top-left of the printed tag), so a detection's corners pair with the layout's.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::camera::{MarkerFamily, MarkerPlacement};

/// The number of ids of each family (tag36h11: 587, tag25h9: 35).
pub fn family_ids(family: MarkerFamily) -> u32 {
    match family {
        MarkerFamily::Tag36h11 => 587,
        MarkerFamily::Tag25h9 => 35,
    }
}

/// The black square of a family's tag in cells, and the whole tag with its white border.
pub fn family_cells(family: MarkerFamily) -> (u32, u32) {
    match family {
        MarkerFamily::Tag36h11 => (8, 10),
        MarkerFamily::Tag25h9 => (7, 9),
    }
}

/// The layout of a calibration board.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardLayout {
    /// Tag family.
    #[serde(default)]
    pub family: MarkerFamily,
    /// Tags across.
    pub columns: u32,
    /// Tags down.
    pub rows: u32,
    /// The id of the top-left tag; the others count up left to right, top row first.
    #[serde(default)]
    pub first_id: u32,
    /// Side of each tag's black square, metres.
    pub tag_side: f64,
    /// Gap between neighbouring tags' black squares, metres (at least two of the tag's cells:
    /// each tag keeps its own white border).
    pub gap: f64,
}

impl Default for BoardLayout {
    /// 8 × 6 tag36h11 tags, ids 100–147, 24 mm squares 6 mm apart: 234 × 174 mm, fits A4.
    fn default() -> Self {
        BoardLayout {
            family: MarkerFamily::Tag36h11,
            columns: 8,
            rows: 6,
            first_id: 100,
            tag_side: 0.024,
            gap: 0.006,
        }
    }
}

/// Why a board layout was refused.
#[derive(Debug, thiserror::Error)]
pub enum BoardError {
    /// The file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said.
        reason: String,
    },
    /// Not a board layout (TOML syntax, unknown or missing fields).
    #[error("{path}: not a board layout: {reason}")]
    Format {
        /// The file.
        path: String,
        /// What the parser said (with line and column).
        reason: String,
    },
    /// The values make no board.
    #[error("board layout: {0}")]
    Values(String),
}

impl BoardLayout {
    /// What is wrong with this layout, if anything.
    pub fn problem(&self) -> Option<String> {
        let (black, _) = family_cells(self.family);
        let n = u64::from(self.columns) * u64::from(self.rows);
        let ids = u64::from(family_ids(self.family));
        if self.columns == 0 || self.rows == 0 {
            Some(format!(
                "columns and rows must be at least 1, not {} × {}",
                self.columns, self.rows
            ))
        } else if n < 4 {
            Some(format!(
                "{n} tags are too few to calibrate from: at least 4"
            ))
        } else if u64::from(self.first_id) + n > ids {
            Some(format!(
                "ids {}..{} do not fit {} (ids 0..{})",
                self.first_id,
                u64::from(self.first_id) + n,
                self.family.name(),
                ids
            ))
        } else if !(self.tag_side.is_finite() && self.tag_side > 0.0 && self.tag_side <= 1.0) {
            Some(format!(
                "tag_side must be in metres, over 0 and at most 1, not {}",
                self.tag_side
            ))
        } else if !(self.gap.is_finite() && self.gap < 1.0) {
            Some(format!("gap must be in metres, under 1, not {}", self.gap))
        } else if self.gap < 2.0 * self.tag_side / f64::from(black) - 1e-12 {
            Some(format!(
                "gap {} m is narrower than two of the tag's cells ({} m): neighbouring tags \
                 would lose their white borders",
                self.gap,
                2.0 * self.tag_side / f64::from(black)
            ))
        } else {
            None
        }
    }

    /// Parse a layout from TOML; `path` names it in errors.
    pub fn parse(path: &str, text: &str) -> Result<BoardLayout, BoardError> {
        let b: BoardLayout = toml::from_str(text).map_err(|e| BoardError::Format {
            path: path.to_string(),
            reason: e.to_string(),
        })?;
        match b.problem() {
            Some(p) => Err(BoardError::Values(format!("{path}: {p}"))),
            None => Ok(b),
        }
    }

    /// Read and check a layout file.
    pub fn load(path: &Path) -> Result<BoardLayout, BoardError> {
        let text = std::fs::read_to_string(path).map_err(|e| BoardError::Io {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        BoardLayout::parse(&path.display().to_string(), &text)
    }

    /// The layout as a commented TOML file.
    pub fn to_toml(&self) -> String {
        format!(
            "# pushbot lens-calibration board ({}); written by `pushbot calibrate board`.\n\
             # Tags count up from first_id left to right, top row first; lengths in metres\n\
             # (tag_side: the black square; gap: between neighbouring black squares).\n\
             # Measure the printed tag_side and correct it here if the printer scaled the page.\n\
             family = \"{}\"\ncolumns = {}\nrows = {}\nfirst_id = {}\ntag_side = {}\ngap = {}\n",
            self.describe(),
            serde_name(self.family),
            self.columns,
            self.rows,
            self.first_id,
            self.tag_side,
            self.gap
        )
    }

    /// One line describing the board.
    pub fn describe(&self) -> String {
        let [w, h] = self.size();
        format!(
            "{} × {} {} tags, ids {}–{}, {:.1} mm squares {:.1} mm apart, {:.1} × {:.1} mm",
            self.columns,
            self.rows,
            self.family.name(),
            self.first_id,
            self.first_id + self.columns * self.rows - 1,
            self.tag_side * 1e3,
            self.gap * 1e3,
            w * 1e3,
            h * 1e3
        )
    }

    /// The extent of the black squares, metres (width, height).
    pub fn size(&self) -> [f64; 2] {
        let pitch = self.tag_side + self.gap;
        [
            f64::from(self.columns) * pitch - self.gap,
            f64::from(self.rows) * pitch - self.gap,
        ]
    }

    /// The number of tags.
    pub fn len(&self) -> usize {
        self.columns as usize * self.rows as usize
    }

    /// Whether the board has no tags (never, for a checked layout).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The tag `id`'s column and row (row 0 at the top), if it is on the board.
    fn cell(&self, id: u32) -> Option<(u32, u32)> {
        let k = id.checked_sub(self.first_id)?;
        (k < self.columns * self.rows).then(|| (k % self.columns, k / self.columns))
    }

    /// The tag `id`'s place on the board, if it is on it.
    pub fn placement(&self, id: u32) -> Option<MarkerPlacement> {
        let (c, r) = self.cell(id)?;
        let pitch = self.tag_side + self.gap;
        let half = self.tag_side / 2.0;
        Some(MarkerPlacement {
            id,
            family: self.family,
            centre: [
                f64::from(c) * pitch + half,
                f64::from(self.rows - 1 - r) * pitch + half,
            ],
            heading: 0.0,
            side: self.tag_side,
            height: 0.0,
        })
    }

    /// The board's tags in id order.
    pub fn placements(&self) -> Vec<MarkerPlacement> {
        (0..self.columns * self.rows)
            .filter_map(|k| self.placement(self.first_id + k))
            .collect()
    }

    /// The corners of tag `id`'s black square on the board (bottom-left, bottom-right,
    /// top-right, top-left), if the tag is on it.
    pub fn corners(&self, family: MarkerFamily, id: u32) -> Option<[[f64; 2]; 4]> {
        if family != self.family {
            return None;
        }
        self.placement(id).map(|p| p.corners())
    }
}

/// The family's name as the layout file spells it (serde's).
fn serde_name(f: MarkerFamily) -> String {
    toml::Value::try_from(f)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_else(|| f.name().to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_layout_round_trips_through_its_file() {
        let b = BoardLayout::default();
        assert_eq!(b.problem(), None);
        let back = BoardLayout::parse("board.toml", &b.to_toml()).unwrap();
        assert_eq!(back, b);
        let [w, h] = b.size();
        assert!((w - 0.234).abs() < 1e-12 && (h - 0.174).abs() < 1e-12);
        assert!(b.describe().contains("ids 100–147"), "{}", b.describe());
    }

    #[test]
    fn tags_count_from_the_top_left_and_corners_are_in_detector_order() {
        let b = BoardLayout::default();
        let top_left = b.placement(100).unwrap();
        assert!((top_left.centre[0] - 0.012).abs() < 1e-12);
        assert!((top_left.centre[1] - (0.174 - 0.012)).abs() < 1e-12);
        let c = b.corners(MarkerFamily::Tag36h11, 147).unwrap();
        // The last tag is at the bottom right: its bottom-left corner is on y = 0.
        assert!(
            (c[0][1]).abs() < 1e-12 && (c[1][0] - 0.234).abs() < 1e-12,
            "{c:?}"
        );
        assert!(c[2][1] > c[1][1] && c[3][0] < c[2][0]);
        assert_eq!(b.corners(MarkerFamily::Tag36h11, 99), None);
        assert_eq!(b.corners(MarkerFamily::Tag36h11, 148), None);
        assert_eq!(b.corners(MarkerFamily::Tag25h9, 100), None);
        assert_eq!(b.placements().len(), 48);
    }

    #[test]
    fn bad_layouts_are_named() {
        let err = |text: &str| BoardLayout::parse("b.toml", text).unwrap_err().to_string();
        let base = "columns = 8\nrows = 6\ntag_side = 0.024\ngap = 0.006\n";
        assert!(BoardLayout::parse("b.toml", base).is_ok());
        assert!(err("columns = 8\n").contains("b.toml"), "missing fields");
        assert!(err(&format!("{base}colour = 1\n")).contains("colour"));
        assert!(err(&base.replace("0.024", "-1.0")).contains("tag_side"));
        assert!(err(&base.replace("0.006", "0.001")).contains("white borders"));
        assert!(err(&format!("{base}first_id = 580\n")).contains("do not fit"));
        assert!(err(&base.replace("rows = 6", "rows = 0")).contains("at least 1"));
        assert!(err(&format!("{base}family = \"tag99\"\n")).contains("tag99"));
    }
}
