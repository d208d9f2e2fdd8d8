//! Axes in metres for figures of the table (or any y-up plane drawn through a
//! [`Frame`]): round ticks along the bottom and left edges, their values, and the unit.

use super::svg::{Doc, Draw, Frame, Style};

/// A tick step (0.05, 0.1, 0.2, 0.5 m …) giving about five to ten ticks over `span` metres.
pub fn tick_step(span: f64) -> f64 {
    let raw = (span / 8.0).max(1e-6);
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag)
}

/// Axes in metres along the bottom and left edges of `f`'s plane (`min`–`max`, metres): ticks,
/// their values, and the unit.
pub fn metre_axes(d: &mut Doc, f: &Frame, min: [f64; 2], max: [f64; 2]) {
    let ink = Style::new().stroke("#444").width(1.0);
    let label = Style::new().fill("#333").font_size(11.0);
    for axis in 0..2 {
        let step = tick_step(max[axis] - min[axis]);
        let mut v = (min[axis] / step).ceil() * step;
        while v <= max[axis] + 1e-9 {
            let (p, q, at, anchor) = if axis == 0 {
                let p = f.map([v, min[1]]);
                (p, [p[0], p[1] + 5.0], [p[0], p[1] + 17.0], "middle")
            } else {
                let p = f.map([min[0], v]);
                (p, [p[0] - 5.0, p[1]], [p[0] - 7.0, p[1] + 4.0], "end")
            };
            d.line(p, q, &ink);
            d.text(at, &format!("{v:.2}"), &label.clone().anchor(anchor));
            v += step;
        }
    }
    let corner = f.map([max[0], min[1]]);
    d.text(
        [corner[0], corner[1] + 32.0],
        "x, y in metres",
        &label.anchor("end"),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_few() {
        assert_eq!(tick_step(1.2), 0.2);
        assert_eq!(tick_step(0.9), 0.2);
        assert_eq!(tick_step(0.3), 0.05);
        assert_eq!(tick_step(4.0), 0.5);
    }

    #[test]
    fn axes_label_the_ticks_in_metres() {
        let f = Frame::table(1.2, 0.9, 100.0).with_margin(40.0);
        let mut d = Doc::for_frame(&f);
        metre_axes(&mut d, &f, [0.0, 0.0], [1.2, 0.9]);
        let s = d.to_string();
        assert!(
            s.contains(">1.20</text>") && s.contains(">0.80</text>"),
            "{s}"
        );
        assert!(s.contains("x, y in metres"));
        // 7 ticks along x (0–1.2 by 0.2), 5 along y (0–0.8).
        assert_eq!(s.matches("<line").count(), 12);
    }
}
