//! Two DC motors on a DRV8833-style dual H-bridge (two PWM inputs per motor, `xIN1`/`xIN2`).
//!
//! One RP2040 PWM slice per motor: channel A drives `IN1`, channel B `IN2`, at 20 kHz (above
//! hearing). Forward: `IN1` pulses, `IN2` low; reverse: the other way round; zero: both low
//! (coast). The bridge's `nSLEEP` is a GPIO held low until the control loop runs, so the
//! motors cannot move before the core commands them, and the pin returns to its reset state
//! (input; the DRV8833's own pull-down keeps the bridge asleep) if the watchdog resets the chip.

use embassy_rp::gpio::Output;
use embassy_rp::pwm::{Config, Pwm};

/// PWM frequency, Hz.
pub const PWM_HZ: u32 = 20_000;

/// One motor's bridge half-pair.
pub struct Motor<'d> {
    pwm: Pwm<'d>,
    config: Config,
    /// -1 for a motor mounted mirror-wise, so positive duty always drives the robot forward.
    sign: f32,
}

impl<'d> Motor<'d> {
    /// A motor on `pwm` (both channels set up as outputs), stopped.
    pub fn new(mut pwm: Pwm<'d>, sys_clk_hz: u32, sign: f32) -> Self {
        let mut config = Config::default();
        // (top + 1) × divider(1) = system clock / PWM frequency; ≤ 65535 for clocks ≤ 1.3 GHz.
        config.top = (sys_clk_hz / PWM_HZ)
            .saturating_sub(1)
            .min(u32::from(u16::MAX)) as u16;
        config.compare_a = 0;
        config.compare_b = 0;
        pwm.set_config(&config);
        Motor { pwm, config, sign }
    }

    /// Apply a signed duty in `-1..=1` (the shell has clamped it already).
    pub fn set(&mut self, duty: f32) {
        let d = duty * self.sign;
        // `top + 1` is fully on; the product is ≤ 65536 and the cast saturates.
        let full = f32::from(self.config.top) + 1.0;
        let compare = (d.abs() * full + 0.5) as u32;
        let compare = compare.min(u32::from(self.config.top) + 1) as u16;
        let (a, b) = if d > 0.0 {
            (compare, 0)
        } else if d < 0.0 {
            (0, compare)
        } else {
            (0, 0)
        };
        if (a, b) != (self.config.compare_a, self.config.compare_b) {
            self.config.compare_a = a;
            self.config.compare_b = b;
            // Compare registers are double-buffered: the change takes effect at the next wrap.
            self.pwm.set_config(&self.config);
        }
    }
}

/// Both motors and the bridge's sleep pin.
pub struct Drive<'d> {
    /// Left, right.
    pub motors: [Motor<'d>; 2],
    /// DRV8833 `nSLEEP`: high = bridge awake.
    pub enable: Output<'d>,
}

impl Drive<'_> {
    /// Apply duties [left, right]; the bridge is woken on the first call.
    pub fn set(&mut self, duty: [f32; 2]) {
        self.motors[0].set(duty[0]);
        self.motors[1].set(duty[1]);
        self.enable.set_high();
    }
}
