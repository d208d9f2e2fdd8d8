//! Lau, Mitani & Igarashi Fig. 11, as a table and as a figure: the success rate of delivery from
//! each start position (A–F, Fig. 10) for each object, the learned strategy ("ours") beside the
//! dipole field. The figure is laid out like the paper's: one panel per object, the starts
//! along the bottom, a bar per method.

use std::fmt::Write;

use super::strategy_eval::{Method, SceneEval};
use crate::plot::svg::{Doc, Draw, Group, Style};

/// The paper's name of a method's column.
fn column(m: Method) -> &'static str {
    match m {
        Method::Learned => "ours",
        Method::Dipole => "dipole",
    }
}

/// A scene's name without the `lau-` prefix.
fn short(s: &str) -> &str {
    s.strip_prefix("lau-").unwrap_or(s)
}

/// The table of Fig. 11: success % per start (rows) and scene × method (columns).
pub fn fig11_table(evals: &[SceneEval], starts: &[String], methods: &[Method]) -> String {
    let mut t = String::new();
    let _ = write!(t, "{:<6}", "start");
    for e in evals {
        let w = 9 * methods.len();
        let _ = write!(t, "| {:<w$}", short(&e.scene));
    }
    t.push('\n');
    let _ = write!(t, "{:<6}", "");
    for _ in evals {
        t.push_str("| ");
        for m in methods {
            let _ = write!(t, "{:<9}", column(*m));
        }
    }
    t.push('\n');
    for s in starts {
        let _ = write!(t, "{s:<6}");
        for e in evals {
            t.push_str("| ");
            for m in methods {
                let cell = rate(e, s, *m).map_or("-".to_owned(), |r| format!("{r:.0}"));
                let _ = write!(t, "{cell:<9}");
            }
        }
        t.push('\n');
    }
    t
}

/// Success % of `method` from `start` in `e`, if it ran.
fn rate(e: &SceneEval, start: &str, method: Method) -> Option<f64> {
    e.results
        .iter()
        .find(|r| r.start == start && r.method == method)
        .map(|r| r.success_rate)
}

/// Panel size and layout, pixels.
const PANEL: [f64; 2] = [300.0, 190.0];
const PLOT: [f64; 2] = [240.0, 120.0];
const PLOT_AT: [f64; 2] = [44.0, 34.0];
const COLUMNS: usize = 3;

/// The figure of Fig. 11: one panel per scene (three to a row), success % (0–100) of each
/// method from each start as bars, the learned strategy dark and the dipole field light, with
/// the trials per bar and the camera named in the caption.
pub fn fig11_svg(
    evals: &[SceneEval],
    starts: &[String],
    methods: &[Method],
    caption: &str,
) -> String {
    let rows = evals.len().div_ceil(COLUMNS).max(1);
    let cols = evals.len().clamp(1, COLUMNS);
    let (w, h) = (PANEL[0] * cols as f64, PANEL[1] * rows as f64 + 60.0);
    let mut d = Doc::new(w, h);
    d.title("Lau, Mitani & Igarashi Fig. 11: success rate of delivery per start");
    d.background(&Style::new().fill("white"));
    let fill = |m: Method| match m {
        Method::Learned => "#2b5d9b",
        Method::Dipole => "#b9c9dd",
    };
    for (k, e) in evals.iter().enumerate() {
        let (r, c) = (k / COLUMNS, k % COLUMNS);
        let mut g = Group::translated(c as f64 * PANEL[0], r as f64 * PANEL[1]);
        let [x0, y0] = PLOT_AT;
        let [pw, ph] = PLOT;
        g.text(
            [x0 + pw / 2.0, 20.0],
            &format!("{} ({} samples)", short(&e.scene), e.samples),
            &Style::new().font_size(13.0).anchor("middle"),
        );
        for pct in [0.0, 50.0, 100.0] {
            let y = y0 + ph * (1.0 - pct / 100.0);
            g.line([x0, y], [x0 + pw, y], &Style::outline("#ddd", 1.0));
            g.text(
                [x0 - 6.0, y + 4.0],
                &format!("{pct:.0}"),
                &Style::new().font_size(10.0).anchor("end"),
            );
        }
        let slot = pw / starts.len().max(1) as f64;
        let bar = slot * 0.8 / methods.len().max(1) as f64;
        for (i, s) in starts.iter().enumerate() {
            let sx = x0 + i as f64 * slot + slot * 0.1;
            for (j, m) in methods.iter().enumerate() {
                let Some(pct) = rate(e, s, *m) else { continue };
                // A 0 % bar is a 1-unit line, so the cell is seen to have been run (and has its tip).
                let bh = (ph * pct.clamp(0.0, 100.0) / 100.0).max(1.0);
                g.rect(
                    [sx + j as f64 * bar, y0 + ph - bh],
                    [bar * 0.92, bh],
                    &Style::new()
                        .fill(fill(*m))
                        .tip(&format!("{s} {}: {pct:.0} %", column(*m))),
                );
            }
            g.text(
                [x0 + i as f64 * slot + slot / 2.0, y0 + ph + 14.0],
                s,
                &Style::new().font_size(11.0).anchor("middle"),
            );
        }
        g.line(
            [x0, y0 + ph],
            [x0 + pw, y0 + ph],
            &Style::outline("black", 1.0),
        );
        g.line([x0, y0], [x0, y0 + ph], &Style::outline("black", 1.0));
        d.group(g);
    }
    let ly = PANEL[1] * rows as f64 + 18.0;
    for (j, m) in methods.iter().enumerate() {
        let x = 20.0 + j as f64 * 110.0;
        d.rect([x, ly - 10.0], [14.0, 12.0], &Style::new().fill(fill(*m)));
        d.text([x + 20.0, ly], column(*m), &Style::new().font_size(12.0));
    }
    d.text(
        [20.0, ly + 24.0],
        caption,
        &Style::new().font_size(11.0).fill("#444"),
    );
    d.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::trials::StartResult;

    fn result(start: &str, method: Method, successes: usize) -> StartResult {
        StartResult {
            start: start.into(),
            method,
            trials: 4,
            successes,
            success_rate: 25.0 * successes as f64,
            mean_time_s: None,
            mean_object_path_m: None,
            mean_robot_path_m: None,
            mean_path_ratio: None,
            max_path_ratio: None,
            path_ratios: Vec::new(),
            failures: Default::default(),
            stall_recoveries: 0,
            silent_timeouts: 0,
        }
    }

    /// One bar per start and method with its height the success rate, and a table cell each.
    #[test]
    fn bars_and_cells_follow_the_results() {
        let starts: Vec<String> = vec!["A".into(), "B".into()];
        let methods = [Method::Dipole, Method::Learned];
        let evals = vec![SceneEval {
            scene: "lau-snake".into(),
            samples: 120,
            collection: None,
            results: vec![
                result("A", Method::Dipole, 1),
                result("A", Method::Learned, 4),
                result("B", Method::Dipole, 0),
                result("B", Method::Learned, 3),
            ],
        }];
        let svg = fig11_svg(&evals, &starts, &methods, "4 trials");
        assert_eq!(
            svg.matches("<rect").count(),
            1 + 4 + 2,
            "background, bars, legend"
        );
        let full = format!("height=\"{}\"", PLOT[1]);
        assert_eq!(svg.matches(&full).count(), 1, "one bar at 100 %: {svg}");
        assert!(svg.contains("B ours: 75 %") && svg.contains("snake (120 samples)"));
        // A cell with no success is still drawn (a 1-unit bar with its tip), never a rectangle
        // without height, which renderers reject.
        assert!(
            svg.contains("height=\"1\"") && svg.contains("B dipole: 0 %"),
            "{svg}"
        );
        assert!(!svg.contains("height=\"0\""), "{svg}");
        let table = fig11_table(&evals, &starts, &methods);
        let rows: Vec<&str> = table.lines().collect();
        assert_eq!(rows.len(), 4);
        assert!(rows[2].contains("25") && rows[2].contains("100"), "{table}");
        assert!(rows[3].contains(" 0") && rows[3].contains("75"), "{table}");
    }
}
