//! SVG drawings of stable pushing plans in the manner of Lynch & Mason (1996) Figs. 13–18:
//! obstacles, the slider drawn along its path, the pusher at the start and at each contact
//! change, the goal, and (beyond the paper) the pusher's transit paths.

use std::fmt::Write;

use super::{Plan, Pose, Problem};
use crate::mechanics::V2;

fn poly(out: &mut String, pts: &[V2], h: f64, s: f64, style: &str) {
    let p: Vec<String> = pts
        .iter()
        .map(|v| format!("{:.2},{:.2}", v.x * s, (h - v.y) * s))
        .collect();
    let _ = writeln!(out, r#"<polygon points="{}" {style}/>"#, p.join(" "));
}

/// Render a plan (or just the problem if no plan) as an SVG document.
pub fn render(p: &Problem, plan: Option<&Plan>) -> String {
    let (w, h) = p.world.table;
    let s = 600.0 / w.max(h);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}" viewBox="0 0 {:.0} {:.0}">"#,
        w * s,
        h * s,
        w * s,
        h * s
    );
    let _ = writeln!(
        out,
        r#"<rect x="0" y="0" width="{:.1}" height="{:.1}" fill="white" stroke="black" stroke-width="2"/>"#,
        w * s,
        h * s
    );
    for o in &p.world.obstacles[p.world.n_walls..] {
        poly(
            &mut out,
            &o.vertices,
            h,
            s,
            r##"fill="#888" stroke="black""##,
        );
    }
    let at = |q: &Pose| -> Vec<V2> { p.slider.vertices.iter().map(|v| q.apply(*v)).collect() };
    poly(
        &mut out,
        &at(&p.goal),
        h,
        s,
        r##"fill="none" stroke="#c00" stroke-dasharray="4 3" stroke-width="2""##,
    );
    poly(
        &mut out,
        &at(&p.start),
        h,
        s,
        r##"fill="#cde" stroke="black" stroke-width="1.5""##,
    );
    if let Some(plan) = plan {
        let every = (plan.steps.len() / 40).max(1);
        let mut prev_contact = None;
        for (i, st) in plan.steps.iter().enumerate() {
            if i % every == 0 || i + 1 == plan.steps.len() {
                poly(
                    &mut out,
                    &at(&st.to),
                    h,
                    s,
                    r##"fill="none" stroke="#246" stroke-width="0.7""##,
                );
            }
            if prev_contact != Some(st.contact) {
                let fp = &p.contacts[st.contact].footprint;
                let c = &p.contacts[st.contact].placement.contact;
                let seg = [st.from.apply(c.a), st.from.apply(c.b)];
                let _ = writeln!(
                    out,
                    r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#e80" stroke-width="4"/>"##,
                    seg[0].x * s,
                    (h - seg[0].y) * s,
                    seg[1].x * s,
                    (h - seg[1].y) * s
                );
                if !fp.is_empty() {
                    let w: Vec<V2> = fp.iter().map(|v| st.from.apply(*v)).collect();
                    poly(
                        &mut out,
                        &w,
                        h,
                        s,
                        r##"fill="#fc8" fill-opacity="0.6" stroke="#a50""##,
                    );
                }
                prev_contact = Some(st.contact);
            }
        }
        let path: Vec<String> = std::iter::once(p.start)
            .chain(plan.steps.iter().map(|st| st.to))
            .map(|q| format!("{:.1},{:.1}", q.x * s, (h - q.y) * s))
            .collect();
        let _ = writeln!(
            out,
            r##"<polyline points="{}" fill="none" stroke="#06c" stroke-width="1.5"/>"##,
            path.join(" ")
        );
        for t in &plan.transits {
            let pts: Vec<String> = t
                .waypoints
                .iter()
                .map(|q| format!("{:.1},{:.1}", q[0] * s, (h - q[1]) * s))
                .collect();
            let _ = writeln!(
                out,
                r##"<polyline points="{}" fill="none" stroke="#a0a" stroke-dasharray="3 3" stroke-width="1.5"/>"##,
                pts.join(" ")
            );
        }
    }
    out.push_str("</svg>\n");
    out
}
