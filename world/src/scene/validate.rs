//! The checks a scene passes after its fields parse: values in range, polygons simple, goals
//! and positions on the table, markers drawable and unique; the geometric checks that need
//! shapes are in [`super::checks`].

use super::error::{Invalid, Seg, invalid, path_string};
use super::{Marker, Note, Scene, Support, placed, pose_finite};
use crate::simplify::{FINE_OUTLINE, OUTLINE_TOLERANCE, Simplified, simplify};

impl Scene {
    pub(super) fn check(&self) -> Result<(), Invalid> {
        use Seg::{Index, Key};
        let t = self.table;
        for (k, v) in [("width", t.width), ("height", t.height)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    vec![Key("table"), Key(k)],
                    "must be a positive length",
                ));
            }
        }
        let r = &self.robot;
        for (k, v) in [
            ("bumper_radius", r.bumper_radius),
            ("wheel_base", r.wheel_base),
            ("wheel_radius", r.wheel_radius),
            ("no_load_speed", r.no_load_speed),
            ("stall_torque", r.stall_torque),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(vec![Key("robot"), Key(k)], "must be positive"));
            }
        }
        if r.encoder_cpr == 0 {
            return Err(invalid(
                vec![Key("robot"), Key("encoder_cpr")],
                "must be positive",
            ));
        }
        let s = r.start;
        let rr = r.bumper_radius;
        if !(pose_finite(&s)
            && s.x >= rr
            && s.x <= t.width - rr
            && s.y >= rr
            && s.y <= t.height - rr)
        {
            return Err(invalid(
                vec![Key("robot"), Key("start")],
                format!("the robot (radius {rr} m) must start on the table"),
            ));
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            check_polygon(&o.outline)
                .map_err(|m| invalid(vec![Key("obstacles"), Index(i), Key("outline")], m))?;
        }
        for (i, o) in self.objects.iter().enumerate() {
            let at = |k| vec![Key("objects"), Index(i), Key(k)];
            if o.id.is_empty() {
                return Err(invalid(at("id"), "must not be empty"));
            }
            if self.objects[..i].iter().any(|p| p.id == o.id) {
                return Err(invalid(at("id"), format!("duplicate object id {:?}", o.id)));
            }
            check_polygon(&o.outline).map_err(|m| invalid(at("outline"), m))?;
            if !pose_finite(&o.pose) {
                return Err(invalid(at("pose"), "must be finite"));
            }
            for v in placed(&o.outline, &o.pose) {
                if !(v[0] >= 0.0 && v[0] <= t.width && v[1] >= 0.0 && v[1] <= t.height) {
                    return Err(invalid(at("pose"), "the object must lie on the table"));
                }
            }
            if !(o.mass.is_finite() && o.mass > 0.0) {
                return Err(invalid(at("mass"), "must be positive"));
            }
            for (k, v) in [
                ("support_friction", o.support_friction),
                ("pusher_friction", o.pusher_friction),
            ] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(invalid(at(k), "must be a friction coefficient ≥ 0"));
                }
            }
            if o.support_friction == 0.0 {
                return Err(invalid(
                    at("support_friction"),
                    "must be positive (a frictionless object never stops)",
                ));
            }
            if let Support::Points { points, weights } = &o.support {
                let sp = vec![Key("objects"), Index(i), Key("support")];
                if points.is_empty() {
                    return Err(invalid(sp, "needs at least one support point"));
                }
                if points.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(invalid(sp, "support points must be finite"));
                }
                if let Some(w) = weights {
                    if w.len() != points.len() {
                        return Err(invalid(sp, "needs one weight per support point"));
                    }
                    if w.iter().any(|x| !(x.is_finite() && *x >= 0.0))
                        || w.iter().sum::<f64>() <= 0.0
                    {
                        return Err(invalid(sp, "weights must be ≥ 0 and not all 0"));
                    }
                }
            }
            if let Some(m) = &o.marker {
                marker_ok(m).map_err(|e| invalid(at("marker"), e))?;
            }
        }
        for (i, g) in self.goals.iter().enumerate() {
            let at = |k| vec![Key("goals"), Index(i), Key(k)];
            if self.object(&g.object).is_none() {
                return Err(invalid(
                    at("object"),
                    format!("no object {:?} in the scene", g.object),
                ));
            }
            if !(pose_finite(&g.pose)
                && g.pose.x >= 0.0
                && g.pose.x <= t.width
                && g.pose.y >= 0.0
                && g.pose.y <= t.height)
            {
                return Err(invalid(at("pose"), "must be on the table"));
            }
            if !(g.tolerance.is_finite() && g.tolerance > 0.0) {
                return Err(invalid(at("tolerance"), "must be positive"));
            }
            if let Some(a) = g.angle_tolerance
                && !(a.is_finite() && a > 0.0)
            {
                return Err(invalid(at("angle_tolerance"), "must be positive"));
            }
        }
        self.check_markers()?;
        for (i, p) in self.positions.iter().enumerate() {
            if !pose_finite(&p.pose) {
                return Err(invalid(
                    vec![Key("positions"), Index(i), Key("pose")],
                    "must be finite",
                ));
            }
        }
        self.check_sections()?;
        self.check_perturb()
    }

    /// Store every outline counter-clockwise (reversed keeping vertex 0 first, so the shape is
    /// the same) and simplify every outline of more than [`FINE_OUTLINE`] vertices within
    /// [`OUTLINE_TOLERANCE`]; the stable task's edge numbers follow its object's outline.
    /// Returns what was changed.
    pub(super) fn normalise(&mut self) -> Vec<Note> {
        let mut notes = self.normalise_winding();
        notes.extend(self.simplify_fine_outlines());
        notes
    }

    fn simplify_fine_outlines(&mut self) -> Vec<Note> {
        let note = |field: String, n: usize, s: &Simplified, extra: &str| Note {
            field,
            message: format!(
                "has {n} vertices; simplified to {} within {:.3} mm{extra}",
                s.outline.len(),
                s.tolerance * 1e3
            ),
        };
        let mut notes = Vec::new();
        for (i, o) in self.obstacles.iter_mut().enumerate() {
            let n = o.outline.len();
            if n > FINE_OUTLINE
                && let Some(s) = simplify(&o.outline, OUTLINE_TOLERANCE)
            {
                notes.push(note(format!("obstacles[{i}].outline"), n, &s, ""));
                o.outline = s.outline;
            }
        }
        for (i, o) in self.objects.iter_mut().enumerate() {
            let n = o.outline.len();
            if n <= FINE_OUTLINE {
                continue;
            }
            let Some(s) = simplify(&o.outline, OUTLINE_TOLERANCE) else {
                continue;
            };
            let mut extra = "";
            if let Some(st) = self.stable.as_mut().filter(|st| st.object == o.id) {
                let mut edges: Vec<usize> = Vec::with_capacity(st.edges.len());
                for e in st.edges.iter().map(|e| s.edge_of(*e)) {
                    if !edges.contains(&e) {
                        edges.push(e);
                    }
                }
                st.edges = edges;
                st.start_edge = st.start_edge.map(|e| s.edge_of(e));
                extra = " (stable.edges renumbered to the simplified edges that hold them)";
            }
            notes.push(note(format!("objects[{i}].outline"), n, &s, extra));
            o.outline = s.outline;
        }
        notes
    }

    fn normalise_winding(&mut self) -> Vec<Note> {
        use crate::polygon::{normalise_ccw, reversed_edge};
        let note = |field: String, extra: &str| Note {
            field,
            message: format!("was clockwise; normalised to counter-clockwise{extra}"),
        };
        let mut notes = Vec::new();
        for (i, o) in self.obstacles.iter_mut().enumerate() {
            if normalise_ccw(&mut o.outline) {
                notes.push(note(format!("obstacles[{i}].outline"), ""));
            }
        }
        for (i, o) in self.objects.iter_mut().enumerate() {
            let n = o.outline.len();
            if !normalise_ccw(&mut o.outline) {
                continue;
            }
            let mut extra = "";
            if let Some(st) = self.stable.as_mut().filter(|st| st.object == o.id) {
                for e in st.edges.iter_mut().chain(st.start_edge.as_mut()) {
                    *e = reversed_edge(*e, n);
                }
                extra = " (edge i is now edge n − 1 − i: stable.edges renumbered)";
            }
            notes.push(note(format!("objects[{i}].outline"), extra));
        }
        notes
    }

    /// Every marker is drawable, calibration markers lie on the table, and no tag id is used
    /// twice (the camera could not tell the bodies apart).
    fn check_markers(&self) -> Result<(), Invalid> {
        use Seg::{Index, Key};
        let c = &self.camera;
        if c.width < 64 || c.height < 64 || c.width > 8192 || c.height > 8192 {
            return Err(invalid(
                vec![Key("camera"), Key("width")],
                "the image must be 64..=8192 pixels on each side",
            ));
        }
        if !(c.fps.is_finite() && c.fps > 0.0 && c.fps <= 1000.0) {
            return Err(invalid(
                vec![Key("camera"), Key("fps")],
                "must be a frame rate in (0, 1000]",
            ));
        }
        if let Some(super::IntrinsicsSpec::Inline(l)) = &c.intrinsics
            && let Some(p) = l.for_size(c.width, c.height).problem()
        {
            return Err(invalid(vec![Key("camera"), Key("intrinsics")], p));
        }
        if let Some(p) = c.pose.and_then(|p| p.problem()) {
            return Err(invalid(vec![Key("camera"), Key("pose")], p));
        }
        if !(c.exposure.is_finite() && (0.0..=1.0 / c.fps).contains(&c.exposure)) {
            return Err(invalid(
                vec![Key("camera"), Key("exposure")],
                format!(
                    "must be a time in seconds from 0 to the frame period ({:.4} s)",
                    1.0 / c.fps
                ),
            ));
        }
        for (i, o) in c.occluders.iter().enumerate() {
            let at = |k| vec![Key("camera"), Key("occluders"), Index(i), Key(k)];
            check_polygon(&o.outline).map_err(|m| invalid(at("outline"), m))?;
            if !(o.z.is_finite() && o.z >= 0.0) {
                return Err(invalid(at("z"), "must be a height of 0 m or more"));
            }
            if o.from.is_nan() || o.until.is_nan() || o.until < o.from {
                return Err(invalid(at("until"), "must not come before `from`"));
            }
        }
        let drawable = |m: &Marker| marker_ok(m).is_ok();
        let mut used: Vec<(u32, Vec<Seg>)> = Vec::new();
        let mut add = |id: u32, path: Vec<Seg>| -> Result<(), Invalid> {
            if id >= 587 {
                return Err(invalid(
                    path,
                    format!("tag id {id} is not in tag36h11 (0..=586)"),
                ));
            }
            if let Some((_, first)) = used.iter().find(|(u, _)| *u == id) {
                return Err(invalid(
                    path,
                    format!("tag id {id} is already used by {}", path_string(first)),
                ));
            }
            used.push((id, path));
            Ok(())
        };
        let rm = vec![Key("camera"), Key("robot_marker")];
        if let Err(e) = marker_ok(&c.robot_marker) {
            return Err(invalid(rm, e));
        }
        add(c.robot_marker.id, rm)?;
        for (i, o) in self.objects.iter().enumerate() {
            if let Some(m) = &o.marker {
                add(m.id, vec![Key("objects"), Index(i), Key("marker")])?;
            }
        }
        for (i, g) in self.goals.iter().enumerate() {
            if let Some(m) = &g.marker {
                let at = vec![Key("goals"), Index(i), Key("marker")];
                if let Err(e) = marker_ok(m) {
                    return Err(invalid(at, e));
                }
                add(m.id, at)?;
            }
        }
        let (w, h) = (self.table.width, self.table.height);
        for (i, m) in self.fiducials().iter().enumerate() {
            let at = vec![Key("camera"), Key("fiducials"), Index(i)];
            let half = m.size / 2.0;
            if !(drawable(m)
                && m.x - half >= 0.0
                && m.x + half <= w
                && m.y - half >= 0.0
                && m.y + half <= h)
            {
                return Err(invalid(at, "a calibration marker must lie on the table"));
            }
            add(m.id, at)?;
        }
        Ok(())
    }
}

/// A drawable marker: a finite centre, a positive size, a finite height `z` ≥ 0.
fn marker_ok(m: &Marker) -> Result<(), &'static str> {
    if !(m.x.is_finite() && m.y.is_finite() && m.size.is_finite() && m.size > 0.0) {
        return Err("needs a finite centre and a positive size");
    }
    if !(m.z.is_finite() && m.z >= 0.0) {
        return Err("z (its height above the table, m) must be finite and ≥ 0");
    }
    Ok(())
}

/// A usable polygon: ≥ 3 finite vertices, non-zero area, no zero-length edge, no edge
/// crossing another ([`crate::geometry::check_simple`]).
fn check_polygon(outline: &[[f64; 2]]) -> Result<(), String> {
    crate::geometry::check_simple(outline).map_err(|e| e.to_string())
}
