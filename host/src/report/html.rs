//! `report.html`: one self-contained page per run — a section per stage with its outcome, its
//! numbers as a table (a number that is itself a record, like a collection's statistics, as a
//! table inside the cell, never raw JSON), its figures at their own size (scaled down only to
//! fit the page, and up when they are small) with captions, and its notes.

use std::collections::HashMap;
use std::fmt::Write;

use serde_json::Value;

use super::StageReport;

/// Figures narrower than this are shown scaled up to it, pixels.
const MIN_FIGURE_PX: f64 = 480.0;
/// Figures lower than this are shown scaled up to it (a row of small plan panels), pixels;
/// the page's width caps both.
const MIN_FIGURE_HEIGHT_PX: f64 = 360.0;

/// The unit a field's values are shown in, read from the last word of its key
/// (`final_distance_m` is in metres, shown in millimetres when under a metre).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// No unit named.
    None,
    /// Metres (`_m`).
    Metre,
    /// Millimetres (`_mm`).
    Millimetre,
    /// Seconds (`_s`).
    Second,
    /// Milliseconds (`_ms`).
    Millisecond,
    /// Degrees (`_deg`).
    Degree,
    /// Radians (`_rad`).
    Radian,
    /// Mebibytes (`_mib`).
    Mebibyte,
}

/// A field's key as a label for people, and the unit of its values: `final_distance_m
/// (camera)` is "Final distance (camera)" in metres, `map_cpu_ms` "Map CPU" in milliseconds,
/// `collected_now` "Collected now".
pub fn label(key: &str) -> (String, Unit) {
    // Words a key shortens.
    const WORDS: &[(&str, &str)] = &[
        ("map_ms", "cost map built in ms"),
        ("plan_ms", "planned in ms"),
        ("replan_ms", "re-planning ms"),
        ("pushed_m", "pushed along m"),
        ("end_x", "end x m"),
        ("end_y", "end y m"),
        ("end_theta_deg", "end heading deg"),
        ("replans", "re-plans"),
        ("repositions", "re-positionings"),
    ];
    let key = match key.find(' ') {
        Some(i) => WORDS
            .iter()
            .find(|(k, _)| *k == &key[..i])
            .map_or(key.to_owned(), |(_, w)| {
                format!("{}{}", w.replace(' ', "_"), &key[i..])
            }),
        None => WORDS
            .iter()
            .find(|(k, _)| *k == key)
            .map_or(key.to_owned(), |(_, w)| w.replace(' ', "_")),
    };
    let key = key.as_str();
    let (base, rest) = match key.find(' ') {
        Some(i) => key.split_at(i),
        None => (key, ""),
    };
    let mut words: Vec<&str> = base.split('_').filter(|w| !w.is_empty()).collect();
    let unit = match words.last().copied() {
        Some("m") => Unit::Metre,
        Some("mm") => Unit::Millimetre,
        Some("s") => Unit::Second,
        Some("ms") => Unit::Millisecond,
        Some("deg") => Unit::Degree,
        Some("rad") => Unit::Radian,
        Some("mib") => Unit::Mebibyte,
        _ => Unit::None,
    };
    if unit != Unit::None && words.len() > 1 {
        words.pop();
    }
    let words: Vec<String> = words
        .iter()
        .map(|w| match *w {
            "cpu" | "json" | "mcap" | "svg" | "png" | "id" | "rms" => w.to_uppercase(),
            _ => (*w).to_owned(),
        })
        .collect();
    let mut text = words.join(" ");
    if let Some(first) = text.get(..1) {
        text = first.to_uppercase() + &text[1..];
    }
    (text + rest, unit)
}

/// `x` to at most four significant digits, without trailing zeros (`0.0128`, `52.71`,
/// `1235`); numbers of five or more digits before the point are rounded to whole numbers.
pub fn significant(x: f64) -> String {
    if !x.is_finite() {
        return if x.is_nan() {
            "—".into()
        } else if x > 0.0 {
            "∞".into()
        } else {
            "−∞".into()
        };
    }
    if x == 0.0 {
        return "0".into();
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (3 - magnitude).max(0) as usize;
    let text = format!("{x:.decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    };
    if text == "-0" { "0".into() } else { text }
}

/// A number in `unit`, rounded, with the unit's symbol (metres under one shown in mm).
fn quantity(x: f64, unit: Unit) -> String {
    match unit {
        Unit::None => significant(x),
        Unit::Metre if x.abs() < 1.0 => format!("{} mm", significant(x * 1000.0)),
        Unit::Metre => format!("{} m", significant(x)),
        Unit::Millimetre => format!("{} mm", significant(x)),
        Unit::Second => format!("{} s", significant(x)),
        Unit::Millisecond => format!("{} ms", significant(x)),
        Unit::Degree => format!("{}°", significant(x)),
        Unit::Radian => format!("{} rad", significant(x)),
        Unit::Mebibyte => format!("{} MiB", significant(x)),
    }
}

/// A value for a table cell, as HTML: numbers rounded, records as tables, lists of records as
/// tables with a column per key, other lists comma-separated.
pub fn value_html(v: &Value) -> String {
    value_in(v, Unit::None)
}

/// [`value_html`] of a value in `unit`; the keys of records and lists of records are labels.
fn value_in(v: &Value, unit: Unit) -> String {
    match v {
        Value::Number(n) => match n.as_f64() {
            Some(x) if n.is_f64() || unit != Unit::None => escape(&quantity(x, unit)),
            _ => n.to_string(),
        },
        Value::String(t) => escape(t),
        Value::Bool(b) => if *b { "yes" } else { "no" }.into(),
        Value::Null => "—".into(),
        Value::Object(m) => {
            let mut h = String::from("<table class=\"inner\">");
            for (k, v) in m {
                let (text, unit) = label(k);
                let _ = write!(
                    h,
                    "<tr><th>{}</th><td>{}</td></tr>",
                    escape(&text),
                    value_in(v, unit)
                );
            }
            h.push_str("</table>");
            h
        }
        Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_object) => {
            let mut keys: Vec<&String> = Vec::new();
            for e in a {
                for k in e.as_object().into_iter().flat_map(|m| m.keys()) {
                    if !keys.contains(&k) {
                        keys.push(k);
                    }
                }
            }
            let mut h = String::from("<table class=\"inner\"><tr>");
            for k in &keys {
                let _ = write!(h, "<th>{}</th>", escape(&label(k).0));
            }
            h.push_str("</tr>");
            for e in a {
                h.push_str("<tr>");
                for k in &keys {
                    let unit = label(k).1;
                    let _ = write!(
                        h,
                        "<td>{}</td>",
                        e.get(k.as_str())
                            .map_or(String::new(), |v| value_in(v, unit))
                    );
                }
                h.push_str("</tr>");
            }
            h.push_str("</table>");
            h
        }
        Value::Array(a) => a
            .iter()
            .map(|v| value_in(v, unit))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The width and height an SVG declares (its root's `width` and `height`), pixels.
pub fn svg_size(svg: &str) -> Option<[f64; 2]> {
    let start = svg.find("<svg")?;
    let head = &svg[start..start + svg[start..].find('>')?];
    let attr = |name: &str| -> Option<f64> {
        let key = format!(" {name}=\"");
        let i = head.find(&key)? + key.len();
        let j = head[i..].find('"')?;
        head[i..i + j].trim_end_matches("px").parse().ok()
    };
    Some([attr("width")?, attr("height")?])
}

/// Escape text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page; `sizes` are the figures' own sizes by file name (those missing are shown at
/// the page's width).
pub fn render(title: &str, stages: &[StageReport], sizes: &HashMap<String, [f64; 2]>) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{t}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }}
h1 {{ font-size: 1.6em; }} h2 {{ border-bottom: 1px solid #ccc; padding-bottom: .2em; }}
.ok {{ color: #18794e; font-weight: bold; }} .failed {{ color: #c0362c; font-weight: bold; }}
table {{ border-collapse: collapse; margin: .5em 0; }}
td, th {{ border: 1px solid #ddd; padding: .25em .6em; text-align: left; vertical-align: top; }}
table.inner {{ margin: 0; font-size: .92em; }} table.inner th {{ font-weight: normal; color: #555; }}
figure {{ display: block; margin: 1em 0; }}
figure img {{ display: block; max-width: 100%; height: auto; border: 1px solid #ddd; }}
figcaption {{ font-size: .9em; color: #555; margin-top: .3em; }}
</style></head><body>
<h1>{t}</h1>
<table><tr><th>Stage</th><th>Paper</th><th>Result</th><th>Wall time</th><th>Mission time</th></tr>
"#,
        t = escape(title)
    );
    for s in stages {
        let _ = writeln!(
            h,
            r##"<tr><td><a href="#{id}">{title}</a></td><td>{paper}</td><td class="{c}">{r}</td><td>{w} s</td><td>{rt} s</td></tr>"##,
            id = escape(&s.id),
            title = escape(&s.title),
            paper = escape(&s.paper),
            c = if s.success { "ok" } else { "failed" },
            r = if s.success { "reached" } else { "failed" },
            w = significant(s.wall_s),
            rt = significant(s.mission_s),
        );
    }
    h.push_str("</table>\n");
    for s in stages {
        let _ = writeln!(
            h,
            r#"<h2 id="{id}">{title}</h2><p>{paper} — <span class="{c}">{r}</span></p>"#,
            id = escape(&s.id),
            title = escape(&s.title),
            paper = escape(&s.paper),
            c = if s.success { "ok" } else { "failed" },
            r = if s.success {
                "goal reached"
            } else {
                "goal not reached"
            },
        );
        if !s.numbers.is_empty() {
            h.push_str("<table>\n");
            for (k, v) in &s.numbers {
                let (text, unit) = label(k);
                let _ = writeln!(
                    h,
                    "<tr><th>{}</th><td>{}</td></tr>",
                    escape(&text),
                    value_in(v, unit)
                );
            }
            h.push_str("</table>\n");
        }
        for (file, caption) in &s.figures {
            // The figure's own size, scaled up when small so its text stays readable; CSS
            // scales it down to the page's width.
            let size = match sizes.get(file) {
                Some(&[w, hh]) if w > 0.0 && hh > 0.0 => {
                    let k = (MIN_FIGURE_PX / w).max(MIN_FIGURE_HEIGHT_PX / hh).max(1.0);
                    format!(r#" width="{:.0}" height="{:.0}""#, w * k, hh * k)
                }
                _ => r#" style="width: 100%""#.to_string(),
            };
            let _ = writeln!(
                h,
                r#"<figure><a href="{f}"><img src="{f}"{size} alt="{c}"></a><figcaption>{c}</figcaption></figure>"#,
                f = escape(file),
                c = escape(caption)
            );
        }
        if !s.notes.is_empty() {
            h.push_str("<ul>\n");
            for n in &s.notes {
                let _ = writeln!(h, "<li>{}</li>", escape(n));
            }
            h.push_str("</ul>\n");
        }
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_has_a_section_per_stage_and_escapes_text() {
        let mut a = StageReport::new("a", "Stage <A>", "paper §1");
        a.success = true;
        a.number("cost", 12);
        a.figures.push(("a.svg".into(), "plan".into()));
        let b = StageReport::new("b", "Stage B", "paper §2");
        a.number(
            "collection",
            serde_json::json!({"samples": 3, "why": "<streak>"}),
        );
        a.number("runs", serde_json::json!([{"n": 1, "ok": true}, {"n": 2}]));
        let sizes = HashMap::from([("a.svg".to_string(), [240.0, 100.0])]);
        let page = render("demo", &[a, b], &sizes);
        assert!(page.contains(r#"<h2 id="a">Stage &lt;A&gt;</h2>"#));
        assert!(page.contains(r#"<h2 id="b">"#));
        // A small figure is shown larger (here 360 px high), in proportion.
        assert!(
            page.contains(r#"<img src="a.svg" width="864" height="360""#),
            "{page}"
        );
        assert_eq!(page.matches("class=\"failed\"").count(), 2);
        assert!(page.contains("<th>Cost</th><td>12</td>"));
        // No raw JSON: a record is a table in its cell, a list of records a table.
        assert!(!page.contains('{') || page.find('{') < page.find("</style>"));
        assert!(page.contains("<th>Samples</th><td>3</td>"));
        assert!(page.contains("<td>&lt;streak&gt;</td>"));
        assert!(page.contains("<tr><th>N</th><th>Ok</th></tr><tr><td>1</td><td>yes</td></tr><tr><td>2</td><td></td></tr>"), "{page}");
    }

    #[test]
    fn fields_read_as_labels_with_units_and_rounded_values() {
        assert_eq!(
            label("final_distance_m (camera)"),
            ("Final distance (camera)".into(), Unit::Metre)
        );
        assert_eq!(label("map_cpu_ms"), ("Map CPU".into(), Unit::Millisecond));
        assert_eq!(label("collected_now"), ("Collected now".into(), Unit::None));
        assert_eq!(label("s"), ("S".into(), Unit::Second));
        assert_eq!(quantity(0.0128, Unit::Metre), "12.8 mm");
        assert_eq!(quantity(52.7110, Unit::Millisecond), "52.71 ms");
        assert_eq!(quantity(1.5, Unit::Metre), "1.5 m");
        for (x, want) in [
            (0.0, "0"),
            (0.012345, "0.01235"),
            (1234.56, "1235"),
            (12345.6, "12346"),
            (-4.56789, "-4.568"),
            (9.99996, "10"),
            (-0.00001, "-0.00001"),
        ] {
            assert_eq!(significant(x), want, "{x}");
        }
        let mut a = StageReport::new("a", "A", "p");
        a.number("collected_now", true);
        a.number("final_distance_m (camera)", 0.0128);
        a.number("map_ms", 52.7110);
        let page = render("demo", &[a], &HashMap::new());
        assert!(
            page.contains("<th>Collected now</th><td>yes</td>"),
            "{page}"
        );
        assert!(page.contains("<th>Final distance (camera)</th><td>12.8 mm</td>"));
        assert!(page.contains("<th>Cost map built in</th><td>52.71 ms</td>"));
    }

    #[test]
    fn svg_size_reads_the_root_element() {
        assert_eq!(
            svg_size(r#"<svg font-family="x" height="90" viewBox="0 0 1 1" width="120.5">"#),
            Some([120.5, 90.0])
        );
        assert_eq!(svg_size("<svg>"), None);
        assert_eq!(svg_size("no svg"), None);
    }
}
