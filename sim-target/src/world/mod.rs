//! The world: a robot on a table bounded by walls, with static obstacles and objects to push.
//!
//! Each step the motors drive the wheels as if they rolled (the wheels carry the body's mass)
//! and the body would move along the arc of the resulting twist. Then every contact acts at
//! once ([`crate::quasistatic`]): the robot pushes objects quasi-statically (the ellipsoidal
//! limit surface of Lynch & Mason §3), objects push each other and rest against walls and
//! obstacles, and the robot's motion is cut back to what the world makes room for, so nothing
//! interpenetrates beyond the step's linearised rotation (a corner at radius r turning by dθ
//! in one step may overshoot by r·dθ²/2, under a micrometre here). Shapes and contact points
//! come from `parry2d` ([`crate::geometry`]).
//! A wheel whose rolling speed no longer matches the body's motion is held by its traction: it
//! stalls (turns with the body) while the motor torque needed to hold it is within traction,
//! and otherwise slips, spinning on the table against kinetic friction. A bumper switch closes
//! while something presses on the bumper within its sector: on the round bumper by the angle
//! of the press, on a flat front plate ([`FrontPlate`]) by where along the plate it presses.
//!
//! The parts: this file holds the [`World`] and its [`Hardware`]; `build` sets a world up
//! (table, walls, obstacles, objects), `state` reads it, `step` advances it.

mod build;
mod state;
mod step;

use rand_chacha::ChaCha8Rng;

use crate::geometry::{ContactPoint, Outline};
use crate::motor::{Motor, MotorParams};
use crate::pushing::Slider;
use crate::quasistatic::BodyRef;
use crate::robot::Pose;

/// Standard gravity, m/s².
const G: f64 = 9.81;

pub use pushbot_world::body::{Body, FrontPlate};

/// The robot's body dimensions in a firmware geometry (no front plate).
pub fn body_from_geometry(g: &pushbot_protocol::Geometry) -> Body {
    Body {
        wheel_base: f64::from(g.wheel_base),
        wheel_radius: f64::from(g.wheel_radius),
        bumper_radius: f64::from(g.bumper_radius),
        front_plate: None,
    }
}

/// Coulomb coefficient between two objects.
pub const OBJECT_FRICTION: f64 = 0.3;
/// Coulomb coefficient between an object and a wall or obstacle.
pub const WALL_FRICTION: f64 = 0.2;
/// Support-friction load `μ_s·m·g` (N) of objects added without one ([`World::add_object`]).
pub const DEFAULT_LOAD: f64 = 0.7;

/// The physical model's constants and noise levels (all noise is drawn from the seed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hardware {
    /// The nominal motor.
    pub motor: MotorParams,
    /// Each motor's gain is drawn uniformly from `1 ± motor_gain_spread`.
    pub motor_gain_spread: f64,
    /// Robot mass, kg.
    pub mass_kg: f64,
    /// Share of the weight on each drive wheel (the rest is on the caster).
    pub drive_wheel_load: f64,
    /// Static wheel–table friction coefficient (kinetic is 90 % of it).
    pub traction_mu: f64,
    /// Each step each wheel's rim speed over the ground is off by a relative error drawn
    /// uniformly from ±`slip_noise` (small random slip that averages out).
    pub slip_noise: f64,
    /// Each wheel's systematic rim-speed error over the ground (share; left, right): a slip
    /// the encoders cannot see, which makes the robot veer (perturbed worlds).
    pub wheel_slip: [f64; 2],
    /// Probability that one encoder reading is off by ±1 count.
    pub encoder_jitter: f64,
    /// Longest bumper-switch bounce after a change, µs.
    pub bounce_us: u64,
}

impl Default for Hardware {
    fn default() -> Self {
        Hardware {
            motor: MotorParams::default(),
            motor_gain_spread: 0.05,
            mass_kg: 0.25,
            drive_wheel_load: 0.4,
            traction_mu: 1.0,
            slip_noise: 0.01,
            wheel_slip: [0.0; 2],
            encoder_jitter: 1e-4,
            bounce_us: 2_000,
        }
    }
}

/// A wall: the robot's centre `c` must keep `normal·c ≤ limit` (normal of unit length, pointing
/// from the robot into the wall).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Wall {
    normal: (f64, f64),
    limit: f64,
}

/// A robot on a walled table.
#[derive(Clone, Debug)]
pub struct World {
    table: (f64, f64),
    walls: Vec<Wall>,
    body: Body,
    hw: Hardware,
    pose: Pose,
    motors: [Motor; 2],
    slipping: [bool; 2],
    pressed: u8,
    rng: ChaCha8Rng,
    obstacles: Vec<Vec<[f64; 2]>>,
    objects: Vec<(String, Slider)>,
    /// The robot's outline, robot frame.
    shape: Outline,
    /// Walls (half-planes beyond the table's edges) and obstacles: outline, pose, bounding box.
    statics: Vec<(Outline, Pose, [f64; 4])>,
    /// Each object's outline (object frame) and support-friction load μ_s·m·g, N.
    object_shapes: Vec<(Outline, f64)>,
    /// Scratch: contacts of the step.
    contacts: Vec<ContactPoint>,
    /// The last step's rows (bodies of each) and solution, to warm-start the next solve.
    last: (
        Vec<(BodyRef, BodyRef)>,
        Option<crate::quasistatic::Solution>,
    ),
}

/// Whether two simple polygons (table frame) overlap by more than a touch (more than 1 nm;
/// parry2d contacts between their convex parts). Unusable polygons count as overlapping
/// nothing.
pub fn polygons_overlap(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    match (Outline::polygon(a), Outline::polygon(b)) {
        (Ok(a), Ok(b)) => a.overlaps(&Pose::default(), &b, &Pose::default(), 1e-9),
        _ => false,
    }
}

#[cfg(test)]
mod reference_robot {
    /// The scene format's default robot (in `pushbot-world`, which knows neither the firmware
    /// nor the motor model) is the firmware's reference geometry with the default motor.
    #[test]
    fn scene_default_robot_is_the_firmware_and_motor_default() {
        let spec = crate::scene::RobotSpec::default();
        let g = pushbot_firmware::RobotParams::default().geometry;
        let m = crate::motor::MotorParams::default();
        assert_eq!(spec.bumper_radius, f64::from(g.bumper_radius));
        assert_eq!(spec.wheel_base, f64::from(g.wheel_base));
        assert_eq!(spec.wheel_radius, f64::from(g.wheel_radius));
        assert_eq!(spec.encoder_cpr, g.encoder_cpr);
        assert_eq!(spec.no_load_speed, m.no_load_speed());
        assert_eq!(spec.stall_torque, m.stall_torque());
    }
}
