//! The checks of the planners' sections, `[rearrange]` and `[stable]`, so that every command
//! that reads a scene (and `scene check`) refuses a bad value with its field's path, not only
//! the planner that reads it: ranges, positive sizes, known names, objects that exist.

use super::Scene;
use super::error::{Invalid, Seg, invalid};
use super::rearrange::Rearrange;
use super::stable::{Stable, StableCost};

/// A direction of the grid planner: `N`, `E`, `S` or `W` (either case).
fn is_dir(s: &str) -> bool {
    matches!(s.to_ascii_uppercase().as_str(), "N" | "E" | "S" | "W")
}

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

impl Scene {
    /// The `[rearrange]` and `[stable]` sections, if present.
    pub(super) fn check_sections(&self) -> Result<(), Invalid> {
        if let Some(r) = &self.rearrange {
            self.check_rearrange(r)?;
        }
        if let Some(s) = &self.stable {
            self.check_stable(s)?;
        }
        Ok(())
    }

    fn check_rearrange(&self, r: &Rearrange) -> Result<(), Invalid> {
        use Seg::{Index, Key};
        let at = |k| vec![Key("rearrange"), Key(k)];
        let c = r.cell;
        let (w, h) = (
            (self.table.width / c + 1e-6).floor(),
            (self.table.height / c + 1e-6).floor(),
        );
        if !(positive(c) && (1.0..=256.0).contains(&w) && (1.0..=256.0).contains(&h)) {
            return Err(invalid(
                at("cell"),
                format!("{c} m makes a grid of {w} × {h} cells; each side must be 1..=256"),
            ));
        }
        let size = match r.robot_size {
            Some(k) => f64::from(k),
            None => ((2.0 * self.robot.bumper_radius / c) - 1e-9)
                .ceil()
                .max(1.0),
        };
        if !(1.0..=8.0).contains(&size) {
            return Err(invalid(
                at("robot_size"),
                format!("a robot of {size} × {size} cells: must be 1..=8"),
            ));
        }
        if let Some([x, y]) = r.robot_goal
            && !(x.is_finite()
                && y.is_finite()
                && (0.0..=self.table.width).contains(&x)
                && (0.0..=self.table.height).contains(&y))
        {
            return Err(invalid(
                at("robot_goal"),
                format!("[{x}, {y}] m is not on the table"),
            ));
        }
        if !positive(r.kg_per_mass) {
            return Err(invalid(at("kg_per_mass"), "must be positive"));
        }
        if let Some(map) = &r.map {
            let rows: Vec<&str> = map
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .collect();
            if rows.len() != h as usize || rows.iter().any(|r| r.chars().count() != w as usize) {
                return Err(invalid(
                    at("map"),
                    format!(
                        "the map must have {h} rows of {w} cells (the table in cells of {c} m)"
                    ),
                ));
            }
            for (y, row) in rows.iter().enumerate() {
                if let Some((x, ch)) = row
                    .chars()
                    .enumerate()
                    .find(|(_, ch)| !".#,;x".contains(*ch))
                {
                    return Err(invalid(
                        at("map"),
                        format!(
                            "row {} column {}: unknown cell '{ch}' (use . # , ; x)",
                            y + 1,
                            x + 1
                        ),
                    ));
                }
            }
        }
        let rules = vec![Key("rearrange"), Key("rules"), Key("push_dirs")];
        if let Some(ch) = r
            .rules
            .push_dirs
            .chars()
            .find(|ch| !is_dir(&ch.to_string()))
        {
            return Err(invalid(rules, format!("'{ch}' is not one of N, E, S, W")));
        }
        if r.metric.rough.contains(&0) {
            return Err(invalid(
                vec![Key("rearrange"), Key("metric"), Key("rough")],
                "passability factors must be ≥ 1",
            ));
        }
        for (j, m) in r.movables.iter().enumerate() {
            let at = |k| vec![Key("rearrange"), Key("movable"), Index(j), Key(k)];
            if self.object(&m.object).is_none() {
                return Err(invalid(
                    at("object"),
                    format!("no object {:?} in the scene", m.object),
                ));
            }
            if r.movables[..j].iter().any(|o| o.object == m.object) {
                return Err(invalid(
                    at("object"),
                    format!("object {:?} already has a [[rearrange.movable]]", m.object),
                ));
            }
            if m.mass == Some(0) {
                return Err(invalid(at("mass"), "must be ≥ 1"));
            }
            for (k, p) in m.push.iter().enumerate() {
                if !is_dir(&p.dir) {
                    let mut path = at("push");
                    path.extend([Index(k), Key("dir")]);
                    return Err(invalid(
                        path,
                        format!("'{}' is not one of N, E, S, W", p.dir),
                    ));
                }
            }
            for (k, q) in m.rotate.iter().enumerate() {
                let mut path = at("rotate");
                path.push(Index(k));
                if !is_dir(&q.dir) {
                    path.push(Key("dir"));
                    return Err(invalid(
                        path,
                        format!("'{}' is not one of N, E, S, W", q.dir),
                    ));
                }
                if q.turn != "cw" && q.turn != "ccw" {
                    path.push(Key("turn"));
                    return Err(invalid(path, format!("'{}' is not cw or ccw", q.turn)));
                }
            }
        }
        Ok(())
    }

    fn check_stable(&self, s: &Stable) -> Result<(), Invalid> {
        use Seg::Key;
        let at = |k| vec![Key("stable"), Key(k)];
        let Some(obj) = self.object(&s.object) else {
            return Err(invalid(
                at("object"),
                format!("no object {:?} in the scene", s.object),
            ));
        };
        if !self.goals.iter().any(|g| g.object == s.object) {
            return Err(invalid(
                at("object"),
                format!("no goal for the stable object {:?} in [[goals]]", s.object),
            ));
        }
        let n = obj.outline.len();
        if s.edges.is_empty() {
            return Err(invalid(at("edges"), "at least one pushing edge is needed"));
        }
        if let Some(e) = s.edges.iter().find(|e| **e >= n) {
            return Err(invalid(
                at("edges"),
                format!("edge {e}: the object's outline has edges 0..={}", n - 1),
            ));
        }
        if let Some(e) = s.start_edge
            && !s.edges.contains(&e)
        {
            return Err(invalid(
                at("start_edge"),
                format!("edge {e} is not in stable.edges"),
            ));
        }
        for (k, v) in [
            ("goal_xy_frac", s.goal_xy_frac),
            ("goal_theta_deg", s.goal_theta_deg),
        ] {
            if !positive(v) {
                return Err(invalid(at(k), "must be finite and > 0"));
            }
        }
        let p = &s.planner;
        let pl = |k| vec![Key("stable"), Key("planner"), Key(k)];
        for (k, v) in [
            ("step_frac", p.step_frac),
            ("grid_xy_frac", p.grid_xy_frac),
            ("grid_theta_deg", p.grid_theta_deg),
            ("fine_factor", p.fine_factor),
        ] {
            if let Some(v) = v
                && !positive(v)
            {
                return Err(invalid(pl(k), format!("must be finite and > 0, got {v}")));
            }
        }
        if let Some(v) = p.fine_radius_frac
            && !(v.is_finite() && v >= 0.0)
        {
            return Err(invalid(
                pl("fine_radius_frac"),
                format!("must be finite and ≥ 0, got {v}"),
            ));
        }
        if let Some(StableCost::Word(w)) = &p.c
            && w != "inf"
        {
            return Err(invalid(
                pl("c"),
                format!("expected an integer or \"inf\", got {w:?}"),
            ));
        }
        if p.max_cost.is_some_and(|m| m > 1_000_000) {
            return Err(invalid(pl("max_cost"), "at most 1000000"));
        }
        let pu = |k| vec![Key("stable"), Key("pusher"), Key(k)];
        let u = &s.pusher;
        if !matches!(u.kind.as_str(), "arm" | "omni" | "car" | "diff-drive") {
            return Err(invalid(
                pu("kind"),
                format!("expected arm, omni, car or diff-drive, got {:?}", u.kind),
            ));
        }
        if u.kind == "car" && u.min_turning_radius.is_none() {
            return Err(invalid(pu("min_turning_radius"), "required for a car"));
        }
        for (k, v) in [
            ("width", u.width),
            ("depth", u.depth),
            ("axle_offset", u.axle_offset),
            ("plate_width", u.plate_width),
            ("min_turning_radius", u.min_turning_radius),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v >= 0.0)
            {
                return Err(invalid(pu(k), format!("must be finite and ≥ 0, got {v}")));
            }
        }
        Ok(())
    }
}
