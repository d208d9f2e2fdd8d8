//! A brushed DC gear motor driving one wheel.
//!
//! The standard armature model with the inductance neglected (its time constant is far below the
//! 1 ms control period): the H-bridge turns the PWM duty `d` into an average armature voltage
//! `V = d·V_supply`, the current is `i = (V − k_e·ω)/R` (back-EMF `k_e·ω`), the torque at the
//! wheel is `k_t·i` with `k_t = k_e` (SI units, gearbox folded in), less viscous and Coulomb
//! friction. The speed then follows `J·dω/dt = τ_motor − τ_friction − τ_load`: a first-order
//! response towards the no-load speed `d·V_supply/k_e`, saturating at duty ±1.
//!
//! What the wheel is loaded with (the robot's body, or a wall that stops it) is the world's
//! business: [`Motor::drive_torque`] gives the motor's torque at a speed and
//! [`advance_with_friction`] integrates one step with stiction.

/// Electrical and mechanical constants of one motor + gearbox + wheel, referred to the wheel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorParams {
    /// Supply voltage at duty 1, V.
    pub supply_v: f64,
    /// Armature resistance (gearbox losses folded in), Ω.
    pub resistance_ohm: f64,
    /// Back-EMF constant at the wheel, V·s/rad; also the torque constant, N·m/A.
    pub ke: f64,
    /// Coulomb (dry) friction torque of motor and gearbox, N·m.
    pub coulomb_nm: f64,
    /// Viscous friction, N·m·s/rad.
    pub viscous: f64,
    /// Inertia of rotor, gearbox and wheel referred to the wheel, kg·m² (without the body).
    pub inertia: f64,
    /// PWM resolution: duty is quantised to this many steps per unit (0 = continuous).
    pub pwm_steps: u32,
}

impl Default for MotorParams {
    /// An N20 50:1 micro gear motor at 6 V: no-load ≈ 32 rad/s, stall torque ≈ 0.018 N·m.
    fn default() -> Self {
        let supply_v = 6.0;
        let ke = supply_v / 32.0;
        MotorParams {
            supply_v,
            // Stall torque ke·V/R = 0.018 N·m.
            resistance_ohm: ke * supply_v / 0.018,
            ke,
            coulomb_nm: 0.0006,
            viscous: 0.0,
            inertia: 1.2e-5,
            pwm_steps: 1000,
        }
    }
}

impl MotorParams {
    /// No-load wheel speed at duty 1 (friction neglected), rad/s.
    pub fn no_load_speed(&self) -> f64 {
        self.supply_v / self.ke
    }

    /// Torque at standstill and duty 1, N·m.
    pub fn stall_torque(&self) -> f64 {
        self.ke * self.supply_v / self.resistance_ohm
    }
}

/// One motor: its constants, a per-unit gain (manufacturing spread), its speed and angle.
#[derive(Clone, Debug)]
pub struct Motor {
    /// Constants.
    pub params: MotorParams,
    /// Multiplies the armature voltage: 1 for a nominal motor, e.g. 0.95 for a weak one.
    pub gain: f64,
    /// Wheel speed, rad/s (positive drives the robot forward).
    pub omega: f64,
    /// Cumulative wheel angle, rad (what the encoder measures).
    pub angle: f64,
}

impl Motor {
    /// A motor at rest.
    pub fn new(params: MotorParams, gain: f64) -> Self {
        Motor {
            params,
            gain,
            omega: 0.0,
            angle: 0.0,
        }
    }

    /// The duty the H-bridge actually applies: clamped to ±1 (saturation), NaN as 0, quantised
    /// to the PWM resolution.
    pub fn applied_duty(&self, duty: f32) -> f64 {
        let d = if duty.is_finite() {
            f64::from(duty).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        match self.params.pwm_steps {
            0 => d,
            n => (d * f64::from(n)).round() / f64::from(n),
        }
    }

    /// Motor torque at the wheel at speed `omega` under `duty`, before Coulomb friction, N·m.
    pub fn drive_torque(&self, duty: f32, omega: f64) -> f64 {
        let p = &self.params;
        let volts = self.applied_duty(duty) * p.supply_v * self.gain;
        let current = (volts - p.ke * omega) / p.resistance_ohm;
        p.ke * current - p.viscous * omega
    }

    /// Advance the angle by the current speed over `dt` seconds.
    pub fn integrate_angle(&mut self, dt: f64) {
        self.angle += self.omega * dt;
    }
}

/// One explicit step of `J·dω/dt = τ − friction` with Coulomb friction that sticks: a wheel at
/// rest stays at rest while `|τ| ≤ friction`, and a wheel slowing down stops at zero rather than
/// reversing within the step.
pub fn advance_with_friction(omega: f64, torque: f64, friction: f64, inertia: f64, dt: f64) -> f64 {
    const AT_REST: f64 = 1e-9;
    if omega.abs() < AT_REST {
        if torque.abs() <= friction {
            return 0.0;
        }
        return (torque - friction.copysign(torque)) / inertia * dt;
    }
    let next = omega + (torque - friction.copysign(omega)) / inertia * dt;
    if next.signum() != omega.signum() && torque.abs() <= friction {
        0.0
    } else {
        next
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free motor at duty 1 settles at its no-load speed less friction; exponentially.
    #[test]
    fn free_motor_settles_at_no_load_speed() {
        let mut m = Motor::new(MotorParams::default(), 1.0);
        let p = m.params;
        let dt = 1e-4;
        for _ in 0..20_000 {
            let tau = m.drive_torque(1.0, m.omega);
            m.omega = advance_with_friction(m.omega, tau, p.coulomb_nm, p.inertia, dt);
        }
        // Steady state: ke(V − ke ω)/R = coulomb.
        let expected = (p.supply_v - p.coulomb_nm * p.resistance_ohm / p.ke) / p.ke;
        assert!(
            (m.omega - expected).abs() < 1e-6,
            "{} vs {expected}",
            m.omega
        );
        assert!(m.omega < p.no_load_speed());
    }

    /// Below the friction torque the wheel does not start.
    #[test]
    fn stiction_holds_small_duty() {
        let m = Motor::new(MotorParams::default(), 1.0);
        let p = m.params;
        let d = (p.coulomb_nm / p.stall_torque() * 0.9) as f32;
        let tau = m.drive_torque(d, 0.0);
        assert_eq!(
            advance_with_friction(0.0, tau, p.coulomb_nm, p.inertia, 1e-3),
            0.0
        );
        let tau = m.drive_torque(d * 2.0, 0.0);
        assert!(advance_with_friction(0.0, tau, p.coulomb_nm, p.inertia, 1e-3) > 0.0);
    }

    /// Duty saturates at ±1 and a NaN duty is no drive.
    #[test]
    fn duty_saturates() {
        let m = Motor::new(MotorParams::default(), 1.0);
        assert_eq!(m.applied_duty(3.0), 1.0);
        assert_eq!(m.applied_duty(-3.0), -1.0);
        assert_eq!(m.applied_duty(f32::NAN), 0.0);
        assert_eq!(m.drive_torque(2.0, 0.0), m.drive_torque(1.0, 0.0));
    }
}
