//! The core's faults and contact handling through its public contract: the bumper, walls,
//! stalls, frozen or jumping encoders, overruns, emergency stop and clearing faults.

use pushbot_firmware::{Faults, Mode};
use pushbot_protocol::{Command, NackReason, Outcome, RobotMsg};

mod common;

use common::Bench;

#[test]
fn bumper_debounce_ignores_a_1_ms_glitch_and_stops_on_contact() {
    let mut b = Bench::connected();
    let s = b.send(Command::AdvanceUntilContact {
        max_distance: 1.0,
        speed: 0.2,
    });
    b.run_ms(300);
    b.bumper_raw = 0b001;
    b.tick(); // 1 ms glitch
    b.bumper_raw = 0;
    b.run_ms(50);
    assert!(b.done(s).is_none(), "a glitch is not a contact");
    assert!(
        !b.msgs
            .iter()
            .any(|(_, m)| matches!(m, RobotMsg::Contact(_)))
    );
    assert_eq!(b.core.mode(), Mode::Advance);
    // A real contact.
    let closed_at = b.now;
    b.bumper_raw = 0b100;
    let d = b.run_until_done(s, 100).expect("contact ends the advance");
    assert_eq!(d.outcome, Outcome::Contact);
    let contact = b
        .msgs
        .iter()
        .find_map(|(_, m)| match m {
            RobotMsg::Contact(c) => Some(*c),
            _ => None,
        })
        .expect("contact event");
    assert_eq!(contact.bumper, 0b100);
    // Debounced edge: 5 ms after the raw edge.
    assert_eq!(contact.time_us, closed_at + 5_000);
    assert_eq!(d.time_us, contact.time_us);
    // Duty 0 at that very step.
    let out = b
        .duties
        .iter()
        .find(|(t, _)| *t == contact.time_us)
        .expect("step");
    assert_eq!(out.1.duty, [0.0, 0.0]);
}

#[test]
fn move_with_stop_on_contact_stops_at_wall() {
    let mut b = Bench::connected();
    b.wall = Some(0.1);
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.2,
        stop_on_contact: true,
    });
    let d = b.run_until_done(s, 3_000).expect("ends");
    assert_eq!(d.outcome, Outcome::Contact);
    assert!((d.pose.x - 0.1).abs() < 0.01, "{:?}", d.pose);
    assert_eq!(b.core.faults(), Faults::NONE);
}

#[test]
fn move_into_wall_without_stop_on_contact_ends_in_stall() {
    let mut b = Bench::connected();
    b.wall = Some(0.1);
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.2,
        stop_on_contact: false,
    });
    let d = b.run_until_done(s, 3_000).expect("ends");
    match d.outcome {
        Outcome::Fault(f) => assert!(
            f.contains(Faults::STALL_LEFT) || f.contains(Faults::STALL_RIGHT),
            "{f:?}"
        ),
        o => panic!("outcome {o:?}"),
    }
    assert!(
        b.msgs
            .iter()
            .any(|(_, m)| matches!(m, RobotMsg::Contact(_))),
        "contact still reported"
    );
    b.tick();
    assert_eq!(b.tick().duty, [0.0, 0.0]);
}

#[test]
fn frozen_encoders_end_in_stall_fault_quickly() {
    let mut b = Bench::connected();
    b.frozen = true;
    let t0 = b.now;
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    let d = b.run_until_done(s, 1_000).expect("does not hang");
    assert!(
        matches!(d.outcome, Outcome::Fault(f) if f.contains(Faults::STALL_LEFT) || f.contains(Faults::STALL_RIGHT)),
        "{:?}",
        d.outcome
    );
    assert!(d.time_us - t0 < 500_000, "took {} µs", d.time_us - t0);
    // Motion is refused while the fault is latched, accepted once cleared.
    b.frozen = false;
    let m = b.send(Command::Spin {
        angle: 1.0,
        rate: 1.0,
    });
    b.tick();
    assert!(
        matches!(b.reply(m), Some(RobotMsg::Nack { reason: NackReason::Faulted(f), .. }) if !f.is_empty())
    );
    let c = b.send(Command::ClearFaults);
    b.tick();
    assert!(b.acked(c));
    assert_eq!(b.core.faults(), Faults::NONE);
    let m = b.send(Command::Spin {
        angle: 1.0,
        rate: 1.0,
    });
    b.tick();
    assert!(b.acked(m));
}

#[test]
fn emergency_stop_cuts_at_once_and_latches() {
    let mut b = Bench::connected();
    let s = b.send(Command::Move {
        distance: 0.3,
        speed: 0.3,
        stop_on_contact: false,
    });
    b.run_ms(300);
    assert_ne!(b.tick().duty, [0.0, 0.0]);
    let e = b.send(Command::EmergencyStop);
    assert_eq!(b.tick().duty, [0.0, 0.0]);
    assert!(b.acked(e));
    assert_eq!(
        b.done(s).map(|d| d.outcome),
        Some(Outcome::Fault(Faults::EMERGENCY_STOP))
    );
    assert_eq!(b.core.faults(), Faults::EMERGENCY_STOP);
    let m = b.send(Command::Move {
        distance: 0.1,
        speed: 0.1,
        stop_on_contact: false,
    });
    b.tick();
    assert_eq!(
        b.reply(m),
        Some(RobotMsg::Nack {
            seq: m,
            reason: NackReason::Faulted(Faults::EMERGENCY_STOP)
        })
    );
    b.send(Command::ClearFaults);
    b.tick();
    assert_eq!(b.core.mode(), Mode::Idle);
}

#[test]
fn encoder_jump_latches_encoder_fault() {
    let mut b = Bench::connected();
    let s = b.send(Command::Velocity {
        v: 0.1,
        omega: 0.0,
        timeout_ms: 1_000,
    });
    b.run_ms(100);
    b.motors[0].angle += 50.0; // thousands of counts in one step
    b.tick();
    assert!(b.core.faults().contains(Faults::ENCODER));
    b.tick();
    assert_eq!(
        b.done(s).map(|d| d.outcome),
        Some(Outcome::Fault(Faults::ENCODER))
    );
    // Cleared only once it has been quiet for a while.
    b.send(Command::ClearFaults);
    assert!(b.core.faults().contains(Faults::ENCODER));
    b.run_ms(150);
    b.send(Command::ClearFaults);
    assert_eq!(b.core.faults(), Faults::NONE);
}

#[test]
fn late_control_step_latches_overrun() {
    let mut b = Bench::connected();
    let s = b.send(Command::Velocity {
        v: 0.1,
        omega: 0.0,
        timeout_ms: 1_000,
    });
    b.run_ms(50);
    b.now += 5_000; // the loop missed five periods
    b.tick();
    assert!(b.core.faults().contains(Faults::CONTROL_OVERRUN));
    assert_eq!(
        b.done(s).map(|d| d.outcome),
        Some(Outcome::Fault(Faults::CONTROL_OVERRUN))
    );
}

#[test]
fn clear_faults_without_faults_leaves_motion_alone() {
    let mut b = Bench::connected();
    let m = b.send(Command::Move {
        distance: 0.2,
        speed: 0.2,
        stop_on_contact: false,
    });
    b.run_ms(300);
    let c = b.send(Command::ClearFaults);
    b.tick();
    assert!(b.acked(c));
    assert_eq!(b.core.mode(), Mode::Move);
    let d = b.run_until_done(m, 3_000).expect("ends");
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((d.pose.x - 0.2).abs() < 0.003);
}
