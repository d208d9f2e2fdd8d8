//! The board shell: the embassy side of the sans-IO contract of `pushbot_firmware`.
//!
//! Every board runs this same module (the QEMU board includes this file by path), so the only
//! board-specific code is the hardware layer behind [`Hardware`] and the tasks that move bytes
//! between the link and [`LINK_RX`] / [`LINK_TX`]. All control and safety logic (wheel control,
//! primitives, odometry, debouncing, link watchdog, stall detection, faults) is the core's:
//! the same code the sim-target runs.
//!
//! Data flow, one control period (`Core::tick_period_us`, on an `embassy-time` [`Ticker`]):
//!
//! ```text
//! link rx task ──LINK_RX──▶ core.receive(now)      bumper edge task ──BUMPER──▶ Inputs
//! Hardware::encoders() ──▶ Inputs ──▶ core.step(now) ──▶ Hardware::drive(duty)
//! core.transmit() ──LINK_TX──▶ link tx task;  Hardware::feed_watchdog()
//! ```

use core::sync::atomic::{AtomicU8, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::pipe::Pipe;
use embassy_time::{Duration, Instant, Ticker};
use pushbot_firmware::{Core, Inputs, RobotParams};

/// Capacity of the receive pipe, bytes: several maximal frames.
pub const RX_CAPACITY: usize = 512;
/// Capacity of the transmit pipe, bytes.
pub const TX_CAPACITY: usize = 1024;

/// Bytes received from the host, not yet handed to the core. Written by the board's link
/// receive task or interrupt; bytes that do not fit are dropped (the frame CRC then rejects
/// the damaged frame and the host retries).
pub static LINK_RX: Pipe<CriticalSectionRawMutex, RX_CAPACITY> = Pipe::new();
/// Bytes the core produced for the host, not yet sent. Read by the board's link transmit task.
pub static LINK_TX: Pipe<CriticalSectionRawMutex, TX_CAPACITY> = Pipe::new();
/// Raw bumper switch bits (bit 0 left, 1 centre, 2 right), set by the board's edge task.
/// Only loads and stores: no compare-and-swap, so it works on `thumbv6m` as it is.
pub static BUMPER: AtomicU8 = AtomicU8::new(0);

/// What the shell needs from a board's hardware layer.
pub trait Hardware {
    /// Cumulative quadrature counts [left, right], wrapping, positive when the wheel drives the
    /// robot forward.
    fn encoders(&mut self) -> [i32; 2];
    /// Apply signed duties [left, right] in `-1..=1` to the H-bridge (0: motors off).
    fn drive(&mut self, duty: [f32; 2]);
    /// Cut the motors at once (used before the first step).
    fn motors_off(&mut self) {
        self.drive([0.0, 0.0]);
    }
    /// Feed the hardware watchdog: called once per control period.
    fn feed_watchdog(&mut self);
}

/// Write as much of `bytes` as the pipe has room for, without waiting; returns how many were
/// written. (`Pipe::try_write` stops at the end of its ring buffer, so one call may take only
/// part of what fits.)
pub fn try_write_all<const N: usize>(
    pipe: &Pipe<CriticalSectionRawMutex, N>,
    bytes: &[u8],
) -> usize {
    let mut done = 0;
    while done < bytes.len() {
        match pipe.try_write(&bytes[done..]) {
            Ok(k) => done += k,
            Err(_) => break,
        }
    }
    done
}

/// A duty made safe for a PWM compare value: non-finite becomes 0, the rest is clamped to
/// `-1..=1`. The core already bounds its outputs; this only keeps a bad float away from the
/// bridge.
pub fn sanitize_duty(d: f32) -> f32 {
    if d.is_finite() {
        d.clamp(-1.0, 1.0)
    } else {
        0.0
    }
}

/// Run the robot built as `params` says: the control loop at the core's rate, forever.
pub async fn control_loop<H: Hardware>(mut hw: H, params: RobotParams) -> ! {
    hw.motors_off();
    let mut core = Core::new(params);
    let period_us = u64::from(core.tick_period_us().max(1));
    defmt::info!("control loop: period {} us", period_us);
    let mut ticker = Ticker::every(Duration::from_micros(period_us));
    let mut rx = [0u8; 64];
    let mut tx = [0u8; 128];
    let mut shown = (core.mode(), core.faults());
    loop {
        ticker.next().await;
        let now_us = Instant::now().as_micros();
        while let Ok(n) = LINK_RX.try_read(&mut rx) {
            core.receive(now_us, &rx[..n]);
        }
        let inputs = Inputs {
            encoder: hw.encoders(),
            bumper: BUMPER.load(Ordering::Relaxed),
        };
        let out = core.step(now_us, &inputs);
        hw.drive([sanitize_duty(out.duty[0]), sanitize_duty(out.duty[1])]);
        // Hand over only what the pipe can take now: nothing the core queued is ever lost.
        loop {
            let room = LINK_TX.free_capacity().min(tx.len());
            if room == 0 {
                break;
            }
            let n = core.transmit(&mut tx[..room]);
            if n == 0 {
                break;
            }
            // All of it fits: `n <= room` and only this task writes to the pipe.
            try_write_all(&LINK_TX, &tx[..n]);
        }
        hw.feed_watchdog();
        let state = (core.mode(), core.faults());
        if state != shown {
            defmt::info!("mode {} faults {}", state.0, state.1);
            shown = state;
        }
    }
}
