//! `pushbot-sim`: the simulated robot on a pseudo-terminal.
//!
//! Prints one JSON line first — `{"serial": "/dev/pts/N", …, "camera": "127.0.0.1:PORT", …}` —
//! then runs until its standard input closes (or it is killed). A host opens the `serial` path
//! as it would a real robot's port, and the `camera` socket as its overhead camera.
#![forbid(unsafe_code)]

use std::io::{Read, Write};
use std::path::PathBuf;

use serde::Serialize;
use std::sync::mpsc;
use std::time::Duration;

use anyhow::{Context, Result};
use clap::Parser;
use pushbot_sim::faults::FaultArgs;
use pushbot_sim::pushing::Slider;
use pushbot_sim::{Pose, PtySim, Scene, SimOptions};

/// The simulated pushbot robot, served on a pseudo-terminal.
#[derive(Parser, Debug)]
#[command(
    version,
    about,
    after_help = "Examples:\n  pushbot-sim --seed 3 --speed 5 --truth-log truth.jsonl\n  pushbot-sim --scene lau-irregular --frames frames/ --no-stdin"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Sub>,
    /// More log output on stderr: the firmware's own log (-v warnings, -vv info, -vvv debug).
    /// `PUSHBOT_LOG=<filter>` overrides it, as for `pushbot`.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
    /// JSON output: `replay` prints one JSON object instead of CSV lines, and an error is one
    /// JSON object on stdout, `{"error": {"kind", "message", "exit_code"}}`, as `pushbot --json`
    /// prints them (the simulator's first line is JSON anyway).
    #[arg(long, global = true)]
    json: bool,
    /// A scene: a preset name (see `pushbot-sim presets`) or a TOML file. Its table, obstacles,
    /// objects and robot replace --table and --start.
    #[arg(long, value_name = "PRESET|FILE")]
    scene: Option<String>,
    /// Seed of all simulated noise: the same seed and the same host bytes give the same run.
    /// Global, like `--json` and `-v`: `pushbot-sim bench --seed 3` is `pushbot-sim --seed 3
    /// bench`.
    #[arg(long, default_value_t = 0, global = true)]
    seed: u64,
    /// Simulated seconds per wall-clock second: 1 = real time, 20 = twenty times faster,
    /// 0 = as fast as possible (unpaced; the host must then not rely on wall-clock timing).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    speed: f64,
    /// Write the true pose as JSON lines {"t", "x", "y", "theta", "duty", "bumper"} to FILE.
    #[arg(long, value_name = "FILE")]
    truth_log: Option<PathBuf>,
    /// Rate of the truth log, Hz of simulated time.
    #[arg(long, default_value_t = 100.0, value_name = "HZ")]
    truth_hz: f64,
    /// Table width (x) and height (y), metres; origin at the lower-left corner.
    #[arg(long, num_args = 2, value_names = ["WIDTH", "HEIGHT"], default_values_t = [1.2, 0.9])]
    table: Vec<f64>,
    /// The robot's true start pose: x and y in metres, heading in degrees (default: the table's
    /// centre, facing +x).
    #[arg(long, num_args = 3, value_names = ["X", "Y", "HEADING_DEG"], allow_negative_numbers = true)]
    start: Option<Vec<f64>>,
    /// Link faults.
    #[command(flatten)]
    faults: FaultArgs,
    /// Keep a symlink at PATH to the robot's pty (as udev keeps `/dev/serial/by-id/…`): hosts
    /// open PATH, which outlives unplugs. The first line's `serial` is then PATH.
    #[arg(long, value_name = "PATH")]
    link: Option<PathBuf>,
    /// Unplug the port at this simulated time, s (repeatable): the pty closes under the host
    /// and PATH vanishes, then a new pty is served behind PATH (a USB re-enumeration).
    #[arg(long, value_name = "S", requires = "link")]
    unplug_at: Vec<f64>,
    /// How long each unplug lasts, s of simulated time.
    #[arg(long, value_name = "S", default_value_t = 1.0, requires = "unplug_at")]
    unplug_for: f64,
    /// Move an object by hand mid-run (repeatable): `AT:OBJECT:DX:DY[:DTHETA_DEG]` — at AT
    /// seconds of simulated time, put OBJECT down DX, DY metres (and DTHETA degrees) from where
    /// it is, e.g. `--disturb 40:box1:0.1:0`.
    #[arg(long, value_name = "AT:OBJECT:DX:DY")]
    disturb: Vec<pushbot_sim::sim::Disturbance>,
    /// Run until killed instead of until standard input closes.
    #[arg(long)]
    no_stdin: bool,
    /// Serve the overhead camera on this address (`HOST:PORT`; port 0 picks a free one). Its
    /// address is the first line's `camera`: a host opens `--camera sim:HOST:PORT`.
    #[arg(long, value_name = "HOST:PORT", default_value = "127.0.0.1:0")]
    camera: String,
    /// Do not run the camera.
    #[arg(long, conflicts_with = "frames")]
    no_camera: bool,
    /// Also write every camera frame to DIR as `frame-NNNNNN.png` with its ground truth
    /// `frame-NNNNNN.json` (markers' table poses and pixel corners).
    #[arg(long, value_name = "DIR")]
    frames: Option<PathBuf>,
}

/// The first line on stdout, in this key order.
#[derive(Serialize)]
struct FirstLine<'a> {
    /// Path of the robot's serial port (the pty slave).
    serial: &'a str,
    seed: u64,
    speed: f64,
    /// Width, height, m.
    table: [f64; 2],
    /// True start pose, table frame (heading in radians).
    start: Pose,
    /// Firmware control period = physics step, µs of simulated time.
    tick_us: u32,
    truth_log: Option<&'a std::path::Path>,
    /// The scene's name, if a scene was given.
    scene: Option<&'a str>,
    /// Object ids, in the order of the truth log's `objects`.
    objects: Vec<&'a str>,
    /// Whether link faults are injected.
    faults: bool,
    /// The camera's socket (`HOST:PORT`), absent with --no-camera.
    camera: Option<String>,
    pid: u32,
}

/// Other things the binary does.
#[derive(clap::Subcommand, Debug)]
enum Sub {
    /// Drive a recorded pusher trajectory against one object of a scene and print the object's
    /// simulated trajectory (quasi-static pushing, no robot dynamics).
    #[command(
        after_help = "Example:\n  pushbot-sim replay --scene lynch-mason-fig12 --object slider --pusher pusher.csv --json"
    )]
    Replay {
        /// Scene: preset name or TOML file.
        #[arg(long, value_name = "PRESET|FILE")]
        scene: String,
        /// The object's id in the scene.
        #[arg(long)]
        object: String,
        /// CSV: time s, pusher x m, y m, θ rad (a header line is allowed); the pusher is a disc
        /// of the scene robot's bumper radius.
        #[arg(long, value_name = "FILE.csv")]
        pusher: PathBuf,
    },
    /// List the built-in scene presets.
    #[command(after_help = "Example:\n  pushbot-sim presets")]
    Presets,
    /// Measure how fast the in-process simulation runs (robot + firmware + a scene's objects,
    /// the robot driving and pushing), and print one JSON object.
    #[command(
        after_help = "Example:\n  pushbot-sim bench --scene three-boxes --seconds 30 --seed 3"
    )]
    Bench {
        /// Scene: preset name or TOML file.
        #[arg(long, default_value = "three-boxes")]
        scene: String,
        /// Simulated seconds to run.
        #[arg(long, default_value_t = 60.0)]
        seconds: f64,
    },
}

/// Input the simulator refuses (flags, scene files, pusher files, a start off the table):
/// exit code 2, as `pushbot` gives; anything that fails later exits 1.
#[derive(Debug)]
struct BadInput(String);

impl std::fmt::Display for BadInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

/// `bail!` for bad input.
macro_rules! bad_input {
    ($($t:tt)*) => {
        return Err(BadInput(format!($($t)*)).into())
    };
}

/// Parse the command line: the global flags (`-v`, `--json`, `--seed`) go before or after a
/// subcommand, as for `pushbot`; the simulator's own flags only without a subcommand.
fn parse_cli() -> Cli {
    use clap::{CommandFactory, FromArgMatches, parser::ValueSource};
    let mut cmd = Cli::command();
    let m = cmd.get_matches_mut();
    if let Some(sub) = m.subcommand_name() {
        let stray = cmd.get_arguments().find(|a| {
            !a.is_global_set()
                && m.value_source(a.get_id().as_str()) == Some(ValueSource::CommandLine)
        });
        if let Some(a) = stray {
            let name = a.get_long().unwrap_or(a.get_id().as_str()).to_string();
            cmd.error(
                clap::error::ErrorKind::ArgumentConflict,
                format!("--{name} runs the simulator; it cannot be used with `{sub}`"),
            )
            .exit();
        }
    }
    Cli::from_arg_matches(&m).unwrap_or_else(|e| e.exit())
}

fn main() {
    // The Rust runtime ignores SIGPIPE, so `println!` into a closed pipe would panic; with the
    // default back, `pushbot-sim presets | head -1` ends quietly. The camera socket is written
    // with MSG_NOSIGNAL by std and the pty gives EIO, so neither can raise the signal.
    sigpipe::reset();
    let cli = parse_cli();
    init_logging(cli.verbose);
    let json = cli.json;
    let result = match cli.command {
        Some(Sub::Replay {
            ref scene,
            ref object,
            ref pusher,
        }) => replay(scene, object, pusher, json),
        Some(Sub::Bench { ref scene, seconds }) => bench(scene, seconds, cli.seed),
        Some(Sub::Presets) => {
            for name in pushbot_sim::scene::PRESETS {
                println!("{name}");
            }
            Ok(())
        }
        None => run(cli),
    };
    if let Err(e) = result {
        let bad = e.downcast_ref::<BadInput>().is_some()
            || e.downcast_ref::<pushbot_sim::scene::SceneError>().is_some();
        let code = if bad { 2 } else { 1 };
        if json {
            let v = serde_json::json!({"error": {
                "kind": if bad { "bad_input" } else { "failed" },
                "message": format!("{e:#}"),
                "exit_code": code,
            }});
            println!("{v}");
        } else {
            eprintln!("pushbot-sim: {e:#}");
        }
        std::process::exit(code);
    }
}

/// Log to stderr: nothing by default, the firmware's warnings with -v, info -vv, debug -vvv.
fn init_logging(verbose: u8) {
    let level = match verbose {
        0 => "off",
        1 => "warn",
        2 => "info",
        3 => "debug",
        _ => "trace",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_env("PUSHBOT_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
}

fn run(cli: Cli) -> Result<()> {
    let [width, height] = cli.table[..] else {
        bad_input!("--table takes a width and a height");
    };
    let start = match cli.start.as_deref() {
        None => Pose::new(width / 2.0, height / 2.0, 0.0),
        Some(&[x, y, deg]) => Pose::new(x, y, deg.to_radians()),
        Some(_) => bad_input!("--start takes x, y and a heading"),
    };
    let scene = match &cli.scene {
        Some(s) => Some(Scene::preset_or_file(s)?),
        None => None,
    };
    let (width, height, start) = match &scene {
        Some(s) => (s.table.width, s.table.height, s.robot.start),
        None => (width, height, start),
    };
    let faults = cli.faults.link_faults().map_err(BadInput)?;
    let secs = |name: &str, s: f64| -> Result<u64> {
        if s.is_finite() && (0.0..1e9).contains(&s) {
            Ok((s * 1e6) as u64)
        } else {
            bad_input!("--{name} must be a time in seconds ≥ 0, not {s}")
        }
    };
    let unplug_for = secs("unplug-for", cli.unplug_for)?;
    let unplugs = cli
        .unplug_at
        .iter()
        .map(|&at| {
            Ok(pushbot_sim::plug::Unplug {
                at_us: secs("unplug-at", at)?,
                for_us: unplug_for,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    if let Some(d) = cli.disturb.iter().find(|d| {
        !scene
            .as_ref()
            .is_some_and(|s| s.objects.iter().any(|o| o.id == d.object))
    }) {
        bad_input!("--disturb: the scene has no object {:?} to move", d.object);
    }
    let opts = SimOptions {
        faults,
        link: cli.link.clone(),
        unplugs,
        disturbances: cli.disturb.clone(),
        scene: scene.clone(),
        seed: cli.seed,
        speed: cli.speed,
        truth_log: cli.truth_log.clone(),
        truth_hz: cli.truth_hz,
        start,
        table: (width, height),
        camera: (!cli.no_camera).then(|| pushbot_sim::camera::live::LiveCameraOptions {
            addr: cli.camera.clone(),
            frames_dir: cli.frames.clone(),
        }),
        ..SimOptions::default()
    };
    // Before anything runs, a refusal is of the options given.
    let sim = PtySim::start(opts.clone()).map_err(|e| BadInput(format!("{e:#}")))?;
    let first = FirstLine {
        serial: sim.serial_path(),
        seed: opts.seed,
        speed: opts.speed,
        table: [width, height],
        start,
        tick_us: opts.robot.tick_period_us(),
        truth_log: opts.truth_log.as_deref(),
        scene: scene.as_ref().map(|s| s.name.as_str()),
        objects: scene
            .as_ref()
            .map(|s| s.objects.iter().map(|o| o.id.as_str()).collect())
            .unwrap_or_default(),
        faults: opts.faults.is_some(),
        camera: sim.camera_addr().map(|a| a.to_string()),
        pid: std::process::id(),
    };
    {
        let mut out = std::io::stdout().lock();
        serde_json::to_writer(&mut out, &first).context("writing to stdout")?;
        writeln!(out).context("writing to stdout")?;
        out.flush().context("writing to stdout")?;
    }

    let (eof_tx, eof_rx) = mpsc::channel::<()>();
    if !cli.no_stdin {
        std::thread::spawn(move || {
            let mut stdin = std::io::stdin().lock();
            let mut buf = [0u8; 256];
            // Anything typed is ignored; end of input (or an error) ends the run.
            while matches!(stdin.read(&mut buf), Ok(n) if n > 0) {}
            let _ = eof_tx.send(());
        });
    }
    loop {
        match eof_rx.recv_timeout(Duration::from_millis(100)) {
            Ok(()) => break,
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            // With --no-stdin the sender is gone at once: run until killed.
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                std::thread::sleep(Duration::from_millis(100))
            }
        }
        if !sim.is_running() {
            break;
        }
    }
    sim.shutdown()
}

/// One row of a replayed trajectory.
#[derive(Serialize)]
struct ReplayRow {
    t: f64,
    x: f64,
    y: f64,
    theta: f64,
    /// How the pusher touched the object on the way to this row (`none` if it did not).
    contact: &'static str,
}

fn replay(scene: &str, object: &str, pusher: &std::path::Path, json: bool) -> Result<()> {
    let scene = Scene::preset_or_file(scene)?;
    let obj = scene.object(object).with_context(|| {
        let ids: Vec<&str> = scene.objects.iter().map(|o| o.id.as_str()).collect();
        format!(
            "no object {object:?} in the scene (it has: {})",
            ids.join(", ")
        )
    })?;
    let mut slider = Slider::from_object(obj);
    let radius = scene.robot.bumper_radius;
    let text =
        std::fs::read_to_string(pusher).with_context(|| format!("reading {}", pusher.display()))?;
    let mut samples: Vec<[f64; 4]> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let parsed: Option<Vec<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
        match parsed {
            Some(v) if v.len() == 4 && v.iter().all(|x| x.is_finite()) => {
                samples.push([v[0], v[1], v[2], v[3]]);
            }
            // A header on the first line.
            None if samples.is_empty() && i == 0 => {}
            _ => bad_input!(
                "{}:{}: expected 4 numbers: time s, x m, y m, theta rad",
                pusher.display(),
                i + 1
            ),
        }
    }
    if samples.is_empty() {
        bad_input!("{}: no samples", pusher.display());
    }
    if samples.windows(2).any(|w| w[1][0] < w[0][0]) {
        bad_input!("{}: time must not decrease", pusher.display());
    }
    let first = samples[0];
    if slider.gap([first[1], first[2]], radius) < -1e-9 {
        bad_input!("the pusher starts inside object {object:?}");
    }
    let mut rows = Vec::with_capacity(samples.len());
    let mut prev = first;
    for s in &samples {
        let mode = slider.push([prev[1], prev[2]], [s[1], s[2]], radius, 5e-4);
        prev = *s;
        rows.push(ReplayRow {
            t: s[0],
            x: slider.pose.x,
            y: slider.pose.y,
            theta: slider.pose.theta,
            contact: match mode {
                None => "none",
                Some(pushbot_sim::pushing::ContactMode::Separating) => "separating",
                Some(pushbot_sim::pushing::ContactMode::Sticking) => "sticking",
                Some(pushbot_sim::pushing::ContactMode::Sliding) => "sliding",
            },
        });
    }
    let mut out = std::io::stdout().lock();
    if json {
        let doc = serde_json::json!({
            "scene": scene.name,
            "object": object,
            "pusher_radius": radius,
            "cof": slider.cof,
            "c": slider.c,
            "trajectory": rows,
        });
        serde_json::to_writer(&mut out, &doc).context("writing to stdout")?;
        writeln!(out).context("writing to stdout")?;
    } else {
        writeln!(out, "t,x,y,theta,contact").context("writing to stdout")?;
        for r in &rows {
            writeln!(out, "{},{},{},{},{}", r.t, r.x, r.y, r.theta, r.contact)
                .context("writing to stdout")?;
        }
    }
    Ok(())
}

fn bench(scene: &str, seconds: f64, seed: u64) -> Result<()> {
    use pushbot_protocol::{Command, HostFrame, MAX_FRAME, PROTOCOL_VERSION, encode_frame};
    if !(seconds.is_finite() && seconds > 0.0) {
        bad_input!("--seconds must be positive");
    }
    let scene = Scene::preset_or_file(scene)?;
    let objects = scene.objects.len();
    let mut sim = pushbot_sim::Sim::new(&SimOptions {
        scene: Some(scene),
        seed,
        ..SimOptions::default()
    })?;
    let mut buf = [0u8; MAX_FRAME];
    let mut send = |sim: &mut pushbot_sim::Sim, seq: u16, cmd: Command| -> Result<()> {
        let n = encode_frame(&HostFrame { seq, cmd }, &mut buf)
            .map_err(|e| anyhow::anyhow!("framing: {e}"))?;
        sim.receive(&buf[..n]);
        Ok(())
    };
    send(
        &mut sim,
        1,
        Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    )?;
    let mut out = Vec::new();
    let start = std::time::Instant::now();
    let end_us = (seconds * 1e6) as u64;
    let mut seq = 2u16;
    while sim.now_us() < end_us {
        let t = sim.now_us();
        if t.is_multiple_of(50_000) {
            send(&mut sim, 0, Command::Heartbeat)?;
        }
        if t.is_multiple_of(2_000_000) {
            // Alternate: drive ahead (pushing), then turn, then back off.
            let (v, omega) = match (t / 2_000_000) % 3 {
                0 => (0.15, 0.0),
                1 => (0.0, 2.0),
                _ => (-0.1, 0.5),
            };
            send(&mut sim, seq, Command::ClearFaults)?;
            send(
                &mut sim,
                seq.wrapping_add(1),
                Command::Velocity {
                    v,
                    omega,
                    timeout_ms: 2500,
                },
            )?;
            seq = seq.wrapping_add(2).max(2);
        }
        sim.tick();
        out.clear();
        sim.transmit(&mut out);
    }
    let wall = start.elapsed().as_secs_f64();
    let sim_s = sim.now_us() as f64 / 1e6;
    let doc = serde_json::json!({
        "objects": objects,
        "sim_s": sim_s,
        "wall_s": wall,
        "realtime_factor": sim_s / wall,
        "ticks_per_s": sim_s * 1e6 / f64::from(sim.tick_us()) / wall,
        "final_pose": sim.truth().pose,
        "object_poses": sim.object_poses(),
    });
    println!("{doc}");
    Ok(())
}
