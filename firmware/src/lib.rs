//! The pushbot robot's firmware core: a sans-IO, `no_std` state machine.
//!
//! CONTRACT (shared with `sim-target` and the board binaries; extend, do not change):
//!
//! ```ignore
//! let mut core = Core::new(RobotParams::default());
//! loop {                                   // every core.tick_period_us() of robot time
//!     core.receive(now_us, &bytes_from_link);           // any time bytes arrive
//!     let out: Outputs = core.step(now_us, &Inputs { encoder: [l, r], bumper });
//!     motors.set(out.duty);                              // signed duty, -1..=1 per wheel
//!     let n = core.transmit(&mut tx_buf);                // bytes to send to the host
//!     link.write(&tx_buf[..n]);
//! }
//! ```
//!
//! * `Inputs::encoder` are cumulative quadrature counts per wheel [left, right], wrapping i32,
//!   positive when the wheel drives the robot forward.
//! * `Inputs::bumper` are the raw (undebounced) switch bits, bit 0 left, 1 centre, 2 right.
//! * `Outputs::duty` is the signed PWM duty per wheel [left, right] in -1.0..=1.0; 0 means
//!   motors off (coast/brake is the board's choice).
//! * Time is robot time in microseconds, monotonic, handed in by the caller: the core never
//!   reads a clock, so it runs identically on the board and at simulated time.
#![cfg_attr(not(test), no_std)]
