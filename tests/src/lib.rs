//! Hardware-in-the-loop tests live in `tests/`: the real host link ([`pushbot::link`],
//! [`pushbot::robot`]) against the simulated robot ([`pushbot_sim::PtySim`]) over a real
//! pseudo-terminal, judged by the simulator's ground truth. This library holds their shared
//! set-up.

use std::time::{Duration, Instant};

use pushbot::robot::{LinkOptions, Robot};
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

/// Connect the host link to the simulated robot, through its pty path like to hardware, with
/// the robot's link watchdog at the longest the firmware takes, 5 s of robot time (1 s of wall
/// time at [`SIM_SPEED`]): these tests share two cores with builds and with each other, and a
/// test of motion must not fail because the host's threads waited for a core. At 1 s of robot
/// time (200 ms of wall time) it did, once in many runs: a square's third leg ended on the
/// watchdog while the tests ran two at a time. The watchdog's own tests use [`connect_strict`].
pub fn connect(sim: &PtySim) -> Robot {
    let robot = connect_strict(sim);
    robot
        .configure(pushbot_protocol::ConfigUpdate {
            watchdog_ms: Some(pushbot_firmware::RobotParams::default().max_watchdog_ms),
            ..Default::default()
        })
        .expect("configure the link watchdog");
    robot
}

/// Connect as [`connect`] does, leaving the robot's link watchdog at the firmware's default.
pub fn connect_strict(sim: &PtySim) -> Robot {
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

/// The path of a binary of this workspace (`pushbot`, `pushbot-sim`), built first if needed.
///
/// `cargo test -p pushbot-tests` builds this package's dependencies as libraries only, so the
/// binaries are brought up to date here (once per test process) with the cargo that runs the
/// tests, into the same target directory and profile as the test itself, by
/// `cargo test --workspace --no-run`: `pushbot` and `pushbot-sim` have integration tests of
/// their own, so that command builds both binaries, with the features resolved as
/// `cargo test --workspace` resolves them. After that command has run, nothing is compiled again.
/// (`cargo build` resolves them without the dev-dependencies, for example `serde` without
/// `alloc`, and compiled every workspace crate a second time: 2–4 minutes in CI.)
pub fn bin(name: &str) -> std::path::PathBuf {
    use std::sync::Mutex;
    static BUILT: Mutex<bool> = Mutex::new(false);
    let exe = std::env::current_exe().expect("the test's own path");
    // target/<profile>/deps/<test>-<hash>
    let dir = exe
        .parent()
        .and_then(|d| d.parent())
        .expect("the test runs from target/<profile>/deps")
        .to_path_buf();
    assert!(
        matches!(name, "pushbot" | "pushbot-sim"),
        "no binary {name} in this workspace"
    );
    let path = dir.join(name);
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if !*built {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let mut cmd = std::process::Command::new(cargo);
        cmd.args(["test", "--quiet", "--workspace", "--no-run"]);
        // The variables the outer cargo sets for this test process describe this package, not
        // the build: build scripts that watch them (ring's watches `CARGO_PKG_NAME` and
        // `CARGO_MANIFEST_DIR`) would run again, and every crate above them be compiled again,
        // once here and once more in the next plain `cargo test` (minutes in CI).
        for (key, _) in std::env::vars_os() {
            if key.to_str().is_some_and(set_by_cargo_for_a_crate) {
                cmd.env_remove(key);
            }
        }
        // target/release holds `cargo test --release`'s build.
        if dir.file_name().is_some_and(|p| p == "release") {
            cmd.arg("--release");
        }
        // Build where the test was built.
        if let Some(target) = dir.parent() {
            cmd.env("CARGO_TARGET_DIR", target);
        }
        let out = cmd
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("run cargo test --no-run");
        assert!(
            out.status.success(),
            "cargo test --workspace --no-run failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        *built = true;
    }
    assert!(path.exists(), "{} was not built", path.display());
    path
}

/// Whether cargo sets the environment variable `key` for the crate it builds or runs (its
/// package's name, version and folders), as opposed to a setting of the build itself.
fn set_by_cargo_for_a_crate(key: &str) -> bool {
    key.starts_with("CARGO_PKG_")
        || key.starts_with("CARGO_BIN_EXE_")
        || matches!(
            key,
            "OUT_DIR"
                | "CARGO_MANIFEST_DIR"
                | "CARGO_MANIFEST_PATH"
                | "CARGO_MANIFEST_LINKS"
                | "CARGO_CRATE_NAME"
                | "CARGO_BIN_NAME"
                | "CARGO_PRIMARY_PACKAGE"
                | "CARGO_TARGET_TMPDIR"
                | "CARGO_RUSTC_CURRENT_DIR"
        )
}

/// What a run of a binary gave: exit code (`None`: killed by a signal), stdout, stderr.
#[derive(Debug)]
pub struct Run {
    /// Exit code; `None` if a signal ended the process.
    pub code: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

/// Run a workspace binary with `args` (standard input closed) and collect what it gave.
pub fn run_bin(name: &str, args: &[&str]) -> Run {
    let out = std::process::Command::new(bin(name))
        .args(args)
        .stdin(std::process::Stdio::null())
        .env_remove("PUSHBOT_LOG")
        .output()
        .expect("start the binary");
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Send the host's and the simulator's logs to the test's output (shown when a test fails, or
/// always with `--nocapture`), filtered by `PUSHBOT_LOG` as for `pushbot` (default: warnings).
pub fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_env("PUSHBOT_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn,pushbot_firmware=error"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_test_writer()
        .try_init();
}

/// A wall-clock limit on a whole test: if the test is still running when it passes, the test
/// process prints `what` and ends with a failure, so a run that stopped making progress fails
/// in minutes instead of holding up the suite. Dropping the guard disarms it.
#[derive(Debug)]
pub struct WallLimit {
    done: std::sync::Arc<(std::sync::Mutex<bool>, std::sync::Condvar)>,
}

impl WallLimit {
    /// Arm a limit of `limit` wall time for the test `what`.
    pub fn arm(what: &str, limit: Duration) -> WallLimit {
        let done = std::sync::Arc::new((std::sync::Mutex::new(false), std::sync::Condvar::new()));
        let flag = done.clone();
        let what = what.to_owned();
        std::thread::spawn(move || {
            let (lock, cv) = &*flag;
            let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
            let (guard, _) = cv
                .wait_timeout_while(guard, limit, |d| !*d)
                .unwrap_or_else(|e| e.into_inner());
            if !*guard {
                use std::io::Write;
                let _ = writeln!(
                    std::io::stderr(),
                    "{what}: still running after {:.0} s of wall time; ending the test process \
                     (rerun with PUSHBOT_LOG=pushbot=debug --nocapture to see where it was)",
                    limit.as_secs_f64()
                );
                std::process::exit(101);
            }
        });
        WallLimit { done }
    }
}

impl Drop for WallLimit {
    fn drop(&mut self) {
        let (lock, cv) = &*self.done;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cv.notify_all();
    }
}
