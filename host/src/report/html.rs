//! `report.html`: one self-contained page per run — a section per stage with its outcome, its
//! numbers as a table, its figures and its notes.

use std::fmt::Write;

use super::StageReport;

/// Escape text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page.
pub fn render(title: &str, stages: &[StageReport]) -> String {
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
td, th {{ border: 1px solid #ddd; padding: .25em .6em; text-align: left; }}
figure {{ display: inline-block; margin: .5em; vertical-align: top; }}
figure img {{ max-width: 520px; border: 1px solid #ddd; }}
figcaption {{ font-size: .9em; color: #555; max-width: 520px; }}
</style></head><body>
<h1>{t}</h1>
<table><tr><th>stage</th><th>paper</th><th>result</th><th>wall s</th><th>mission s</th></tr>
"#,
        t = escape(title)
    );
    for s in stages {
        let _ = writeln!(
            h,
            r##"<tr><td><a href="#{id}">{title}</a></td><td>{paper}</td><td class="{c}">{r}</td><td>{w:.1}</td><td>{rt:.1}</td></tr>"##,
            id = escape(&s.id),
            title = escape(&s.title),
            paper = escape(&s.paper),
            c = if s.success { "ok" } else { "failed" },
            r = if s.success { "reached" } else { "failed" },
            w = s.wall_s,
            rt = s.mission_s,
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
                let v = match v {
                    serde_json::Value::Number(n) => match n.as_f64() {
                        Some(x) if n.is_f64() => format!("{x:.4}"),
                        _ => n.to_string(),
                    },
                    serde_json::Value::String(t) => t.clone(),
                    other => other.to_string(),
                };
                let _ = writeln!(h, "<tr><th>{}</th><td>{}</td></tr>", escape(k), escape(&v));
            }
            h.push_str("</table>\n");
        }
        for (file, caption) in &s.figures {
            let _ = writeln!(
                h,
                r#"<figure><a href="{f}"><img src="{f}" alt="{c}"></a><figcaption>{c}</figcaption></figure>"#,
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
        let page = render("demo", &[a, b]);
        assert!(page.contains(r#"<h2 id="a">Stage &lt;A&gt;</h2>"#));
        assert!(page.contains(r#"<h2 id="b">"#));
        assert!(page.contains(r#"<img src="a.svg""#));
        assert_eq!(page.matches("class=\"failed\"").count(), 2);
        assert!(page.contains("<th>cost</th><td>12</td>"));
    }
}
