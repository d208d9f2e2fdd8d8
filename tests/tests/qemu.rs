//! The firmware's embassy shell on an emulated Cortex-M3 (QEMU `lm3s6965evb`, the board in
//! `firmware/board-qemu`), driven by the real host link over the emulated UART on a pty.
//!
//! The emulated board has no motors and no encoders, so the core sees frozen wheels: a
//! commanded move must end in the stall fault, not hang. Checked here: the handshake and its
//! versions, heartbeats keeping the link up, the stall fault, garbage and corrupted frames
//! rejected without effect, and the link watchdog stopping everything when the host goes quiet.
//!
//! The ELF: `$PUSHBOT_QEMU_ELF` if set; otherwise this test runs `cargo build --release` in
//! `firmware/board-qemu` with the target directory `$PUSHBOT_BOARD_TARGET_DIR` (default
//! `target/boards` at the repository root), the same one `firmware/build-boards.sh` uses, so
//! after that script the build is a no-op.
//!
//! Without `qemu-system-arm` the test is skipped with a message, unless `CI` is set, where a
//! missing QEMU is a failure (`.ci/run` installs it from Debian's packages).

use std::io::{BufRead, BufReader, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use pushbot::link::LinkError;
use pushbot::robot::{LinkOptions, Robot};
use pushbot_firmware::RobotParams;
use pushbot_protocol::{
    Command as Cmd, ConfigUpdate, Faults, HostFrame, MAX_FRAME, Mode, NackReason, Outcome,
    PROTOCOL_VERSION, encode_frame,
};

/// The robot's link watchdog during the test, ms of robot time.
const LINK_WATCHDOG_MS: u16 = 1000;

/// `O_NOCTTY` on Linux.
const O_NOCTTY: i32 = 0o400;

/// The whole test must end well within this (wall time), or QEMU is killed and it fails.
const TEST_BUDGET: Duration = Duration::from_secs(90);

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the repository")
        .to_path_buf()
}

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The board ELF, built if needed.
fn qemu_elf() -> PathBuf {
    if let Some(p) = std::env::var_os("PUSHBOT_QEMU_ELF") {
        return PathBuf::from(p);
    }
    let board = repo_root().join("firmware/board-qemu");
    let target_dir = std::env::var_os("PUSHBOT_BOARD_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo_root().join("target/boards"));
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .args(["build", "--release", "--quiet"])
        .current_dir(&board)
        .env("CARGO_TARGET_DIR", &target_dir)
        // The outer `cargo test` must not leak its build settings into the board's build.
        .env_remove("CARGO_BUILD_TARGET")
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .status()
        .expect("run cargo to build firmware/board-qemu");
    assert!(status.success(), "building firmware/board-qemu failed");
    target_dir.join("thumbv7m-none-eabi/release/pushbot-board-qemu")
}

/// A running QEMU; killed on drop.
struct Qemu {
    child: Child,
    monitor: ChildStdin,
    pty: String,
    /// The pty held open from before the CPU starts to the end.
    _holder: std::fs::File,
}

impl Qemu {
    /// Start QEMU halted with UART0 on a pty, hold the pty open, then let the CPU run, so no
    /// byte the firmware sends is lost to an unconnected pty.
    fn start(elf: &Path, log: &Path) -> Qemu {
        let mut child = Command::new("qemu-system-arm")
            .args(["-cpu", "cortex-m3", "-machine", "lm3s6965evb"])
            .args(["-display", "none", "-monitor", "stdio"])
            .args(["-serial", "pty"])
            .arg("-serial")
            .arg(format!("file:{}", log.display()))
            .args(["-S", "-no-reboot", "-kernel"])
            .arg(elf)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start qemu-system-arm");
        let monitor = child.stdin.take().expect("piped stdin");
        let stdout = child.stdout.take().expect("piped stdout");
        let (tx, rx) = mpsc::channel();
        thread::spawn(move || {
            // Keep draining the monitor's output so QEMU never blocks on a full pipe.
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if let Some(rest) = line.split("redirected to ").nth(1)
                    && rest.contains("label serial0")
                {
                    let path = rest.split_whitespace().next().unwrap_or("").to_string();
                    let _ = tx.send(path);
                }
            }
        });
        let pty = match rx.recv_timeout(Duration::from_secs(20)) {
            Ok(p) => p,
            Err(_) => {
                let _ = child.kill();
                panic!("QEMU did not report its pty");
            }
        };
        // Hold the pty open before the CPU runs (O_NOCTTY: never our controlling terminal).
        let holder = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(O_NOCTTY)
            .open(&pty)
            .unwrap_or_else(|e| panic!("open QEMU's pty {pty}: {e}"));
        let mut qemu = Qemu {
            child,
            monitor,
            pty,
            _holder: holder,
        };
        qemu.monitor("cont");
        qemu
    }

    fn monitor(&mut self, cmd: &str) {
        writeln!(self.monitor, "{cmd}").expect("write to the QEMU monitor");
        self.monitor.flush().expect("flush the QEMU monitor");
    }

    /// Whether QEMU is still running (`-no-reboot`: a watchdog reset or a lock-up ends it).
    fn alive(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A corrupted copy of a valid frame: one payload byte flipped (the delimiter kept).
fn corrupted(frame: &[u8], at: usize) -> Vec<u8> {
    let mut bad = frame.to_vec();
    let i = 1 + at % (bad.len() - 2);
    bad[i] ^= 0x5A;
    if bad[i] == 0 {
        bad[i] = 0x01; // keep the frame in one piece
    }
    bad
}

/// Telemetry over at least `robot_us` of robot time; returns (first, last).
fn telemetry_span(
    robot: &Robot,
    robot_us: u64,
) -> (pushbot_protocol::Telemetry, pushbot_protocol::Telemetry) {
    let first = robot.wait_telemetry(None).expect("telemetry");
    let mut last = first;
    while last.time_us < first.time_us + robot_us {
        last = robot.wait_telemetry(Some(last.time_us)).expect("telemetry");
    }
    (first, last)
}

#[test]
#[ignore = "timing-flaky under load (QEMU steps the control loop with 2-70 ms gaps); run with --ignored"]
fn firmware_in_qemu_against_the_host_link() {
    if Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_err()
    {
        assert!(
            !in_ci(),
            "qemu-system-arm is missing in CI (apt-get install qemu-system-arm)"
        );
        println!("SKIPPED firmware_in_qemu_against_the_host_link: qemu-system-arm not installed");
        return;
    }
    let elf = qemu_elf();
    assert!(elf.exists(), "no board ELF at {}", elf.display());
    let dir = tempfile::tempdir().expect("temp dir");
    let mut qemu = Qemu::start(&elf, &dir.path().join("defmt.bin"));

    // A guard that ends a hung run: killing QEMU makes every link call fail.
    let pid = qemu.child.id();
    let (done_tx, done_rx) = mpsc::channel::<()>();
    let guard = thread::spawn(move || {
        // Disconnected (the test ended, or panicked) is not a time-out.
        if let Err(mpsc::RecvTimeoutError::Timeout) = done_rx.recv_timeout(TEST_BUDGET) {
            eprintln!("qemu test over its {TEST_BUDGET:?} budget: killing QEMU");
            let _ = Command::new("kill").arg(pid.to_string()).status();
        }
    });
    let started = Instant::now();
    run_checks(&mut qemu);
    let _ = done_tx.send(());
    let _ = guard.join();
    println!("qemu test took {:.1} s", started.elapsed().as_secs_f64());
}

fn run_checks(qemu: &mut Qemu) {
    let params = RobotParams::default();

    // 1. Handshake. A host with another protocol version is refused first ...
    let wrong = PROTOCOL_VERSION.wrapping_add(1);
    let refused = Robot::connect(
        &qemu.pty,
        LinkOptions {
            protocol_version_override: Some(wrong),
            ..LinkOptions::default()
        },
    );
    match refused {
        Err(LinkError::VersionMismatch { robot, .. }) => assert_eq!(robot, PROTOCOL_VERSION),
        Err(e) => panic!("a host with protocol {wrong}: {e}, not a version mismatch"),
        Ok(r) => panic!("a host with protocol {wrong} was accepted: {:?}", r.hello()),
    }
    // ... then ours is accepted, with the right versions and the reference robot's geometry.
    // (A HelloReply carries no sequence number: let the answers to the refused host's retries
    // arrive, and be flushed when the port is opened, before shaking hands again.)
    thread::sleep(Duration::from_millis(500));
    let mut robot = Robot::connect(&qemu.pty, LinkOptions::default())
        .unwrap_or_else(|e| panic!("handshake with the QEMU board on {}: {e}", qemu.pty));
    let hello = *robot.hello();
    assert_eq!(hello.protocol, PROTOCOL_VERSION);
    assert!(hello.accepted);
    assert_eq!(hello.firmware, params.firmware);
    assert_eq!(hello.geometry, params.geometry);

    // QEMU runs in real time on a shared host that can pause it for a while: a 1 s link
    // watchdog (instead of the default 200 ms) keeps a busy CI machine from tripping it.
    robot
        .configure(ConfigUpdate {
            watchdog_ms: Some(LINK_WATCHDOG_MS),
            ..ConfigUpdate::default()
        })
        .expect("configure the link watchdog");

    // 2. Heartbeats keep the link up: a second of robot time (five watchdog periods) passes
    //    without LINK_LOST, and robot time runs at wall-clock speed (SysTick is calibrated).
    let wall = Instant::now();
    let (first, last) = telemetry_span(&robot, 1_000_000);
    let robot_s = (last.time_us - first.time_us) as f64 / 1e6;
    let wall_s = wall.elapsed().as_secs_f64();
    assert!(
        !last.faults.contains(Faults::LINK_LOST),
        "link lost despite heartbeats: {:?}",
        last.faults
    );
    assert_eq!(last.mode, Mode::Idle);
    assert!(robot.stats().heartbeats_sent > 0, "no heartbeat was sent");
    assert!(
        robot_s > 0.25 * wall_s && robot_s < 2.0 * wall_s + 0.1,
        "robot time {robot_s:.3} s against wall time {wall_s:.3} s"
    );

    // 3. Garbage on the wire: a run of noise with no delimiter (longer than any frame),
    //    random bytes with delimiters, and a corrupted Move frame. None may act; the link
    //    keeps working afterwards.
    let rejected_before = robot.stats().frames_rejected;
    let mut noise = vec![0x55u8; 3 * MAX_FRAME];
    noise.push(0);
    robot.send_raw(&noise).expect("send noise");
    let mut x: u32 = 0x1234_5678;
    let random: Vec<u8> = (0..300)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x >> 24) as u8
        })
        .collect();
    robot.send_raw(&random).expect("send random bytes");
    robot.send_raw(&[0]).expect("send delimiter");
    let mut frame = [0u8; MAX_FRAME];
    let n = encode_frame(
        &HostFrame {
            seq: 0xBEEF,
            cmd: Cmd::Move {
                distance: 0.5,
                speed: 0.1,
                stop_on_contact: false,
            },
        },
        &mut frame,
    )
    .expect("encode a Move frame");
    for at in (0..n).step_by(3) {
        robot
            .send_raw(&corrupted(&frame[..n], at))
            .expect("send a corrupted frame");
    }
    let (_, after) = telemetry_span(&robot, 300_000);
    assert_eq!(
        after.mode,
        Mode::Idle,
        "after garbage: mode {:?}, faults {:?}",
        after.mode,
        after.faults
    );
    assert_eq!(after.active, None, "a corrupted frame started a motion");
    assert!(
        after.faults.is_empty(),
        "garbage latched faults: {:?}",
        after.faults
    );
    // The robot itself sends nothing garbled: the host rejected none of its frames.
    assert_eq!(robot.stats().frames_rejected, rejected_before);
    assert!(
        qemu.alive(),
        "QEMU ended (watchdog reset or lock-up) on garbage"
    );

    // 4. A move with frozen encoders ends in the stall fault, not a hang. QEMU keeps real time
    //    on a host that may be too busy to run the 1 kHz loop on time; a move the core stopped
    //    for a missed deadline (CONTROL_OVERRUN, its own safety check) says nothing about the
    //    stall, so it is cleared and tried again, a few times at most.
    let mut overruns = 0;
    let done = loop {
        let done = robot
            .move_distance(0.2, 0.1, false)
            .expect("the move must end with a Done");
        match done.outcome {
            Outcome::Fault(f) if f == Faults::CONTROL_OVERRUN && overruns < 5 => {
                overruns += 1;
                println!("move {overruns}: control overrun (busy host), trying again");
                // Let the overrun age past FAULT_QUIET_US, then clear it.
                telemetry_span(&robot, 2 * pushbot_firmware::FAULT_QUIET_US);
                let left = robot.clear_faults().expect("clear faults");
                assert!(left.is_empty(), "faults left after an overrun: {left:?}");
            }
            _ => break done,
        }
    };
    match done.outcome {
        Outcome::Fault(f) => assert!(
            f.contains(Faults::STALL_LEFT) || f.contains(Faults::STALL_RIGHT),
            "move ended in fault {f:?}, not a stall"
        ),
        other => panic!("move on frozen wheels ended {other:?}, not in the stall fault"),
    }
    let t = robot.wait_telemetry(Some(done.time_us)).expect("telemetry");
    assert_eq!(t.mode, Mode::Faulted);
    // Motion is refused while the fault is latched ...
    let refused = robot.move_distance(0.1, 0.1, false);
    assert!(
        matches!(
            refused,
            Err(LinkError::Refused {
                reason: pushbot::link::Refusal(NackReason::Faulted(_)),
                ..
            })
        ),
        "a move was not refused while faulted: {refused:?}"
    );
    // ... and the stall clears: its cause (the drive) has gone.
    let left = robot.clear_faults().expect("clear faults");
    assert!(
        left.is_empty(),
        "faults still latched after ClearFaults: {left:?}"
    );

    // 5. The host goes quiet: the link watchdog stops the running motion and latches LINK_LOST.
    //    (A control overrun on a busy host is cleared and the check repeated, as in 4.)
    let mut overruns = 0;
    let (motion, done) = loop {
        let motion = robot
            .velocity(0.0, 0.0, Duration::from_secs(20))
            .expect("start a velocity command");
        robot.pause_heartbeats(true);
        let done = robot.wait(&motion).expect("the velocity command must end");
        match done.outcome {
            Outcome::Fault(f) if f == Faults::CONTROL_OVERRUN && overruns < 5 => {
                overruns += 1;
                println!("quiet host {overruns}: control overrun (busy host), trying again");
                robot.pause_heartbeats(false);
                telemetry_span(&robot, 2 * pushbot_firmware::FAULT_QUIET_US);
                let left = robot.clear_faults().expect("clear faults");
                assert!(left.is_empty(), "faults left after an overrun: {left:?}");
            }
            _ => break (motion, done),
        }
    };
    match done.outcome {
        Outcome::Fault(f) => assert!(
            f.contains(Faults::LINK_LOST),
            "quiet host: motion ended in {f:?}, not LINK_LOST"
        ),
        other => panic!("quiet host: motion ended {other:?}, not in LINK_LOST"),
    }
    let t = robot.wait_telemetry(Some(done.time_us)).expect("telemetry");
    assert!(t.faults.contains(Faults::LINK_LOST));
    assert_eq!(t.mode, Mode::Faulted);
    assert_eq!(t.active, None);
    // It took about the watchdog period, not the command's 20 s.
    let took = done
        .time_us
        .saturating_sub(motion.started_us.unwrap_or(done.time_us));
    let limit = 2 * u64::from(LINK_WATCHDOG_MS) * 1000;
    assert!(took < limit, "the link watchdog took {took} us");

    // 6. A new session clears LINK_LOST.
    robot.pause_heartbeats(false);
    robot.reconnect().expect("reconnect");
    let t = robot.wait_telemetry(None).expect("telemetry");
    let t = robot.wait_telemetry(Some(t.time_us)).expect("telemetry");
    assert!(
        !t.faults.contains(Faults::LINK_LOST),
        "LINK_LOST still latched after a new handshake: {:?}",
        t.faults
    );
    assert!(qemu.alive(), "QEMU ended during the test");
}
