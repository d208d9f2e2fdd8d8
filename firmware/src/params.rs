//! The robot's settings: geometry, limits, gains, safety thresholds; the reference robot.

use pushbot_protocol::{FirmwareVersion, Geometry, WheelGains};

/// Motion limits of the body: speeds and accelerations.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Limits {
    /// Largest forward speed, m/s.
    pub max_speed: f32,
    /// Largest forward acceleration, m/s².
    pub max_accel: f32,
    /// Largest turn rate, rad/s.
    pub max_omega: f32,
    /// Largest angular acceleration, rad/s².
    pub max_alpha: f32,
}

/// Everything the core needs to know about its robot. `Default` is the reference robot
/// (N20 50:1 gear motors, 16 mm wheels, 70 mm wheel base, 1 kHz control).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RobotParams {
    /// Geometry, reported in the `HelloReply`.
    pub geometry: Geometry,
    /// Firmware version, reported in the `HelloReply`.
    pub firmware: FirmwareVersion,
    /// Motion limits in force at start-up (changeable with `Configure` within `hard_limits`).
    pub limits: Limits,
    /// Hard bounds: `Configure` may not set limits above these.
    pub hard_limits: Limits,
    /// Wheel-speed controller gains at start-up.
    pub gains: WheelGains,
    /// Largest gain `Configure` may set (each of kp, ki, kff).
    pub max_gain: f32,
    /// Link watchdog, ms of robot time (default 200).
    pub watchdog_ms: u16,
    /// Smallest watchdog `Configure` may set, ms.
    pub min_watchdog_ms: u16,
    /// Largest watchdog `Configure` may set, ms.
    pub max_watchdog_ms: u16,
    /// Telemetry rate, Hz (default 50; 0 = off).
    pub telemetry_hz: u16,
    /// Largest telemetry rate `Configure` may set, Hz.
    pub max_telemetry_hz: u16,
    /// Stall detection: |duty| at or above this counts as "driven hard".
    pub stall_duty: f32,
    /// Stall detection: measured |wheel speed| below this counts as "not turning", rad/s.
    pub stall_speed: f32,
    /// Stall detection: how long a wheel must be driven hard without turning, ms.
    pub stall_ms: u16,
    /// Bumper debounce: a switch change counts once it held this long, µs.
    pub debounce_us: u32,
    /// Largest plausible wheel speed, rad/s: a larger encoder step latches `ENCODER`.
    pub max_wheel_speed: f32,
    /// A primitive taking longer than `timeout_factor` × its planned time + `timeout_slack_ms`
    /// ends `Done(Timeout)`.
    pub timeout_factor: f32,
    /// See `timeout_factor`, ms.
    pub timeout_slack_ms: u32,
    /// Distance tolerance for the end of a move, m.
    pub distance_tolerance: f32,
    /// Angle tolerance for the end of a spin, rad.
    pub angle_tolerance: f32,
    /// After a profile has arrived, how long the wheels may take to come within the tolerance
    /// before the remainder is planned again, ms.
    pub settle_ms: u16,
    /// Largest |distance| of a `Move` or `AdvanceUntilContact`, m.
    pub max_distance: f32,
    /// Largest |angle| of a `Spin`, rad.
    pub max_angle: f32,
    /// `CONTROL_OVERRUN` latches when more than this many control periods pass between two
    /// steps while the motors are driven (default 3). A real board keeps its deadlines; an
    /// emulated one on a shared host cannot, and raises this.
    pub overrun_periods: u32,
}

impl Default for RobotParams {
    fn default() -> Self {
        // Feed-forward: the motor's no-load wheel speed is ≈ 32 rad/s at duty 1.
        let kff = 1.0 / 32.0;
        RobotParams {
            geometry: Geometry {
                wheel_base: 0.07,
                wheel_radius: 0.016,
                bumper_radius: 0.04,
                encoder_cpr: 1400,
                control_hz: 1000,
            },
            firmware: FirmwareVersion {
                major: 0,
                minor: 1,
                patch: 0,
            },
            limits: Limits {
                max_speed: 0.3,
                max_accel: 0.6,
                max_omega: 4.0,
                max_alpha: 12.0,
            },
            hard_limits: Limits {
                max_speed: 0.45,
                max_accel: 2.0,
                max_omega: 8.0,
                max_alpha: 40.0,
            },
            gains: WheelGains {
                kp: 0.05,
                ki: 0.8,
                kff,
            },
            max_gain: 10.0,
            watchdog_ms: 200,
            min_watchdog_ms: 20,
            max_watchdog_ms: 5000,
            telemetry_hz: 50,
            max_telemetry_hz: 200,
            stall_duty: 0.3,
            stall_speed: 1.0,
            stall_ms: 150,
            debounce_us: 5_000,
            max_wheel_speed: 100.0,
            timeout_factor: 3.0,
            timeout_slack_ms: 1_000,
            distance_tolerance: 0.002,
            angle_tolerance: 0.02,
            settle_ms: 200,
            max_distance: 10.0,
            max_angle: 4.0 * core::f32::consts::PI,
            overrun_periods: 3,
        }
    }
}

impl RobotParams {
    /// Control period, µs (`1e6 / control_hz`, at least 1).
    pub fn tick_period_us(&self) -> u32 {
        1_000_000 / u32::from(self.geometry.control_hz.max(1))
    }
}
