//! The robot's build as the world sees it: its body (wheel base, wheel radius, round bumper),
//! the optional flat front plate (Lynch & Mason's line-contact pusher, §2), and which bumper
//! switch closes where.

use serde::{Deserialize, Serialize};

use crate::geometry::{Outline, ShapeError};

/// Bumper switch bits, as the firmware reads them.
pub mod switch {
    /// Left switch.
    pub const LEFT: u8 = 1 << 0;
    /// Centre switch.
    pub const CENTRE: u8 = 1 << 1;
    /// Right switch.
    pub const RIGHT: u8 = 1 << 2;
}

/// The robot's body dimensions, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Distance between the wheel contact points.
    pub wheel_base: f64,
    /// Wheel radius.
    pub wheel_radius: f64,
    /// Bumper radius around the axle centre.
    pub bumper_radius: f64,
    /// A flat plate across the front, if fitted (default: the round bumper only).
    pub front_plate: Option<FrontPlate>,
}

/// A flat bumper plate across the robot's front: a straight plate `width` m wide,
/// perpendicular to the heading, its face `offset` m ahead of the wheel axis (centred on the
/// heading). The robot's outline is the round body plus the plate (a plate
/// [`FrontPlate::THICKNESS`] thick behind its face). Objects pushed flat against it touch it
/// along a line (line contact, Lynch & Mason §2). Its switches close by where it is pressed:
/// the right switch for presses on its right part (from the right end to `width/8` right of
/// centre), the centre switch within `width/4` of the centre, the left switch on its left part
/// (the zones overlap, like the round bumper's sectors); a flush press spanning the plate
/// closes all three.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrontPlate {
    /// Plate width, m.
    pub width: f64,
    /// Distance of the plate's face ahead of the wheel axis, m.
    pub offset: f64,
}

impl FrontPlate {
    /// Thickness of the plate behind its face, m.
    pub const THICKNESS: f64 = 0.004;

    /// The plate's outline in the robot frame (x ahead, y to the left).
    pub fn outline(&self) -> [[f64; 2]; 4] {
        let (h, f, b) = (self.width / 2.0, self.offset, self.offset - Self::THICKNESS);
        [[b, -h], [f, -h], [f, h], [b, h]]
    }

    /// Whether the plate is usable: finite, positive width, face ahead of the axis.
    pub fn valid(&self) -> bool {
        self.width.is_finite()
            && self.offset.is_finite()
            && self.width > 0.0
            && self.offset > Self::THICKNESS
    }

    /// The switches closed by presses spanning lateral positions `lo..=hi` (m, left positive).
    pub fn switches(&self, lo: f64, hi: f64) -> u8 {
        let w = self.width;
        let hit = |a: f64, b: f64| hi >= a && lo <= b;
        let mut bits = 0;
        if hit(-w / 4.0, w / 4.0) {
            bits |= switch::CENTRE;
        }
        if hit(w / 8.0, f64::INFINITY) {
            bits |= switch::LEFT;
        }
        if hit(f64::NEG_INFINITY, -w / 8.0) {
            bits |= switch::RIGHT;
        }
        bits
    }
}

impl Body {
    /// The robot's outline (robot frame): the round bumper, plus the plate if fitted.
    pub fn outline(&self) -> Result<Outline, ShapeError> {
        let disc = Outline::disc(self.bumper_radius);
        match self.front_plate {
            None => Ok(disc),
            Some(p) if p.valid() => disc.with_convex_part(&p.outline()),
            Some(_) => Err(ShapeError::Plate),
        }
    }
}
