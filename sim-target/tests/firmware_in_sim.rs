//! The firmware core driving the simulated robot in process: the host's frames go in as bytes,
//! the true motion comes out.

use pushbot_protocol::{
    Command, FrameDecoder, HostFrame, MAX_FRAME, Outcome, PROTOCOL_VERSION, RobotMsg, encode_frame,
};
use pushbot_sim::{Pose, Sim, SimOptions};

fn frame(seq: u16, cmd: Command) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(&HostFrame { seq, cmd }, &mut buf).expect("frame fits");
    buf[..n].to_vec()
}

/// Tick until the robot sends a message matching `want`, feeding heartbeats every 50 ms of
/// simulated time; returns it, or None after `max_s` simulated seconds.
fn run_until(
    sim: &mut Sim,
    max_s: f64,
    mut want: impl FnMut(&RobotMsg) -> bool,
) -> Option<RobotMsg> {
    let mut dec = FrameDecoder::new();
    let mut out = Vec::new();
    let end = sim.now_us() + (max_s * 1e6) as u64;
    while sim.now_us() < end {
        if sim.now_us().is_multiple_of(50_000) {
            sim.receive(&frame(0, Command::Heartbeat));
        }
        sim.tick();
        out.clear();
        sim.transmit(&mut out);
        let mut found = None;
        dec.feed::<RobotMsg>(&out, |m| {
            if let Ok(m) = m
                && found.is_none()
                && want(&m)
            {
                found = Some(m);
            }
        });
        if found.is_some() {
            return found;
        }
    }
    None
}

fn hello(sim: &mut Sim) {
    sim.receive(&frame(
        1,
        Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    ));
    let reply = run_until(sim, 0.5, |m| matches!(m, RobotMsg::HelloReply(_)));
    match reply {
        Some(RobotMsg::HelloReply(r)) => assert!(r.accepted, "{r:?}"),
        other => panic!("no hello reply: {other:?}"),
    }
}

/// A 0.25 m move ends `Completed` and the true robot moved 0.25 m along its heading.
fn drive(seed: u64) -> (Pose, Vec<(f64, f64)>) {
    let start = Pose::new(0.3, 0.45, 0.3);
    let mut sim = Sim::new(&SimOptions {
        seed,
        start,
        ..SimOptions::default()
    })
    .expect("sim");
    hello(&mut sim);
    sim.receive(&frame(
        2,
        Command::Move {
            distance: 0.25,
            speed: 0.15,
            stop_on_contact: true,
        },
    ));
    let mut trace = Vec::new();
    let done = run_until(
        &mut sim,
        10.0,
        |m| matches!(m, RobotMsg::Done(d) if d.seq == 2),
    );
    let Some(RobotMsg::Done(d)) = done else {
        panic!("no done: {done:?}");
    };
    assert_eq!(d.outcome, Outcome::Completed);
    // Let it settle, then record.
    sim.run_for(0.0);
    let p = sim.truth().pose;
    trace.push((p.x, p.y));
    let moved = ((p.x - start.x).powi(2) + (p.y - start.y).powi(2)).sqrt();
    assert!(
        (moved - 0.25).abs() < 0.005,
        "moved {moved} m, asked 0.25 m"
    );
    let along = (p.y - start.y).atan2(p.x - start.x);
    assert!(
        (along - start.theta).abs() < 0.02,
        "drove at {along} rad, heading {}",
        start.theta
    );
    (p, trace)
}

#[test]
fn move_moves_the_true_robot() {
    drive(5);
}

/// Same seed, same run; another seed, another (slightly different) end pose.
#[test]
fn deterministic_for_a_seed_with_firmware() {
    let a = drive(21);
    let b = drive(21);
    assert_eq!(a, b);
    let c = drive(22);
    assert_ne!(a.0, c.0);
}

/// Advancing until contact toward a wall ends `Contact`, with the bumper at the wall.
#[test]
fn advance_until_contact_at_a_wall() {
    let mut sim = Sim::new(&SimOptions {
        seed: 3,
        start: Pose::new(0.9, 0.45, 0.0),
        ..SimOptions::default()
    })
    .expect("sim");
    hello(&mut sim);
    sim.receive(&frame(
        2,
        Command::AdvanceUntilContact {
            max_distance: 0.5,
            speed: 0.1,
        },
    ));
    let done = run_until(
        &mut sim,
        10.0,
        |m| matches!(m, RobotMsg::Done(d) if d.seq == 2),
    );
    let Some(RobotMsg::Done(d)) = done else {
        panic!("no done: {done:?}");
    };
    assert_eq!(d.outcome, Outcome::Contact);
    let r = f64::from(SimOptions::default().robot.geometry.bumper_radius);
    let x = sim.truth().pose.x;
    assert!(x <= 1.2 - r + 1e-12 && x > 1.2 - r - 0.003, "x {x}");
}

/// A 0.3 m square of moves and 90° spins ends near its start by ground truth, for several
/// seeds (the noise is small enough for the robot's own odometry to close the square).
#[test]
fn square_closes_by_ground_truth() {
    for seed in [1, 2, 3] {
        let start = Pose::new(0.45, 0.3, 0.0);
        let mut sim = Sim::new(&SimOptions {
            seed,
            start,
            ..SimOptions::default()
        })
        .expect("sim");
        hello(&mut sim);
        let mut seq = 2;
        for _ in 0..4 {
            for cmd in [
                Command::Move {
                    distance: 0.3,
                    speed: 0.15,
                    stop_on_contact: false,
                },
                Command::Spin {
                    angle: std::f32::consts::FRAC_PI_2,
                    rate: 2.0,
                },
            ] {
                sim.receive(&frame(seq, cmd));
                let done = run_until(
                    &mut sim,
                    10.0,
                    |m| matches!(m, RobotMsg::Done(d) if d.seq == seq),
                );
                let Some(RobotMsg::Done(d)) = done else {
                    panic!("no done for {cmd:?}: {done:?}");
                };
                assert_eq!(d.outcome, Outcome::Completed, "{cmd:?}");
                seq += 1;
            }
        }
        let p = sim.truth().pose;
        let err = ((p.x - start.x).powi(2) + (p.y - start.y).powi(2)).sqrt();
        eprintln!(
            "seed {seed}: square closes within {:.2} mm, heading {:.4} rad, odometry {:?}",
            err * 1e3,
            p.theta,
            sim.truth().odometry
        );
        assert!(err < 0.01, "seed {seed}: {err} m from the start");
    }
}
