//! SVG → PNG with `resvg`, for every figure the project draws as SVG.
//!
//! Text uses the machine's system fonts, loaded once per process. The generic families
//! (`sans-serif`, `serif`, `monospace`) are pointed at a font that is really there (DejaVu if
//! present, else the first face found), so labels do not vanish because "Arial" is missing.
//! With no font at all, text is left out of the picture; nothing panics.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use anyhow::{Context, bail};
use resvg::usvg::{self, fontdb};

/// The largest picture side in pixels (larger SVGs are refused, not rendered).
const MAX_SIDE: u32 = 16_384;

fn fonts() -> Arc<fontdb::Database> {
    static DB: OnceLock<Arc<fontdb::Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = fontdb::Database::new();
        db.load_system_fonts();
        let families: Vec<String> = db
            .faces()
            .flat_map(|f| f.families.iter().map(|(n, _)| n.clone()))
            .collect();
        let pick = |wanted: &[&str]| -> Option<String> {
            wanted
                .iter()
                .find_map(|w| families.iter().find(|f| f.as_str() == *w).cloned())
                .or_else(|| families.first().cloned())
        };
        if let Some(f) = pick(&["DejaVu Sans", "Liberation Sans", "Noto Sans"]) {
            db.set_sans_serif_family(f);
        }
        if let Some(f) = pick(&["DejaVu Serif", "Liberation Serif", "Noto Serif"]) {
            db.set_serif_family(f);
        }
        if let Some(f) = pick(&["DejaVu Sans Mono", "Liberation Mono", "Noto Sans Mono"]) {
            db.set_monospace_family(f);
        }
        Arc::new(db)
    })
    .clone()
}

/// Render an SVG document to PNG bytes at `scale` pixels per SVG unit.
pub fn render_png(svg: &str, scale: f32) -> anyhow::Result<Vec<u8>> {
    if !(scale.is_finite() && scale > 0.0) {
        bail!("PNG scale must be a positive number, not {scale}");
    }
    let opt = usvg::Options {
        fontdb: fonts(),
        font_family: "sans-serif".to_string(),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(svg, &opt).context("parsing the SVG")?;
    let size = tree.size();
    let (w, h) = (
        (size.width() * scale).ceil(),
        (size.height() * scale).ceil(),
    );
    if !(w >= 1.0 && h >= 1.0 && w <= MAX_SIDE as f32 && h <= MAX_SIDE as f32) {
        bail!("the picture would be {w} × {h} pixels (1..={MAX_SIDE} per side)");
    }
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(w as u32, h as u32).context("allocating the picture")?;
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    pixmap.encode_png().context("encoding the PNG")
}

/// Render an SVG document to a PNG file, one pixel per SVG unit.
pub fn svg_to_png(svg: &str, path: &Path) -> anyhow::Result<()> {
    let png = render_png(svg, 1.0)?;
    std::fs::write(path, png).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SVG: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20" font-family="sans-serif"><rect width="100%" height="100%" fill="white"/><rect x="0" y="0" width="10" height="10" fill="#ff0000"/><text x="20" y="15" font-size="12">A</text></svg>"##;

    fn decode(png: &[u8]) -> image::RgbaImage {
        image::load_from_memory(png).unwrap().to_rgba8()
    }

    #[test]
    fn renders_shapes_at_their_place_and_scale() {
        let img = decode(&render_png(SVG, 2.0).unwrap());
        assert_eq!((img.width(), img.height()), (80, 40));
        assert_eq!(img.get_pixel(5, 5).0, [255, 0, 0, 255]);
        assert_eq!(img.get_pixel(25, 5).0, [255, 255, 255, 255]);
    }

    #[test]
    fn text_is_drawn_when_a_font_exists() {
        let img = decode(&render_png(SVG, 1.0).unwrap());
        let dark = (20..32)
            .flat_map(|x| (4..16).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 128)
            .count();
        if fonts().faces().next().is_some() {
            assert!(dark > 0, "no glyph pixels although fonts exist");
        } else {
            assert_eq!(dark, 0);
        }
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        assert!(render_png("not svg", 1.0).is_err());
        assert!(render_png(SVG, 0.0).is_err());
        assert!(render_png(SVG, 1e6).is_err());
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.png");
        svg_to_png(SVG, &p).unwrap();
        assert!(std::fs::read(&p).unwrap().starts_with(b"\x89PNG"));
        assert!(svg_to_png(SVG, &dir.path().join("no/such/dir.png")).is_err());
    }
}
