//! SVG drawings of stable pushing plans in the manner of Lynch & Mason (1996) Figs. 13–18:
//! obstacles, the slider drawn along its path, the pusher at the start and at each contact
//! change, the goal, and (beyond the paper) the pusher's transit paths; for a search that found
//! no plan, the tree it explored (group `explored`: one line per expanded configuration, from
//! its parent's centre to its own).

use super::{Plan, Pose, Problem};
use crate::mechanics::V2;
use crate::plot::svg::{Doc, Draw, Frame, Group, Style};

/// The longer table side in user units.
const SIDE: f64 = 600.0;
/// Room around the table for the axes in metres.
const AXES_MARGIN: f64 = 44.0;

/// Render a plan (or just the problem if no plan) as an SVG document.
pub fn render(p: &Problem, plan: Option<&Plan>) -> String {
    render_executed(p, plan, &[])
}

/// [`render`] with the slider's executed path (table m) drawn over the planned one, in green.
pub fn render_executed(p: &Problem, plan: Option<&Plan>, executed: &[[f64; 2]]) -> String {
    let (w, h) = p.world.table;
    let f = Frame::table(w, h, SIDE / w.max(h)).with_margin(AXES_MARGIN);
    let map = |pts: &[V2]| -> Vec<[f64; 2]> { pts.iter().map(|v| f.map([v.x, v.y])).collect() };
    let mut d = Doc::for_frame(&f);
    let (at, size) = f.area();
    d.rect(
        at,
        size,
        &Style::new().fill("white").stroke("black").width(2.0),
    );
    crate::plot::axes::metre_axes(&mut d, &f, [0.0, 0.0], [w, h]);
    for o in &p.world.obstacles[p.world.n_walls..] {
        d.polygon(
            &map(&o.vertices),
            &Style::new().fill("#888").stroke("black"),
        );
    }
    let slider = |q: &Pose| -> Vec<[f64; 2]> {
        let pts: Vec<V2> = p.slider.vertices.iter().map(|v| q.apply(*v)).collect();
        map(&pts)
    };
    d.polygon(&slider(&p.goal), &Style::outline("#c00", 2.0).dash("4 3"));
    d.polygon(
        &slider(&p.start),
        &Style::new().fill("#cde").stroke("black").width(1.5),
    );
    let Some(plan) = plan else {
        return d.to_string();
    };
    if !plan.found && !plan.search.tree.is_empty() {
        let mut g = Group::with_id("explored");
        let style = Style::outline("#7a9", 0.6).opacity(0.7);
        for [a, b] in &plan.search.tree {
            g.line(f.map([a.x, a.y]), f.map([b.x, b.y]), &style);
        }
        d.group(g);
        if let Some((q, _)) = plan.search.closest {
            d.polygon(&slider(&q), &Style::outline("#c60", 1.5));
        }
    }
    let every = (plan.steps.len() / 40).max(1);
    let mut prev_contact = None;
    for (i, st) in plan.steps.iter().enumerate() {
        if i % every == 0 || i + 1 == plan.steps.len() {
            d.polygon(&slider(&st.to), &Style::outline("#246", 0.7));
        }
        if prev_contact != Some(st.contact) {
            let fp = &p.contacts[st.contact].footprint;
            let c = &p.contacts[st.contact].placement.contact;
            let seg = map(&[st.from.apply(c.a), st.from.apply(c.b)]);
            d.line(seg[0], seg[1], &Style::new().stroke("#e80").width(4.0));
            if !fp.is_empty() {
                let w: Vec<V2> = fp.iter().map(|v| st.from.apply(*v)).collect();
                d.polygon(
                    &map(&w),
                    &Style::new().fill("#fc8").fill_opacity(0.6).stroke("#a50"),
                );
            }
            prev_contact = Some(st.contact);
        }
    }
    let path: Vec<[f64; 2]> = std::iter::once(p.start)
        .chain(plan.steps.iter().map(|st| st.to))
        .map(|q| f.map([q.x, q.y]))
        .collect();
    d.polyline(&path, &Style::outline("#06c", 1.5));
    for t in &plan.transits {
        d.polyline(
            &f.map_all(&t.waypoints),
            &Style::outline("#a0a", 1.5).dash("3 3"),
        );
    }
    if executed.len() > 1 {
        d.polyline(&f.map_all(executed), &Style::outline("#0a4", 2.0));
    }
    d.to_string()
}
