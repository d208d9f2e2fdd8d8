//! `PtySim` in process: a host talks to the robot through the pty exactly as to hardware.

use std::io::Read;
use std::time::{Duration, Instant};

use pushbot_protocol::{
    Command, ConfigUpdate, FrameDecoder, HostFrame, MAX_FRAME, Outcome, PROTOCOL_VERSION, RobotMsg,
    encode_frame,
};
use pushbot_sim::{Pose, PtySim, SimOptions};
use serialport::SerialPort;

fn send(port: &mut dyn SerialPort, seq: u16, cmd: Command) {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(&HostFrame { seq, cmd }, &mut buf).expect("frame");
    port.write_all(&buf[..n]).expect("write");
}

/// Read until a message matches, sending a heartbeat every 5 ms of wall time (50 ms of robot
/// time at speed 10, well inside the 200 ms watchdog); panics after
/// `secs` of wall time.
fn wait_for(
    port: &mut dyn SerialPort,
    secs: f64,
    mut want: impl FnMut(&RobotMsg) -> bool,
) -> RobotMsg {
    let mut dec = FrameDecoder::new();
    let deadline = Instant::now() + Duration::from_secs_f64(secs);
    let mut last_beat = Instant::now();
    let mut rx = [0u8; 256];
    while Instant::now() < deadline {
        if last_beat.elapsed() > Duration::from_millis(5) {
            send(port, 0, Command::Heartbeat);
            last_beat = Instant::now();
        }
        let n = match port.read(&mut rx) {
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => 0,
            Err(e) => panic!("reading the pty: {e}"),
        };
        let mut found = None;
        dec.feed::<RobotMsg>(&rx[..n], |m| {
            if let Ok(m) = m
                && found.is_none()
                && want(&m)
            {
                found = Some(m);
            }
        });
        if let Some(m) = found {
            return m;
        }
    }
    panic!("no matching message within {secs} s");
}

fn open(sim: &PtySim) -> Box<dyn SerialPort> {
    // A freshly closed port may be refused for a moment (exclusive flag; see `pty`).
    let deadline = Instant::now() + Duration::from_secs(2);
    loop {
        match serialport::new(sim.serial_path(), 115_200)
            .timeout(Duration::from_millis(2))
            .open()
        {
            Ok(p) => return p,
            Err(e) if Instant::now() < deadline => {
                eprintln!("retrying open: {e}");
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(e) => panic!("opening {}: {e}", sim.serial_path()),
        }
    }
}

fn hello(port: &mut dyn SerialPort, seq: u16) {
    send(
        port,
        seq,
        Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    );
    match wait_for(port, 5.0, |m| matches!(m, RobotMsg::HelloReply(_))) {
        RobotMsg::HelloReply(r) => assert!(r.accepted),
        _ => unreachable!(),
    }
    // At 10× a host thread descheduled for 20 ms of wall time misses 200 ms of robot time:
    // give the watchdog room on a loaded machine.
    let configure = Command::Configure(ConfigUpdate {
        watchdog_ms: Some(2000),
        ..ConfigUpdate::default()
    });
    send(port, seq + 100, configure);
    wait_for(
        port,
        5.0,
        |m| matches!(m, RobotMsg::Ack { seq: s } if *s == seq + 100),
    );
}

#[test]
fn host_drives_the_robot_over_the_pty_and_reconnects() {
    let start = Pose::new(0.4, 0.4, 0.0);
    let sim = PtySim::start(SimOptions {
        seed: 9,
        speed: 10.0,
        start,
        ..SimOptions::default()
    })
    .expect("start");
    assert!(sim.serial_path().starts_with("/dev/"));
    let mut port = open(&sim);
    hello(port.as_mut(), 1);
    send(
        port.as_mut(),
        2,
        Command::Move {
            distance: 0.1,
            speed: 0.1,
            stop_on_contact: false,
        },
    );
    let done = wait_for(
        port.as_mut(),
        10.0,
        |m| matches!(m, RobotMsg::Done(d) if d.seq == 2),
    );
    let RobotMsg::Done(d) = done else {
        unreachable!()
    };
    assert_eq!(d.outcome, Outcome::Completed);
    let truth = sim.truth();
    assert!(
        (truth.pose.x - start.x - 0.1).abs() < 0.003,
        "truth {:?} after a 0.1 m move",
        truth.pose
    );
    assert!(truth.t > 1.0, "simulated time ran: {}", truth.t);

    // The host goes away without reading; simulated time keeps running.
    drop(port);
    let t0 = sim.truth().t;
    std::thread::sleep(Duration::from_millis(300));
    let t1 = sim.truth().t;
    assert!(t1 - t0 > 1.0, "paced at 10×: {t0} → {t1}");
    assert!(sim.is_running());

    // And it comes back: reopen, a new session, another move.
    let mut port = open(&sim);
    hello(port.as_mut(), 3);
    send(port.as_mut(), 4, Command::ClearFaults);
    wait_for(port.as_mut(), 5.0, |m| {
        matches!(m, RobotMsg::Ack { seq: 4 })
    });
    send(
        port.as_mut(),
        5,
        Command::Move {
            distance: -0.05,
            speed: 0.1,
            stop_on_contact: false,
        },
    );
    let done = wait_for(
        port.as_mut(),
        10.0,
        |m| matches!(m, RobotMsg::Done(d) if d.seq == 5),
    );
    let RobotMsg::Done(d) = done else {
        unreachable!()
    };
    assert_eq!(d.outcome, Outcome::Completed);
    assert!((sim.truth().pose.x - start.x - 0.05).abs() < 0.004);
    drop(port);
    sim.shutdown().expect("clean shutdown");
}

/// The pace follows `speed`: about `speed` simulated seconds per wall second.
#[test]
fn speed_paces_simulated_time() {
    for speed in [1.0, 20.0] {
        let sim = PtySim::start(SimOptions {
            speed,
            ..SimOptions::default()
        })
        .expect("start");
        let wall = Instant::now();
        std::thread::sleep(Duration::from_millis(500));
        let t = sim.truth().t;
        let ratio = t / wall.elapsed().as_secs_f64();
        // Generous: a loaded machine may run slow, never fast.
        assert!(
            ratio <= speed * 1.05 && ratio > speed * 0.5,
            "speed {speed}: ratio {ratio}"
        );
        sim.shutdown().expect("shutdown");
    }
}

/// With every byte dropped the robot never answers; with the default fault profile a host
/// that retries still gets its session.
#[test]
fn link_faults_apply_on_the_pty() {
    use pushbot_sim::faults::LinkFaults;
    let dead = PtySim::start(SimOptions {
        speed: 10.0,
        faults: Some(LinkFaults {
            drop: 1.0,
            ..LinkFaults::default()
        }),
        ..SimOptions::default()
    })
    .expect("start");
    let mut port = open(&dead);
    send(
        port.as_mut(),
        1,
        Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    );
    let mut rx = [0u8; 64];
    let deadline = Instant::now() + Duration::from_millis(500);
    while Instant::now() < deadline {
        match port.read(&mut rx) {
            Ok(n) => assert_eq!(n, 0, "a byte got through a link that drops all"),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => panic!("{e}"),
        }
    }
    drop(port);
    dead.shutdown().expect("shutdown");

    let noisy = PtySim::start(SimOptions {
        speed: 5.0,
        faults: Some(LinkFaults {
            drop: 0.01,
            corrupt: 0.01,
            ..LinkFaults::default()
        }),
        ..SimOptions::default()
    })
    .expect("start");
    let mut port = open(&noisy);
    let mut got = false;
    let mut dec = FrameDecoder::new();
    for attempt in 0..20 {
        send(
            port.as_mut(),
            1,
            Command::Hello {
                protocol: PROTOCOL_VERSION,
            },
        );
        let deadline = Instant::now() + Duration::from_millis(100);
        while Instant::now() < deadline && !got {
            if let Ok(n) = port.read(&mut rx) {
                dec.feed::<RobotMsg>(&rx[..n], |m| {
                    got |= matches!(m, Ok(RobotMsg::HelloReply(r)) if r.accepted);
                });
            }
        }
        if got {
            eprintln!("session after {} attempt(s)", attempt + 1);
            break;
        }
    }
    assert!(got, "no session through a 1 % faulty link in 20 tries");
    noisy.shutdown().expect("shutdown");
}
