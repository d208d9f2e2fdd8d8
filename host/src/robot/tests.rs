//! Link-level tests against a scripted fake robot on a pty pair: retries keep their sequence
//! number, answers and `Done`s are matched, a lost `Done` is recovered from the telemetry,
//! refusals read well, heartbeats follow robot time, a vanished port is reported.
//! (The real robot's behaviour is tested in the HIL tests of `pushbot-tests`.)

use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use pushbot_protocol::*;
use serialport::{SerialPort, TTYPort};

use super::*;

/// What the fake robot keeps between frames.
#[derive(Default)]
struct FakeState {
    time_us: u64,
    active: Option<u16>,
    last_done: Option<(u16, Outcome)>,
    /// Every frame received, in order.
    received: Vec<HostFrame>,
    /// Robot time of each heartbeat received.
    heartbeat_times: Vec<u64>,
    /// Commands executed (not retries).
    executed: Vec<HostFrame>,
    quit: bool,
}

type Script = Box<dyn FnMut(&HostFrame, &mut FakeState, &mut Vec<RobotMsg>) + Send>;

struct Fake {
    state: Arc<Mutex<FakeState>>,
    thread: Option<JoinHandle<()>>,
    path: String,
    _slave: TTYPort,
}

impl Fake {
    /// A fake robot advancing `step_us` of robot time (and sending telemetry) every ~2 ms.
    fn start(step_us: u64, mut script: Script) -> Fake {
        let (mut master, slave) = TTYPort::pair().unwrap();
        master.set_timeout(Duration::from_millis(2)).unwrap();
        let path = slave.name().unwrap();
        let state = Arc::new(Mutex::new(FakeState::default()));
        let st = Arc::clone(&state);
        let thread = std::thread::spawn(move || {
            let mut dec = FrameDecoder::new();
            let mut buf = [0u8; 256];
            loop {
                let mut out = Vec::new();
                if let Ok(n) = master.read(&mut buf) {
                    for &b in &buf[..n] {
                        if let Some(Ok(f)) = dec.push::<HostFrame>(b) {
                            let mut s = st.lock().unwrap_or_else(|e| e.into_inner());
                            s.received.push(f);
                            if f.cmd == Command::Heartbeat {
                                let t = s.time_us;
                                s.heartbeat_times.push(t);
                            } else {
                                script(&f, &mut s, &mut out);
                            }
                        }
                    }
                }
                let mut s = st.lock().unwrap_or_else(|e| e.into_inner());
                if s.quit {
                    return; // drops the master: the host's port vanishes
                }
                s.time_us += step_us;
                out.push(RobotMsg::Telemetry(Telemetry {
                    time_us: s.time_us,
                    pose: Pose::default(),
                    wheel_speed: [0.0; 2],
                    bumper: 0,
                    mode: if s.active.is_some() {
                        Mode::Move
                    } else {
                        Mode::Idle
                    },
                    faults: Faults::NONE,
                    active: s.active,
                    last_done: s.last_done,
                }));
                drop(s);
                for m in out {
                    let mut fb = [0u8; MAX_FRAME];
                    let n = encode_frame(&m, &mut fb).unwrap();
                    if master.write_all(&fb[..n]).is_err() {
                        return;
                    }
                }
            }
        });
        Fake {
            state,
            thread: Some(thread),
            path,
            _slave: slave,
        }
    }

    /// Stop the fake robot. A lock poisoned by a failed assertion is still taken, and a
    /// panicked thread is not re-raised, so a failing test reports its own message instead of
    /// aborting on a panic during unwinding.
    fn quit(&mut self) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).quit = true;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Fake {
    fn drop(&mut self) {
        self.quit();
    }
}

fn hello_reply(protocol: u16, accepted: bool) -> RobotMsg {
    RobotMsg::HelloReply(HelloReply {
        protocol,
        accepted,
        firmware: FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        geometry: Geometry {
            wheel_base: 0.1,
            wheel_radius: 0.02,
            bumper_radius: 0.07,
            encoder_cpr: 1440,
            control_hz: 500,
        },
    })
}

/// A fake that follows the protocol's retry rule, finishes motions at once, and lets `tweak`
/// drop or alter answers: `tweak(frame, n-th time this seq was seen, replies)`.
fn well_behaved(
    mut tweak: impl FnMut(&HostFrame, usize, &mut Vec<RobotMsg>) + Send + 'static,
) -> Script {
    let mut last: Option<(u16, Vec<RobotMsg>)> = None;
    let mut seen = std::collections::HashMap::<u16, usize>::new();
    Box::new(move |f, s, out| {
        let n = seen.entry(f.seq).or_default();
        *n += 1;
        let mut replies = Vec::new();
        match &last {
            Some((seq, answer)) if *seq == f.seq => replies.extend(answer.iter().copied()),
            _ => {
                s.executed.push(*f);
                match f.cmd {
                    Command::Hello { protocol } => {
                        replies.push(hello_reply(PROTOCOL_VERSION, protocol == PROTOCOL_VERSION))
                    }
                    _ => replies.push(RobotMsg::Ack { seq: f.seq }),
                }
                last = Some((f.seq, replies.clone()));
                if matches!(f.cmd, Command::Move { .. } | Command::Spin { .. }) {
                    replies.push(RobotMsg::Done(Done {
                        seq: f.seq,
                        outcome: Outcome::Completed,
                        pose: Pose {
                            x: 0.3,
                            y: 0.0,
                            theta: 0.0,
                        },
                        time_us: s.time_us,
                    }));
                    s.last_done = Some((f.seq, Outcome::Completed));
                }
            }
        }
        tweak(f, *n, &mut replies);
        out.extend(replies);
    })
}

fn fast_opts() -> LinkOptions {
    LinkOptions {
        ack_timeout: Duration::from_millis(60),
        ..LinkOptions::default()
    }
}

#[test]
fn handshake_and_move() {
    let fake = Fake::start(1000, well_behaved(|_, _, _| {}));
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    assert_eq!(robot.hello().protocol, PROTOCOL_VERSION);
    let done = robot.move_distance(0.3, 0.1, false).unwrap();
    assert_eq!(done.outcome, Outcome::Completed);
    assert!(!done.recovered);
    assert_eq!(done.pose.x, 0.3);
    let s = fake.state.lock().unwrap();
    assert_eq!(s.executed.len(), 2);
    assert!(matches!(s.executed[1].cmd, Command::Move { .. }));
    assert_eq!(s.executed[1].seq, s.executed[0].seq.wrapping_add(1));
}

#[test]
fn lost_ack_is_retried_with_the_same_seq_and_executed_once() {
    // Drop the answers to the first two sendings of every command after Hello.
    let fake = Fake::start(
        1000,
        well_behaved(|f, n, replies| {
            if !matches!(f.cmd, Command::Hello { .. }) && n <= 2 {
                replies.clear();
            }
        }),
    );
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    let done = robot.spin(1.0, 1.0).unwrap();
    assert_eq!(done.outcome, Outcome::Completed);
    // The Done was dropped with the Acks: recovered from the telemetry's last_done.
    assert!(done.recovered);
    let s = fake.state.lock().unwrap();
    let spins: Vec<_> = s
        .received
        .iter()
        .filter(|f| matches!(f.cmd, Command::Spin { .. }))
        .collect();
    // Two answers are dropped, so at least three sendings; a host slowed down by a loaded
    // machine may resend once more, which must change nothing.
    assert!(spins.len() >= 3, "sent {} times", spins.len());
    assert!(spins.iter().all(|f| f.seq == spins[0].seq), "same seq");
    assert_eq!(
        s.executed
            .iter()
            .filter(|f| matches!(f.cmd, Command::Spin { .. }))
            .count(),
        1
    );
    let retries = robot.stats().retries;
    drop(s);
    assert!(retries >= 2, "{retries} retries");
}

#[test]
fn no_answer_gives_up_after_the_attempts() {
    let fake = Fake::start(
        1000,
        well_behaved(|f, _, replies| {
            if matches!(f.cmd, Command::Stop) {
                replies.clear();
            }
        }),
    );
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    let err = robot.stop().unwrap_err();
    assert!(
        matches!(err, LinkError::NoAnswer { attempts: 5, .. }),
        "{err}"
    );
    let stops = fake
        .state
        .lock()
        .unwrap()
        .received
        .iter()
        .filter(|f| f.cmd == Command::Stop)
        .count();
    assert_eq!(stops, 5);
}

#[test]
fn version_mismatch_names_both_versions() {
    let fake = Fake::start(1000, well_behaved(|_, _, _| {}));
    let opts = LinkOptions {
        protocol_version_override: Some(PROTOCOL_VERSION + 41),
        ..fast_opts()
    };
    let err = Robot::connect(&fake.path, opts).err().unwrap();
    let msg = err.to_string();
    assert!(matches!(err, LinkError::VersionMismatch { .. }), "{msg}");
    assert!(
        msg.contains(&format!("v{}", PROTOCOL_VERSION + 41)),
        "{msg}"
    );
    assert!(msg.contains(&format!("v{PROTOCOL_VERSION}")), "{msg}");
}

#[test]
fn robot_with_another_version_is_refused_even_if_it_accepts() {
    let fake = Fake::start(
        1000,
        Box::new(|f, _, out| {
            if let Command::Hello { .. } = f.cmd {
                out.push(hello_reply(PROTOCOL_VERSION + 1, true));
            }
        }),
    );
    let err = Robot::connect(&fake.path, fast_opts()).err().unwrap();
    assert!(matches!(err, LinkError::VersionMismatch { .. }), "{err}");
}

#[test]
fn nack_faulted_says_what_to_do() {
    let fake = Fake::start(
        1000,
        well_behaved(|f, _, replies| {
            if matches!(f.cmd, Command::Move { .. }) {
                *replies = vec![RobotMsg::Nack {
                    seq: f.seq,
                    reason: NackReason::Faulted(Faults::STALL_LEFT.union(Faults::LINK_LOST)),
                }];
            }
        }),
    );
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    let err = robot.move_distance(0.1, 0.1, false).unwrap_err();
    assert_eq!(
        err.to_string(),
        "robot refused Move: faults latched: STALL_LEFT, LINK_LOST; run `pushbot robot clear-faults`"
    );
}

#[test]
fn done_wait_is_bounded_in_robot_time() {
    // A robot that accepts a spin and never finishes it; 100 ms of robot time per ~2 ms.
    let fake = Fake::start(
        100_000,
        Box::new(|f, s, out| match f.cmd {
            Command::Hello { .. } => out.push(hello_reply(PROTOCOL_VERSION, true)),
            _ => {
                s.executed.push(*f);
                out.push(RobotMsg::Ack { seq: f.seq });
            }
        }),
    );
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    let wall = std::time::Instant::now();
    let err = robot.spin(0.5, 1.0).unwrap_err();
    // Budget: 2 * 0.5 s + 5 s = 6 s robot, i.e. ~60 loop steps, far below 6 s of wall time.
    assert!(matches!(err, LinkError::DoneTimeout { .. }), "{err}");
    assert!(
        wall.elapsed() < Duration::from_secs(3),
        "{:?}",
        wall.elapsed()
    );
    let s = fake.state.lock().unwrap();
    assert_eq!(s.executed.last().unwrap().cmd, Command::Stop, "sent Stop");
}

#[test]
fn heartbeats_follow_robot_time() {
    // 20 ms of robot time per ~2 ms of wall time: ~10x faster than real time.
    let fake = Fake::start(20_000, well_behaved(|_, _, _| {}));
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    let t0 = robot.telemetry().map_or(0, |t| t.time_us);
    robot.wait_telemetry(Some(t0 + 3_000_000)).unwrap();
    let s = fake.state.lock().unwrap();
    let hb: Vec<u64> = s
        .heartbeat_times
        .iter()
        .copied()
        .filter(|&t| t > t0)
        .collect();
    assert!(
        hb.len() >= 30,
        "{} heartbeats in 3 s of robot time",
        hb.len()
    );
    // Quarter watchdog (50 ms of robot time) plus telemetry and pipe latency. Judged on the
    // 90th percentile of the gaps: a loaded test machine can stall a thread for tens of ms of
    // wall time, hundreds of ms of robot time at 10x, once in a while; heartbeats paced by the
    // wall clock instead would leave 500 ms gaps here, and about 6 heartbeats, not 30.
    let mut gaps: Vec<u64> = hb.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_unstable();
    let p90 = gaps[gaps.len() * 9 / 10];
    assert!(
        p90 <= 100_000,
        "90th percentile heartbeat gap {p90} us of robot time (largest {} us)",
        gaps.last().unwrap()
    );
}

#[test]
fn paused_heartbeats_go_quiet() {
    let fake = Fake::start(20_000, well_behaved(|_, _, _| {}));
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    robot.pause_heartbeats(true);
    let t0 = robot.wait_telemetry(None).unwrap().time_us;
    robot.wait_telemetry(Some(t0 + 1_000_000)).unwrap();
    let s = fake.state.lock().unwrap();
    let after = s
        .heartbeat_times
        .iter()
        .filter(|&&t| t > t0 + 40_000)
        .count();
    assert_eq!(after, 0);
}

#[test]
fn vanished_port_is_reported() {
    let mut fake = Fake::start(1000, well_behaved(|_, _, _| {}));
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    fake.quit();
    let err = robot.wait_telemetry(Some(u64::MAX - 1)).unwrap_err();
    assert!(matches!(err, LinkError::Disconnected { .. }), "{err}");
    assert!(err.to_string().contains(&fake.path));
}

#[test]
fn silent_robot_is_a_dead_link() {
    let fake = Fake::start(1000, well_behaved(|_, _, _| {}));
    let opts = LinkOptions {
        dead_link_timeout: Duration::from_millis(300),
        ..fast_opts()
    };
    let robot = Robot::connect(&fake.path, opts).unwrap();
    // Freeze the fake: it holds its lock so it neither reads nor writes.
    let guard = fake.state.lock().unwrap();
    let err = robot.wait_telemetry(Some(u64::MAX - 1)).unwrap_err();
    drop(guard);
    assert!(matches!(err, LinkError::Silent { .. }), "{err}");
}

#[test]
fn telemetry_stream_delivers_in_order() {
    let fake = Fake::start(1000, well_behaved(|_, _, _| {}));
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    let rx = robot.subscribe();
    let times: Vec<u64> = rx
        .iter()
        .filter_map(|e| match e {
            RobotEvent::Telemetry(t) => Some(t.time_us),
            _ => None,
        })
        .take(20)
        .collect();
    assert!(times.windows(2).all(|w| w[0] < w[1]), "{times:?}");
}

#[test]
fn send_raw_garbage_does_not_break_the_link() {
    let fake = Fake::start(1000, well_behaved(|_, _, _| {}));
    let robot = Robot::connect(&fake.path, fast_opts()).unwrap();
    robot.send_raw(&[0xff; 300]).unwrap();
    robot.send_raw(&[0x00, 0x13, 0x37, 0x00]).unwrap();
    let done = robot.move_distance(0.3, 0.1, false).unwrap();
    assert_eq!(done.outcome, Outcome::Completed);
}

#[test]
fn undecodable_hello_reply_of_another_version_is_a_mismatch() {
    /// A future protocol's reply: same variant 0 and first field, different fields after.
    #[derive(serde::Serialize)]
    enum FutureMsg {
        HelloReply {
            protocol: u16,
            accepted: bool,
            serial: u64,
        },
    }
    // The scripted fake speaks only our messages: answer the Hello by hand.
    let (mut master, slave) = TTYPort::pair().unwrap();
    master.set_timeout(Duration::from_millis(5)).unwrap();
    let path = slave.name().unwrap();
    let peer = std::thread::spawn(move || {
        let mut dec = FrameDecoder::new();
        let mut buf = [0u8; 64];
        let deadline = std::time::Instant::now() + Duration::from_secs(3);
        while std::time::Instant::now() < deadline {
            let Ok(n) = master.read(&mut buf) else {
                continue;
            };
            for &b in &buf[..n] {
                if let Some(Ok(HostFrame {
                    cmd: Command::Hello { .. },
                    ..
                })) = dec.push::<HostFrame>(b)
                {
                    let mut fb = [0u8; MAX_FRAME];
                    let msg = FutureMsg::HelloReply {
                        protocol: 9,
                        accepted: false,
                        serial: u64::MAX,
                    };
                    let n = encode_frame(&msg, &mut fb).unwrap();
                    master.write_all(&fb[..n]).unwrap();
                    return master; // kept open until the host has read the reply
                }
            }
        }
        master
    });
    let err = Robot::connect(&path, fast_opts()).err().unwrap();
    let _master = peer.join().unwrap();
    drop(slave);
    assert!(
        matches!(err, LinkError::VersionMismatch { host, robot: 9, .. } if host == PROTOCOL_VERSION),
        "{err}"
    );
}
