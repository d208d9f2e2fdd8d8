//! The SVG document builder every figure of the host is drawn with: the live view's camera
//! overlay, the rearrangement and stable-pushing plans, executed runs and the learned strategy.
//!
//! - [`Doc`]: one document — size and view box, a white (or any) [`Doc::background`], arrow
//!   markers ([`Doc::arrow_marker`]), a [`Doc::title`] (the document's name, shown as a tooltip)
//!   and a visible [`Doc::caption`] at its top-left corner.
//! - [`Group`]: a `<g>`, optionally translated, for panels of a figure.
//! - [`Draw`]: the shapes both can hold — [`Draw::polygon`], [`Draw::polyline`], [`Draw::line`],
//!   [`Draw::circle`], [`Draw::rect`], [`Draw::text`] — each painted with a [`Style`].
//! - [`Frame`]: table metres (or any y-up plane) to SVG user units: scale, y flipped down, a
//!   margin and an optional band on top for a title.
//!
//! The XML itself is written by the `svg` crate (no dependencies, escapes `&`, `<`, `>` in text
//! and quotes in attribute values); this module only adds what the figures share. Numbers are
//! rounded to 0.01 user unit; points that are not finite are left out (a shape with a
//! non-finite position or size is not drawn), so a lost track never writes `NaN` into a figure.

use std::fmt;

use svg::Node;
use svg::node::element::Element;

/// A number as written: rounded to 0.01, never `-0`.
fn num(v: f64) -> f64 {
    let r = (v * 100.0).round() / 100.0;
    if r == 0.0 { 0.0 } else { r }
}

fn finite(p: [f64; 2]) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

/// `x,y x,y …` of the finite points.
fn points(pts: &[[f64; 2]]) -> String {
    pts.iter()
        .filter(|p| finite(**p))
        .map(|p| format!("{},{}", num(p[0]), num(p[1])))
        .collect::<Vec<_>>()
        .join(" ")
}

/// How a shape is painted: SVG presentation attributes, set in order (a later value of the
/// same attribute replaces the earlier one), and an optional tooltip (`<title>` child).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Style {
    attrs: Vec<(&'static str, String)>,
    tip: Option<String>,
}

impl Style {
    /// No attribute: SVG's defaults (black fill, no stroke).
    pub fn new() -> Style {
        Style::default()
    }

    /// Set any attribute (escaped when written).
    pub fn attr(mut self, name: &'static str, value: impl fmt::Display) -> Style {
        let value = value.to_string();
        match self.attrs.iter_mut().find(|(n, _)| *n == name) {
            Some(a) => a.1 = value,
            None => self.attrs.push((name, value)),
        }
        self
    }

    fn number(self, name: &'static str, v: f64) -> Style {
        self.attr(name, num(v))
    }

    /// Fill colour (`none` for an outline).
    pub fn fill(self, colour: &str) -> Style {
        self.attr("fill", colour)
    }

    /// Stroke colour.
    pub fn stroke(self, colour: &str) -> Style {
        self.attr("stroke", colour)
    }

    /// Stroke width in user units.
    pub fn width(self, w: f64) -> Style {
        self.number("stroke-width", w)
    }

    /// An outline: no fill, stroke `colour` of width `w`.
    pub fn outline(colour: &str, w: f64) -> Style {
        Style::new().fill("none").stroke(colour).width(w)
    }

    /// Dashes, e.g. `"4 3"` (dash, gap in user units).
    pub fn dash(self, pattern: &str) -> Style {
        self.attr("stroke-dasharray", pattern)
    }

    /// Opacity of the whole shape, 0–1.
    pub fn opacity(self, o: f64) -> Style {
        self.number("opacity", o)
    }

    /// Opacity of the fill only, 0–1.
    pub fn fill_opacity(self, o: f64) -> Style {
        self.number("fill-opacity", o)
    }

    /// An arrowhead at the end of a line or polyline: the marker `id` made by
    /// [`Doc::arrow_marker`].
    pub fn arrow_end(self, id: &str) -> Style {
        self.attr("marker-end", format!("url(#{id})"))
    }

    /// Corner radius of a rectangle.
    pub fn rounded(self, r: f64) -> Style {
        self.number("rx", r)
    }

    /// Font size of a text, in user units.
    pub fn font_size(self, size: f64) -> Style {
        self.number("font-size", size)
    }

    /// Text anchor: `start`, `middle` or `end`.
    pub fn anchor(self, anchor: &str) -> Style {
        self.attr("text-anchor", anchor)
    }

    /// A tooltip: the shape gets a `<title>` child with this text.
    pub fn tip(mut self, text: &str) -> Style {
        self.tip = Some(text.to_string());
        self
    }

    fn apply(&self, e: &mut Element) {
        for (n, v) in &self.attrs {
            e.assign(*n, v.as_str());
        }
        if let Some(t) = &self.tip {
            e.append(titled(t));
        }
    }
}

fn titled(text: &str) -> Element {
    let mut t = Element::new("title");
    t.append(svg::node::Text::new(text));
    t
}

fn element(name: &str, attrs: &[(&'static str, f64)], style: &Style) -> Element {
    let mut e = Element::new(name);
    for (n, v) in attrs {
        e.assign(*n, num(*v));
    }
    style.apply(&mut e);
    e
}

/// What shapes can be drawn into: a [`Doc`] or a [`Group`]. Coordinates are SVG user units
/// (y down); map table metres with a [`Frame`] first.
pub trait Draw {
    /// Append an element as it is (the `svg` crate's type); the other methods build on it.
    fn push(&mut self, e: Element);

    /// A closed polygon through `pts` (at least one finite point, else nothing is drawn).
    fn polygon(&mut self, pts: &[[f64; 2]], style: &Style) {
        let p = points(pts);
        if !p.is_empty() {
            let mut e = element("polygon", &[], style);
            e.assign("points", p);
            self.push(e);
        }
    }

    /// An open polyline through `pts` (at least two finite points, else nothing is drawn).
    fn polyline(&mut self, pts: &[[f64; 2]], style: &Style) {
        if pts.iter().filter(|p| finite(**p)).count() >= 2 {
            let mut e = element("polyline", &[], style);
            e.assign("points", points(pts));
            self.push(e);
        }
    }

    /// A segment from `a` to `b`.
    fn line(&mut self, a: [f64; 2], b: [f64; 2], style: &Style) {
        if finite(a) && finite(b) {
            let xy = [("x1", a[0]), ("y1", a[1]), ("x2", b[0]), ("y2", b[1])];
            self.push(element("line", &xy, style));
        }
    }

    /// A circle of radius `r` around `c`.
    fn circle(&mut self, c: [f64; 2], r: f64, style: &Style) {
        if finite(c) && r.is_finite() {
            self.push(element(
                "circle",
                &[("cx", c[0]), ("cy", c[1]), ("r", r)],
                style,
            ));
        }
    }

    /// A rectangle with top-left corner `at` and size `size`.
    fn rect(&mut self, at: [f64; 2], size: [f64; 2], style: &Style) {
        // SVG draws nothing of a rectangle without area, and renderers reject one of negative size.
        if finite(at) && finite(size) && size[0] > 0.0 && size[1] > 0.0 {
            let a = [
                ("x", at[0]),
                ("y", at[1]),
                ("width", size[0]),
                ("height", size[1]),
            ];
            self.push(element("rect", &a, style));
        }
    }

    /// `content` (escaped) with its baseline starting at `at` (or centred on it, with
    /// [`Style::anchor`]).
    fn text(&mut self, at: [f64; 2], content: &str, style: &Style) {
        if finite(at) {
            let mut e = element("text", &[("x", at[0]), ("y", at[1])], style);
            e.append(svg::node::Text::new(content));
            self.push(e);
        }
    }

    /// A group of shapes.
    fn group(&mut self, g: Group) {
        self.push(g.0);
    }
}

/// A `<g>` element: shapes drawn together, optionally moved.
#[derive(Debug, Clone)]
pub struct Group(Element);

impl Group {
    /// An empty group.
    pub fn new() -> Group {
        Group(Element::new("g"))
    }

    /// An empty group with the element id `id` (for a reader or a test to find it by).
    pub fn with_id(id: &str) -> Group {
        let mut g = Group::new();
        g.0.assign("id", id.to_string());
        g
    }

    /// An empty group whose shapes are moved by `(dx, dy)`.
    pub fn translated(dx: f64, dy: f64) -> Group {
        let mut g = Group::new();
        g.0.assign("transform", format!("translate({},{})", num(dx), num(dy)));
        g
    }
}

impl Default for Group {
    fn default() -> Group {
        Group::new()
    }
}

impl Draw for Group {
    fn push(&mut self, e: Element) {
        self.0.append(e);
    }
}

/// An SVG document: `width` × `height` on screen, a view box (by default the same size from
/// the origin), `font-family="sans-serif"` for every text. Written out by [`fmt::Display`]
/// (`to_string()`), ending with a newline.
#[derive(Debug, Clone)]
pub struct Doc {
    size: [f64; 2],
    view_box: [f64; 4],
    title: Option<String>,
    defs: Vec<Element>,
    body: Vec<Element>,
}

impl Doc {
    /// A blank document of `width` × `height` user units (and pixels).
    pub fn new(width: f64, height: f64) -> Doc {
        Doc {
            size: [width, height],
            view_box: [0.0, 0.0, width, height],
            title: None,
            defs: Vec::new(),
            body: Vec::new(),
        }
    }

    /// A blank document exactly the size of `frame`.
    pub fn for_frame(frame: &Frame) -> Doc {
        Doc::new(frame.width(), frame.height())
    }

    /// Show the user-unit rectangle `[x, y, width, height]` instead of `0 0 width height`.
    pub fn with_view_box(mut self, view_box: [f64; 4]) -> Doc {
        self.view_box = view_box;
        self
    }

    /// Fill the whole view box: a rectangle painted with `style` under everything drawn later.
    pub fn background(&mut self, style: &Style) {
        let [x, y, w, h] = self.view_box;
        self.rect([x, y], [w, h], style);
    }

    /// Define a triangular arrowhead marker `id` of `colour`, for [`Style::arrow_end`].
    pub fn arrow_marker(&mut self, id: &str, colour: &str) {
        let mut m = Element::new("marker");
        m.assign("id", id);
        m.assign("viewBox", "0 0 10 10");
        m.assign("refX", 9);
        m.assign("refY", 5);
        m.assign("markerWidth", 6);
        m.assign("markerHeight", 6);
        m.assign("orient", "auto-start-reverse");
        let mut p = Element::new("path");
        p.assign("d", "M0 0L10 5L0 10z");
        p.assign("fill", colour);
        m.append(p);
        self.defs.push(m);
    }

    /// The document's name (`<title>`: a tooltip in browsers, the accessible name).
    pub fn title(&mut self, text: &str) {
        self.title = Some(text.to_string());
    }

    /// A visible line of text of size `size` at the view box's top-left corner, painted with
    /// `style` (e.g. its fill colour).
    pub fn caption(&mut self, content: &str, size: f64, style: &Style) {
        let at = [self.view_box[0] + 8.0, self.view_box[1] + size + 4.0];
        self.text(at, content, &style.clone().font_size(size));
    }
}

impl Draw for Doc {
    fn push(&mut self, e: Element) {
        self.body.push(e);
    }
}

impl fmt::Display for Doc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [vx, vy, vw, vh] = self.view_box.map(num);
        let mut d = svg::Document::new()
            .set("width", num(self.size[0]))
            .set("height", num(self.size[1]))
            .set("viewBox", format!("{vx} {vy} {vw} {vh}"))
            .set("font-family", "sans-serif");
        if let Some(t) = &self.title {
            d.append(titled(t));
        }
        if !self.defs.is_empty() {
            let mut defs = Element::new("defs");
            for m in &self.defs {
                defs.append(m.clone());
            }
            d.append(defs);
        }
        for e in &self.body {
            d.append(e.clone());
        }
        writeln!(f, "{d}")
    }
}

/// A y-up plane (table metres) mapped to SVG user units: the rectangle `min`–`max` is drawn
/// `scale` units per metre with `max.y` at the top, inside a `margin` on every side and below
/// a `band` (room for a caption) on top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    min: [f64; 2],
    max: [f64; 2],
    scale: f64,
    margin: f64,
    band: f64,
}

impl Frame {
    /// The table `[0, width] × [0, height]` (metres) at `scale` units per metre.
    pub fn table(width: f64, height: f64, scale: f64) -> Frame {
        Frame::region([0.0, 0.0], [width, height], scale)
    }

    /// The rectangle `min`–`max` at `scale` units per metre.
    pub fn region(min: [f64; 2], max: [f64; 2], scale: f64) -> Frame {
        Frame {
            min,
            max,
            scale,
            margin: 0.0,
            band: 0.0,
        }
    }

    /// The same with `margin` user units of room on every side.
    pub fn with_margin(mut self, margin: f64) -> Frame {
        self.margin = margin;
        self
    }

    /// The same with a band `band` user units high above the plane (for a caption).
    pub fn with_band(mut self, band: f64) -> Frame {
        self.band = band;
        self
    }

    /// Where the point `p` (metres, y up) is drawn (user units, y down).
    pub fn map(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.margin + (p[0] - self.min[0]) * self.scale,
            self.band + self.margin + (self.max[1] - p[1]) * self.scale,
        ]
    }

    /// [`Frame::map`] of every point.
    pub fn map_all<'a>(&self, pts: impl IntoIterator<Item = &'a [f64; 2]>) -> Vec<[f64; 2]> {
        pts.into_iter().map(|p| self.map(*p)).collect()
    }

    /// A length in metres (a radius, a tolerance) in user units.
    pub fn length(&self, metres: f64) -> f64 {
        metres * self.scale
    }

    /// The plane's rectangle in user units: top-left corner and size.
    pub fn area(&self) -> ([f64; 2], [f64; 2]) {
        (
            [self.margin, self.band + self.margin],
            [
                (self.max[0] - self.min[0]) * self.scale,
                (self.max[1] - self.min[1]) * self.scale,
            ],
        )
    }

    /// The whole width in user units (margins included).
    pub fn width(&self) -> f64 {
        (self.max[0] - self.min[0]) * self.scale + 2.0 * self.margin
    }

    /// The whole height in user units (band and margins included).
    pub fn height(&self) -> f64 {
        (self.max[1] - self.min[1]) * self.scale + 2.0 * self.margin + self.band
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_attributes_are_escaped() {
        let mut d = Doc::new(10.0, 10.0);
        d.text([1.0, 2.0], "a<b & \"c\"", &Style::new().fill("x\"y"));
        d.title("t<1>");
        let s = d.to_string();
        assert!(s.contains(">a&lt;b &amp; \"c\"</text>"), "{s}");
        assert!(s.contains(r#"fill="x&quot;y""#), "{s}");
        assert!(s.contains("<title>t&lt;1&gt;</title>"), "{s}");
        assert!(!s.contains("a<b"), "{s}");
        assert!(s.starts_with("<svg") && s.ends_with("</svg>\n"), "{s}");
    }

    #[test]
    fn frame_maps_y_up_metres_to_y_down_units() {
        let f = Frame::table(1.0, 0.5, 100.0)
            .with_margin(10.0)
            .with_band(20.0);
        assert_eq!(f.map([0.0, 0.0]), [10.0, 80.0]);
        assert_eq!(f.map([1.0, 0.5]), [110.0, 30.0]);
        assert_eq!(f.map([0.25, 0.1]), [35.0, 70.0]);
        assert_eq!((f.width(), f.height()), (120.0, 90.0));
        assert_eq!(f.area(), ([10.0, 30.0], [100.0, 50.0]));
        assert_eq!(f.length(0.02), 2.0);
        let c = Frame::region([-0.5, -0.5], [0.5, 0.5], 10.0);
        assert_eq!(c.map([0.0, 0.0]), [5.0, 5.0]);
        assert_eq!(c.map([-0.5, 0.5]), [0.0, 0.0]);
    }

    #[test]
    fn polygon_points_are_mapped_rounded_and_finite() {
        let f = Frame::table(1.0, 1.0, 100.0);
        let mut d = Doc::for_frame(&f);
        let tri = f.map_all(&[[0.0, 0.0], [0.5, 0.0], [0.123456, 0.5], [f64::NAN, 0.0]]);
        d.polygon(&tri, &Style::new().fill("#555"));
        let s = d.to_string();
        assert!(
            s.contains(r##"<polygon fill="#555" points="0,100 50,100 12.35,50"/>"##),
            "{s}"
        );
        assert!(
            s.starts_with(
                r#"<svg font-family="sans-serif" height="100" viewBox="0 0 100 100" width="100""#
            ),
            "{s}"
        );
    }

    #[test]
    fn shapes_need_finite_points() {
        let mut g = Group::translated(5.0, -0.001);
        g.polyline(&[[0.0, 0.0]], &Style::new());
        g.line([0.0, f64::INFINITY], [1.0, 1.0], &Style::new());
        g.circle([1.0, 1.0], f64::NAN, &Style::new());
        g.polygon(&[[f64::NAN, 0.0]], &Style::new());
        g.circle([1.0, 2.0], 3.0, &Style::outline("red", 1.5).dash("2,3"));
        // A rectangle without area (a 0 % bar) or of negative size is not written.
        g.rect([0.0, 0.0], [4.0, 0.0], &Style::new());
        g.rect([0.0, 0.0], [-1.0, 2.0], &Style::new());
        let mut d = Doc::new(10.0, 10.0);
        d.group(g);
        let s = d.to_string();
        assert!(s.contains(r#"<g transform="translate(5,0)">"#), "{s}");
        assert_eq!(s.matches('<').count(), 5, "svg, g, circle, /g, /svg: {s}");
        assert!(s.contains(
            r#"<circle cx="1" cy="2" fill="none" r="3" stroke="red" stroke-dasharray="2,3" stroke-width="1.5"/>"#
        ), "{s}");
    }

    #[test]
    fn style_replaces_a_repeated_attribute_and_adds_tips_markers_and_captions() {
        let st = Style::new()
            .fill("red")
            .fill("blue")
            .tip("path <1>")
            .arrow_end("arrow");
        let mut d = Doc::new(100.0, 50.0).with_view_box([0.0, -20.0, 100.0, 70.0]);
        d.arrow_marker("arrow", "#1c7ed6");
        d.background(&Style::new().fill("white"));
        d.polyline(&[[0.0, 0.0], [1.0, 1.0]], &st);
        d.caption("hello", 16.0, &Style::new().fill("yellow"));
        let s = d.to_string();
        assert!(
            s.contains(r#"fill="blue""#) && !s.contains(r#"fill="red""#),
            "{s}"
        );
        assert!(s.contains("<title>path &lt;1&gt;</title>"), "{s}");
        assert!(s.contains(r#"marker-end="url(#arrow)""#), "{s}");
        assert!(
            s.contains(r#"<marker id="arrow""#) || s.contains("<marker "),
            "{s}"
        );
        assert!(
            s.contains(r##"<path d="M0 0L10 5L0 10z" fill="#1c7ed6"/>"##),
            "{s}"
        );
        assert!(
            s.contains(r#"<rect fill="white" height="70" width="100" x="0" y="-20"/>"#),
            "{s}"
        );
        assert!(
            s.contains(r#"<text fill="yellow" font-size="16" x="8" y="0">hello</text>"#),
            "{s}"
        );
    }
}
