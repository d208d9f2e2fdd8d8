//! The simulator's own count of started motion primitives per sequence number: a retry is not
//! a start, a command replayed under an old number after another one is (executed twice), and
//! a new session starts the count afresh.

use pushbot_protocol::{Command, HostFrame, MAX_FRAME, PROTOCOL_VERSION, encode_frame};
use pushbot_sim::{Sim, SimOptions};

fn send(sim: &mut Sim, seq: u16, cmd: Command) {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(&HostFrame { seq, cmd }, &mut buf).unwrap();
    sim.receive(&buf[..n]);
    sim.run_for(0.01);
}

const MOVE: Command = Command::Move {
    distance: 0.01,
    speed: 0.2,
    stop_on_contact: false,
};

#[test]
fn starts_are_counted_per_sequence_number() {
    let mut sim = Sim::new(&SimOptions {
        speed: 0.0,
        ..SimOptions::default()
    })
    .unwrap();
    let hello = Command::Hello {
        protocol: PROTOCOL_VERSION,
    };
    send(&mut sim, 1, hello);
    send(&mut sim, 2, MOVE);
    send(&mut sim, 2, MOVE); // a retry: answered again, not executed
    for _ in 0..100 {
        send(&mut sim, 2, Command::Heartbeat); // feeds the link watchdog
    }
    assert_eq!(sim.starts().get(&2), Some(&1));
    send(&mut sim, 3, Command::Stop);
    send(&mut sim, 2, MOVE); // an old number replayed after another command: executed again
    assert_eq!(sim.starts().get(&2), Some(&2));
    send(&mut sim, 1, hello); // the same Hello again: the same session
    assert_eq!(sim.starts().get(&2), Some(&2));
    send(&mut sim, 9, hello); // a new session
    assert!(sim.starts().is_empty());
    send(&mut sim, 10, MOVE);
    assert_eq!(sim.starts().get(&10), Some(&1));
}
