//! The link on a noisy wire, in process: the link bench at 1 % byte corruption, 5 %
//! frame loss and 1 % duplicated frames each way completes ≥ 99.9 % of 1 000 commands with none
//! executed twice by the simulator's own count; a real cut at a random moment of a move stops
//! the motors within 250 ms of robot time, 100 times of 100, and the link comes back.
#![cfg(feature = "sim")]

use pushbot::experiments::link_bench::{LinkBenchOptions, run};
use pushbot::robot::{LinkOptions, Robot};
use pushbot::sim::inprocess::InProcess;
use pushbot_protocol::{Command, Faults};
use pushbot_sim::faults::LinkFaults;
use pushbot_sim::{Pose, Sim, SimOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn a_thousand_commands_survive_a_noisy_wire() {
    for seed in [1, 2] {
        let r = run(&LinkBenchOptions {
            commands: 1000,
            corrupt: 0.01,
            frame_loss: 0.05,
            duplicate: 0.01,
            seed,
            ..LinkBenchOptions::default()
        })
        .unwrap();
        assert_eq!(r.sent, 1000);
        assert!(r.completed_share() >= 0.999, "seed {seed}: {r:?}");
        assert_eq!(r.executed_twice, 0, "seed {seed}: {r:?}");
        assert_eq!(r.unasked_motions, 0, "seed {seed}: {r:?}");
        // The faults did happen, and the simulator saw the motions it ran.
        assert!(r.retries_per_command > 0.05, "{r:?}");
        assert!(r.frames_rejected > 100, "{r:?}");
        assert!(r.motions_started > 500, "{r:?}");
    }
}

const CLEAN: LinkFaults = LinkFaults::NONE;

#[test]
fn real_cuts_stop_the_motors_within_250_ms() {
    let sim = Sim::new(&SimOptions {
        seed: 5,
        speed: 0.0,
        table: (6.0, 6.0),
        start: Pose::new(3.0, 3.0, 0.0),
        ..SimOptions::default()
    })
    .unwrap();
    let link = LinkOptions::default();
    let driver = InProcess::with_faults(sim, link.client_options(7), CLEAN, 5);
    let robot = Robot::over(driver, link).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut worst_us = 0;
    for cut in 0..100 {
        let sign = if cut % 2 == 0 { 1.0 } else { -1.0 };
        let motion = robot
            .start(Command::Move {
                distance: 0.5 * sign,
                speed: 0.2,
                stop_on_contact: false,
            })
            .unwrap();
        let d = robot.driver();
        // Somewhere in the move, once the wheels are driven.
        d.run_for(rng.random_range(0.1..0.8));
        assert!(
            d.sim().truth().duty.iter().any(|&u| u != 0.0),
            "cut {cut}: driving"
        );
        let at = d.sim().now_us();
        d.cut_for(1_000_000);
        while d.sim().truth().duty.iter().any(|&u| u != 0.0) {
            assert!(d.sim().now_us() - at <= 250_000, "cut {cut}: still driven");
            d.run_for(0.001);
        }
        worst_us = worst_us.max(d.sim().now_us() - at);
        assert!(d.sim().truth().faults.contains(Faults::LINK_LOST));
        // The wire comes back: the move ended in the fault, which the host clears.
        d.run_for(1.0);
        let done = robot.wait(&motion).unwrap();
        assert!(
            matches!(done.outcome, pushbot_protocol::Outcome::Fault(f) if f.contains(Faults::LINK_LOST)),
            "cut {cut}: {done:?}"
        );
        assert_eq!(robot.clear_faults().unwrap(), Faults::NONE, "cut {cut}");
    }
    assert_eq!(robot.driver().sim().watchdog_trips(), 100);
    eprintln!("worst stop after a cut: {} ms", worst_us / 1000);
}
