//! The optional `[perturb]` section of a scene: how far the simulated world may differ from the
//! model the planner uses (Lynch & Mason §4 plan with nominal friction and a known
//! start, and their stable pushes promise only that the slider stays on the pusher). Ranges
//! only: `pushbot_sim::perturb` draws one world from them per trial; every field is optional
//! and defaults to the value shown.
//!
//! ```toml
//! [perturb]
//! start_theta_deg = 5.0     # the slider's (and the robot's on it) start heading, ± degrees
//! start_xy = 0.01           # its start position, ± m in x and in y
//! support_friction = 0.3    # slider–table friction, ± relative
//! pusher_friction = 0.3     # pusher–slider friction, ± relative
//! cof_offset = 0.005        # the centre of friction moved up to this far, m
//! wheel_slip = 0.005        # each wheel's rim speed off by up to ± this share, for the whole run
//! camera_xy = 0.001         # camera position noise, standard deviation, m
//! camera_theta_deg = 0.5    # camera heading noise, standard deviation, degrees
//! ```

use serde::{Deserialize, Serialize};

use super::Scene;
use super::error::{Invalid, Seg, invalid};

/// Ranges of the simulated world's differences from the planner's model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Perturb {
    /// Start heading error, ± degrees (uniform).
    pub start_theta_deg: f64,
    /// Start position error, ± m in x and in y (uniform).
    pub start_xy: f64,
    /// Slider–table friction error, ± relative (uniform).
    pub support_friction: f64,
    /// Pusher–slider friction error, ± relative (uniform).
    pub pusher_friction: f64,
    /// Largest offset of the slider's centre of friction, m (uniform in the disk).
    pub cof_offset: f64,
    /// Each wheel's systematic rim-speed error, ± share (uniform).
    pub wheel_slip: f64,
    /// Camera position noise, standard deviation, m.
    pub camera_xy: f64,
    /// Camera heading noise, standard deviation, degrees.
    pub camera_theta_deg: f64,
}

impl Default for Perturb {
    /// The default ranges: ±5°, ±10 mm, friction ±30 %, 5 mm centre of friction, ±0.5 % wheel
    /// slip, a camera with 1 mm and 0.5° of noise.
    fn default() -> Self {
        Perturb {
            start_theta_deg: 5.0,
            start_xy: 0.01,
            support_friction: 0.3,
            pusher_friction: 0.3,
            cof_offset: 0.005,
            wheel_slip: 0.005,
            camera_xy: 0.001,
            camera_theta_deg: 0.5,
        }
    }
}

impl Perturb {
    /// No difference at all: the world is the model, the camera exact.
    pub fn none() -> Self {
        Perturb {
            start_theta_deg: 0.0,
            start_xy: 0.0,
            support_friction: 0.0,
            pusher_friction: 0.0,
            cof_offset: 0.0,
            wheel_slip: 0.0,
            camera_xy: 0.0,
            camera_theta_deg: 0.0,
        }
    }

    /// Each field with its name and largest sensible value (inclusive).
    pub fn fields(&self) -> [(&'static str, f64, f64); 8] {
        [
            ("start_theta_deg", self.start_theta_deg, 45.0),
            ("start_xy", self.start_xy, 0.2),
            ("support_friction", self.support_friction, 0.9),
            ("pusher_friction", self.pusher_friction, 0.9),
            ("cof_offset", self.cof_offset, 0.1),
            ("wheel_slip", self.wheel_slip, 0.2),
            ("camera_xy", self.camera_xy, 0.05),
            ("camera_theta_deg", self.camera_theta_deg, 10.0),
        ]
    }
}

impl Scene {
    /// The `[perturb]` section, if present: every range finite, ≥ 0 and within its bound
    /// (friction errors below 100 %, so a friction stays positive).
    pub(super) fn check_perturb(&self) -> Result<(), Invalid> {
        let Some(p) = &self.perturb else {
            return Ok(());
        };
        for (k, v, max) in p.fields() {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(invalid(
                    vec![Seg::Key("perturb"), Seg::Key(k)],
                    format!("{v}: must be a number in 0..={max}"),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(section: &str) -> Result<Scene, crate::SceneError> {
        let mut t = crate::presets::text("fig15").expect("fig15");
        t.push_str(section);
        Scene::from_toml(&t, "perturbed.toml")
    }

    #[test]
    fn missing_fields_take_the_defaults_and_bad_ones_name_their_field() {
        let s = with("\n[perturb]\nstart_theta_deg = 2.0\n").unwrap();
        let p = s.perturb.unwrap();
        assert_eq!(p.start_theta_deg, 2.0);
        assert_eq!(p.pusher_friction, Perturb::default().pusher_friction);
        assert_eq!(with("").unwrap().perturb, None);
        for (bad, field) in [
            ("start_xy = -0.01", "perturb.start_xy"),
            ("support_friction = 1.0", "perturb.support_friction"),
            ("camera_xy = nan", "perturb.camera_xy"),
        ] {
            let e = with(&format!("\n[perturb]\n{bad}\n")).unwrap_err();
            assert_eq!(e.field.as_deref(), Some(field), "{e}");
        }
    }
}
