//! What vision needs to know of a scene: the table's size, the calibration markers fixed at
//! known table positions, and which marker sits where on which body (robot, objects, goals), as
//! in Lau et al. §IV (markers on the robot, the object and the goal). Normally taken from the
//! shared scene format ([`MarkerLayout::from_scene`]); a stand-alone TOML/JSON layout file is
//! still accepted for cameras over tables that have no scene.

use std::path::Path;

use pushbot_world::camera::{MarkerFamily, MarkerPlacement};
use serde::{Deserialize, Serialize};

pub use pushbot_world::{Pose, wrap_angle};

/// A marker fixed on the table at a known place: used to calibrate the camera.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FixedMarker {
    /// Tag id.
    pub id: u32,
    /// Tag family (default tag36h11).
    #[serde(default)]
    pub family: MarkerFamily,
    /// Centre on the table, metres.
    pub centre: [f64; 2],
    /// Heading of the printed tag's +x axis, radians.
    #[serde(default)]
    pub heading: f64,
    /// Side of the black square, metres.
    pub side: f64,
}

impl FixedMarker {
    /// As a placement to render or to take corners from.
    pub fn placement(&self) -> MarkerPlacement {
        MarkerPlacement {
            id: self.id,
            family: self.family,
            centre: self.centre,
            heading: self.heading,
            side: self.side,
            height: 0.0,
        }
    }
}

/// A marker on a body: its tag and its pose in the body's frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyMarker {
    /// The body's name (`robot`, `object`, `goal`, …): the id tracking reports.
    pub body: String,
    /// Tag id.
    pub id: u32,
    /// Tag family (default tag36h11).
    #[serde(default)]
    pub family: MarkerFamily,
    /// Side of the black square, metres.
    pub side: f64,
    /// The marker's pose in the body frame `[x, y, θ]` (metres, radians).
    #[serde(default)]
    pub offset: [f64; 3],
    /// Height of the marker above the table, metres (the scene marker's `z`).
    #[serde(default)]
    pub height: f64,
    /// Fixed to the table (a goal's marker): once seen it is looked for only where it was,
    /// and a miss there means it is covered (the object over its goal), not that it moved.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub fixed: bool,
}

impl BodyMarker {
    /// The marker's pose in the body frame.
    pub fn offset_pose(&self) -> Pose {
        Pose::new(self.offset[0], self.offset[1], self.offset[2])
    }

    /// Where the marker is when the body is at `body`.
    pub fn placement(&self, body: &Pose) -> MarkerPlacement {
        let m = body.compose(&self.offset_pose());
        MarkerPlacement {
            id: self.id,
            family: self.family,
            centre: [m.x, m.y],
            heading: m.theta,
            side: self.side,
            height: self.height,
        }
    }

    /// The body's pose given its marker's pose.
    pub fn body_pose(&self, marker: &Pose) -> Pose {
        marker.compose(&self.offset_pose().inverse())
    }
}

/// What vision needs to know of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarkerLayout {
    /// Table size `[width, depth]`, metres; the table spans `[0, w] × [0, d]`.
    pub table: [f64; 2],
    /// Markers fixed on the table for calibration.
    #[serde(default)]
    pub calibration: Vec<FixedMarker>,
    /// Markers on bodies.
    #[serde(default)]
    pub bodies: Vec<BodyMarker>,
}

impl MarkerLayout {
    /// The built-in layout: a 1.2 m × 0.9 m table, six 5 cm calibration markers (ids 0–5) near
    /// its corners and long edges; the robot (id 10, marker at its centre), two objects (ids 11,
    /// 12, markers off their centres) and a goal (id 20). Markers are 5 × 5 cm as in Lau et al.
    pub fn default_table() -> MarkerLayout {
        let side = 0.05;
        let fixed = |id, x, y| FixedMarker {
            id,
            family: MarkerFamily::Tag36h11,
            centre: [x, y],
            heading: 0.0,
            side,
        };
        let body = |name: &str, id, offset: [f64; 3]| BodyMarker {
            body: name.into(),
            id,
            family: MarkerFamily::Tag36h11,
            side,
            offset,
            height: 0.0,
            fixed: false,
        };
        MarkerLayout {
            table: [1.2, 0.9],
            calibration: vec![
                fixed(0, 0.05, 0.05),
                fixed(1, 1.15, 0.05),
                fixed(2, 1.15, 0.85),
                fixed(3, 0.05, 0.85),
                fixed(4, 0.6, 0.05),
                fixed(5, 0.6, 0.85),
            ],
            bodies: vec![
                body("robot", 10, [0.0, 0.0, 0.0]),
                body("object", 11, [0.02, -0.01, 0.0]),
                body("object2", 12, [-0.03, 0.02, std::f64::consts::FRAC_PI_2]),
                body("goal", 20, [0.0, 0.0, 0.0]),
            ],
        }
    }

    /// The layout a scene describes: its table, its calibration markers (`[camera] fiducials`),
    /// the robot's marker (body `robot`), each object's marker (body = the object's id) and each
    /// goal's marker (body `goal:<object id>`, [`BodyMarker::fixed`]).
    pub fn from_scene(scene: &pushbot_world::Scene) -> MarkerLayout {
        let body = |name: String, m: &pushbot_world::scene::Marker| BodyMarker {
            body: name,
            id: m.id,
            family: MarkerFamily::Tag36h11,
            side: m.size,
            offset: [m.x, m.y, 0.0],
            height: m.z,
            fixed: false,
        };
        let mut bodies = vec![body("robot".into(), &scene.camera.robot_marker)];
        for o in &scene.objects {
            if let Some(m) = &o.marker {
                bodies.push(body(o.id.clone(), m));
            }
        }
        for g in &scene.goals {
            if let Some(m) = &g.marker {
                bodies.push(BodyMarker {
                    fixed: true,
                    ..body(format!("goal:{}", g.object), m)
                });
            }
        }
        MarkerLayout {
            table: [scene.table.width, scene.table.height],
            calibration: scene
                .fiducials()
                .iter()
                .map(|m| FixedMarker {
                    id: m.id,
                    family: MarkerFamily::Tag36h11,
                    centre: [m.x, m.y],
                    heading: 0.0,
                    side: m.size,
                })
                .collect(),
            bodies,
        }
    }

    /// Read a layout from a TOML or JSON file (by extension; TOML otherwise) and check it.
    pub fn load(path: &Path) -> Result<MarkerLayout, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let layout: MarkerLayout = if path.extension().is_some_and(|e| e == "json") {
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?
        } else {
            toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?
        };
        layout
            .validate()
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(layout)
    }

    /// Check sizes are positive and finite and that no (family, id) is used twice.
    pub fn validate(&self) -> Result<(), String> {
        if !self.table.iter().all(|v| v.is_finite() && *v > 0.0) {
            return Err(format!("table size {:?} must be positive", self.table));
        }
        let mut seen = std::collections::HashSet::new();
        let fixed = self.calibration.iter().map(|m| {
            (
                m.family,
                m.id,
                m.side,
                m.centre[0] + m.centre[1] + m.heading,
            )
        });
        let bodies = self
            .bodies
            .iter()
            .map(|b| (b.family, b.id, b.side, b.offset.iter().sum::<f64>()));
        for (family, id, side, sum) in fixed.chain(bodies) {
            if !(side.is_finite() && side > 0.0 && sum.is_finite()) {
                return Err(format!(
                    "marker {} {id}: side and positions must be finite, side positive",
                    family.name()
                ));
            }
            if !seen.insert((family, id)) {
                return Err(format!("marker {} {id} is used twice", family.name()));
            }
        }
        Ok(())
    }

    /// The body marker with this tag, if any.
    pub fn body_marker(&self, family: MarkerFamily, id: u32) -> Option<&BodyMarker> {
        self.bodies
            .iter()
            .find(|b| b.family == family && b.id == id)
    }

    /// The calibration marker with this tag, if any.
    pub fn fixed_marker(&self, family: MarkerFamily, id: u32) -> Option<&FixedMarker> {
        self.calibration
            .iter()
            .find(|b| b.family == family && b.id == id)
    }

    /// The families any marker uses.
    pub fn families(&self) -> Vec<MarkerFamily> {
        let mut f: Vec<MarkerFamily> = self
            .calibration
            .iter()
            .map(|m| m.family)
            .chain(self.bodies.iter().map(|b| b.family))
            .collect();
        f.sort_by_key(|f| f.name());
        f.dedup();
        if f.is_empty() {
            f.push(MarkerFamily::Tag36h11);
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn body_pose_inverts_placement() {
        let b = BodyMarker {
            body: "o".into(),
            id: 1,
            family: MarkerFamily::Tag36h11,
            side: 0.05,
            offset: [0.03, -0.02, 0.7],
            height: 0.0,
            fixed: false,
        };
        let body = Pose::new(0.4, 0.3, -2.9);
        let m = b.placement(&body);
        let back = b.body_pose(&Pose::new(m.centre[0], m.centre[1], m.heading));
        assert!((back.x - body.x).abs() < 1e-12 && (back.y - body.y).abs() < 1e-12);
        assert!(wrap_angle(back.theta - body.theta).abs() < 1e-12);
    }

    #[test]
    fn layout_round_trips_through_toml_and_rejects_duplicates() {
        let l = MarkerLayout::default_table();
        l.validate().unwrap();
        let text = toml::to_string(&l).unwrap();
        let back: MarkerLayout = toml::from_str(&text).unwrap();
        assert_eq!(back, l);
        let mut dup = l.clone();
        dup.bodies[1].id = 0;
        assert!(dup.validate().is_err());
    }
}
