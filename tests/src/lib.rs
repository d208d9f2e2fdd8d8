//! Hardware-in-the-loop tests live in `tests/`: the real host link ([`pushbot::link`]) against
//! the simulated robot ([`pushbot_sim::PtySim`]) over a real pseudo-terminal, judged by the
//! simulator's ground truth. This library holds their shared set-up.

use std::time::{Duration, Instant};

use pushbot::link::{LinkOptions, Robot};
use pushbot_sim::{PtySim, SimOptions, Truth};

/// Pace of the simulated robot in the HIL tests: five times real time, so the host's
/// robot-time heartbeat pacing is exercised and the tests stay short.
pub const SIM_SPEED: f64 = 5.0;

/// A simulated robot at `(x, y, θ)` on the default 1.2 m × 0.9 m table, served on a pty.
pub fn sim_at(seed: u64, x: f64, y: f64, theta: f64) -> PtySim {
    PtySim::start(SimOptions {
        seed,
        speed: SIM_SPEED,
        start: pushbot_sim::Pose::new(x, y, theta),
        ..SimOptions::default()
    })
    .expect("start the simulated robot")
}

/// Connect the host link to the simulated robot, through its pty path like to hardware.
pub fn connect(sim: &PtySim) -> Robot {
    Robot::connect(sim.serial_path(), LinkOptions::default()).expect("connect to the sim")
}

/// Poll the ground truth (every 200 µs of wall time) until `pred` holds; `None` after `wall`.
pub fn wait_truth(
    sim: &PtySim,
    wall: Duration,
    mut pred: impl FnMut(&Truth) -> bool,
) -> Option<Truth> {
    let end = Instant::now() + wall;
    while Instant::now() < end {
        let t = sim.truth();
        if pred(&t) {
            return Some(t);
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    None
}

/// Distance between two true positions, m.
pub fn dist(a: &pushbot_sim::Pose, b: &pushbot_sim::Pose) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// `a − b` wrapped into (−π, π].
pub fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}
