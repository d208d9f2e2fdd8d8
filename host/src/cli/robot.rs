//! `pushbot robot …`: talk to the robot over its serial port. Without `--port`, a built-in
//! simulated robot is started and reached through its pty exactly like hardware.

use clap::{Args, Subcommand};
use pushbot_protocol::{Faults, Mode, Outcome, Pose, Telemetry};
use serde_json::{Value, json};

use super::{CliError, CliResult, Global, Status};
use crate::link::{FaultNames, LinkError};
use crate::robot::{DoneReport, Robot};

/// `pushbot robot`: the robot's commands and how to reach it.
#[derive(Args, Debug)]
pub struct RobotArgs {
    /// Serial port of the robot (e.g. /dev/ttyACM0). Without it, a built-in simulated robot is
    /// started and reached through a pseudo-terminal.
    #[arg(long, global = true, value_name = "PATH")]
    pub port: Option<String>,
    /// The world of the built-in simulated robot (preset name or TOML file): its table,
    /// obstacles, objects and the robot's start. Not with `--port`.
    #[arg(
        long,
        global = true,
        value_name = "PRESET|FILE",
        conflicts_with = "port"
    )]
    pub scene: Option<String>,
    /// Pace of the built-in simulated robot against the wall clock (10 = ten times real time).
    #[arg(long, global = true, default_value_t = 10.0, value_name = "X")]
    pub sim_speed: f64,
    /// What to do.
    #[command(subcommand)]
    pub cmd: RobotCmd,
}

/// The robot commands.
#[derive(Subcommand, Debug)]
pub enum RobotCmd {
    /// Firmware, protocol, geometry, mode, faults and odometry.
    Info,
    /// Drive straight for a distance (negative: backwards).
    #[command(allow_negative_numbers = true)]
    Move {
        /// Distance, m.
        #[arg(long)]
        distance: f64,
        /// Cruise speed, m/s.
        #[arg(long, default_value_t = 0.1)]
        speed: f64,
        /// End at the first bumper contact (then `contact` is a success).
        #[arg(long)]
        stop_on_contact: bool,
    },
    /// Turn on the spot (counter-clockwise positive).
    #[command(allow_negative_numbers = true)]
    Spin {
        /// Angle, degrees.
        #[arg(long)]
        angle: f64,
        /// Cruise turn rate, degrees per second.
        #[arg(long, default_value_t = 90.0)]
        rate: f64,
    },
    /// Brake to a stop.
    Stop,
    /// Cut the motors at once and latch the EMERGENCY_STOP fault.
    Estop,
    /// Clear the latched faults whose cause has gone.
    ClearFaults,
}

fn link_error(e: LinkError) -> CliError {
    if e.is_bad_input() {
        CliError::BadInput(e.into())
    } else {
        CliError::Failed(e.into())
    }
}

fn finite(name: &str, v: f64) -> Result<f32, CliError> {
    if v.is_finite() {
        Ok(v as f32)
    } else {
        Err(CliError::bad_input(format!(
            "--{name} must be a finite number, got {v}"
        )))
    }
}

fn positive(name: &str, v: f64) -> Result<f32, CliError> {
    if v.is_finite() && v > 0.0 {
        Ok(v as f32)
    } else {
        Err(CliError::bad_input(format!(
            "--{name} must be a positive number, got {v}"
        )))
    }
}

pub use crate::robot::outcome_name;

fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::Idle => "idle",
        Mode::Velocity => "velocity",
        Mode::Move => "move",
        Mode::Spin => "spin",
        Mode::Advance => "advance",
        Mode::Braking => "braking",
        Mode::Faulted => "faulted",
    }
}

fn pose_json(p: Pose) -> Value {
    json!({ "x_m": p.x, "y_m": p.y, "theta_deg": f64::from(p.theta).to_degrees() })
}

fn pose_text(p: Pose) -> String {
    format!(
        "odometry: x {:+.4} m, y {:+.4} m, heading {:+.2}°",
        p.x,
        p.y,
        f64::from(p.theta).to_degrees()
    )
}

fn faults_json(f: Faults) -> Value {
    json!(FaultNames(f).names())
}

/// The robot's end: a port given, or the built-in simulated robot.
struct Target {
    #[cfg(feature = "sim")]
    sim: Option<crate::sim::SimTarget>,
    path: String,
}

impl Target {
    fn open(args: &RobotArgs, seed: u64) -> Result<Target, CliError> {
        match &args.port {
            Some(p) => Ok(Target {
                #[cfg(feature = "sim")]
                sim: None,
                path: p.clone(),
            }),
            None => Self::built_in(args, seed),
        }
    }

    /// The built-in simulated robot on a pty.
    #[cfg(feature = "sim")]
    fn built_in(args: &RobotArgs, seed: u64) -> Result<Target, CliError> {
        if !(args.sim_speed.is_finite() && args.sim_speed > 0.0) {
            return Err(CliError::bad_input(format!(
                "--sim-speed must be a positive number, got {}",
                args.sim_speed
            )));
        }
        let scene = match &args.scene {
            Some(s) => Some(
                pushbot_world::Scene::preset_or_file(s)
                    .map_err(|e| CliError::bad_input(e.to_string()))?,
            ),
            None => None,
        };
        let sim = crate::sim::SimTarget::start_robot(scene.as_ref(), seed, args.sim_speed)
            .map_err(CliError::Failed)?;
        let path = sim.port().to_string();
        tracing::info!("built-in simulated robot on {path}");
        Ok(Target {
            sim: Some(sim),
            path,
        })
    }

    /// Without the `sim` feature there is no built-in robot: `--port` is needed.
    #[cfg(not(feature = "sim"))]
    fn built_in(_args: &RobotArgs, _seed: u64) -> Result<Target, CliError> {
        Err(crate::cli::no_simulated_target())
    }

    /// Whether the robot is the built-in simulated one.
    fn simulated(&self) -> bool {
        #[cfg(feature = "sim")]
        return self.sim.is_some();
        #[cfg(not(feature = "sim"))]
        false
    }

    fn close(self) {
        #[cfg(feature = "sim")]
        if let Some(sim) = self.sim
            && let Err(e) = sim.shutdown()
        {
            tracing::warn!("the simulated robot stopped with an error: {e:#}");
        }
    }
}

/// Run `pushbot robot …`.
pub fn run(global: &Global, args: RobotArgs) -> CliResult {
    // Check arguments before touching any port.
    let cmd = &args.cmd;
    let parsed = match *cmd {
        RobotCmd::Move {
            distance,
            speed,
            stop_on_contact,
        } => Some((
            finite("distance", distance)?,
            positive("speed", speed)?,
            stop_on_contact,
        )),
        _ => None,
    };
    let spin = match *cmd {
        RobotCmd::Spin { angle, rate } => Some((
            finite("angle", angle)?.to_radians(),
            positive("rate", rate)?.to_radians(),
        )),
        _ => None,
    };
    let target = Target::open(&args, global.seed)?;
    let result = (|| {
        let mut robot = Robot::connect(&target.path, global.link_options()?).map_err(link_error)?;
        let simulated = target.simulated();
        let port_path = robot.path().to_string();
        let base =
            |name: &str| json!({ "command": name, "port": port_path, "simulated": simulated });
        match args.cmd {
            RobotCmd::Info => {
                let info = robot.info().map_err(link_error)?;
                let fw = info.firmware;
                let g = info.geometry;
                let t = info.telemetry;
                if global.json {
                    let mut v = base("info");
                    v["protocol"] = json!(info.protocol);
                    v["firmware"] = json!(format!("{}.{}.{}", fw.major, fw.minor, fw.patch));
                    v["geometry"] = json!({
                        "wheel_base_m": g.wheel_base, "wheel_radius_m": g.wheel_radius,
                        "bumper_radius_m": g.bumper_radius, "encoder_cpr": g.encoder_cpr,
                        "control_hz": g.control_hz,
                    });
                    v["mode"] = json!(mode_name(t.mode));
                    v["faults"] = faults_json(t.faults);
                    v["time_s"] = json!(t.time_us as f64 / 1e6);
                    v["odometry"] = pose_json(t.pose);
                    println!("{v}");
                } else {
                    println!(
                        "robot on {}{}",
                        robot.path(),
                        if simulated {
                            " (built-in simulator)"
                        } else {
                            ""
                        }
                    );
                    println!(
                        "firmware {}.{}.{}, protocol v{}",
                        fw.major, fw.minor, fw.patch, info.protocol
                    );
                    println!(
                        "geometry: wheel base {:.4} m, wheel radius {:.4} m, bumper radius {:.4} m, \
                         {} counts/rev, control {} Hz",
                        g.wheel_base, g.wheel_radius, g.bumper_radius, g.encoder_cpr, g.control_hz
                    );
                    println!(
                        "mode {}, faults {}, robot time {:.3} s",
                        mode_name(t.mode),
                        FaultNames(t.faults),
                        t.time_us as f64 / 1e6
                    );
                    println!("{}", pose_text(t.pose));
                }
                Ok(Status::Success)
            }
            RobotCmd::Move { .. } | RobotCmd::Spin { .. } => {
                use crate::exec::primitive::{Primitive, run_primitive};
                let (name, p, contact_ok) = if let Some((d, s, soc)) = parsed {
                    let p = Primitive::Move {
                        distance: d,
                        speed: s,
                        stop_on_contact: soc,
                    };
                    ("move", p, soc)
                } else if let Some((a, r)) = spin {
                    ("spin", Primitive::Spin { angle: a, rate: r }, false)
                } else {
                    return Err(CliError::bad_input("internal: no motion arguments"));
                };
                let end = run_primitive(&mut robot, p, !global.no_recover).map_err(link_error)?;
                let done: DoneReport = end.done;
                let ok = done.outcome == Outcome::Completed
                    || (contact_ok && done.outcome == Outcome::Contact);
                if global.json {
                    let mut v = base(name);
                    v["outcome"] = json!(outcome_name(done.outcome));
                    v["success"] = json!(ok);
                    v["seq"] = json!(done.seq);
                    v["duration_s"] = json!(done.duration_s);
                    v["time_s"] = json!(done.time_us as f64 / 1e6);
                    v["odometry"] = pose_json(done.pose);
                    v["recoveries"] = json!(end.recoveries);
                    println!("{v}");
                } else {
                    println!(
                        "{name}: {} after {:.3} s of robot time",
                        outcome_name(done.outcome),
                        done.duration_s
                    );
                    println!("{}", pose_text(done.pose));
                    for r in &end.recoveries {
                        println!(
                            "link recovered at robot time {:.1} s ({}); the rest was sent anew",
                            r.robot_time_s, r.cause
                        );
                    }
                }
                Ok(if ok {
                    Status::Success
                } else {
                    Status::TaskFailed
                })
            }
            RobotCmd::Stop | RobotCmd::Estop | RobotCmd::ClearFaults => {
                let (name, t): (&str, Telemetry) = match args.cmd {
                    RobotCmd::Stop => ("stop", robot.stop().map_err(link_error)?),
                    RobotCmd::Estop => ("estop", robot.emergency_stop().map_err(link_error)?),
                    _ => {
                        let at = robot.telemetry().map(|t| t.time_us);
                        robot.clear_faults().map_err(link_error)?;
                        (
                            "clear-faults",
                            robot.wait_telemetry(at).map_err(link_error)?,
                        )
                    }
                };
                let ok = match name {
                    "clear-faults" => t.faults.is_empty(),
                    _ => true,
                };
                if global.json {
                    let mut v = base(name);
                    v["success"] = json!(ok);
                    v["mode"] = json!(mode_name(t.mode));
                    v["faults"] = faults_json(t.faults);
                    v["time_s"] = json!(t.time_us as f64 / 1e6);
                    v["odometry"] = pose_json(t.pose);
                    println!("{v}");
                } else {
                    println!(
                        "{name}: mode {}, faults {}",
                        mode_name(t.mode),
                        FaultNames(t.faults)
                    );
                    if !ok {
                        println!("faults remain latched: their cause has not gone");
                    }
                    println!("{}", pose_text(t.pose));
                }
                Ok(if ok {
                    Status::Success
                } else {
                    Status::TaskFailed
                })
            }
        }
    })();
    target.close();
    result
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;
    use crate::cli::{Cli, Command};

    fn parse(args: &[&str]) -> RobotArgs {
        let mut argv = vec!["pushbot", "robot"];
        argv.extend_from_slice(args);
        // Other commands join `Command` over time.
        #[allow(unreachable_patterns)]
        match Cli::try_parse_from(argv).unwrap().command {
            Command::Robot(r) => r,
            _ => unreachable!("parsed as a robot command"),
        }
    }

    #[test]
    fn negative_values_and_port_parse() {
        let r = parse(&["move", "--distance", "-0.25", "--port", "/dev/ttyACM0"]);
        assert_eq!(r.port.as_deref(), Some("/dev/ttyACM0"));
        assert!(
            matches!(r.cmd, RobotCmd::Move { distance, speed, stop_on_contact: false }
            if distance == -0.25 && speed == 0.1)
        );
        let r = parse(&["--port", "/dev/x", "spin", "--angle", "-90", "--rate", "45"]);
        assert!(matches!(r.cmd, RobotCmd::Spin { angle, rate } if angle == -90.0 && rate == 45.0));
        assert_eq!(r.sim_speed, 10.0);
        assert!(matches!(
            parse(&["clear-faults"]).cmd,
            RobotCmd::ClearFaults
        ));
        assert!(matches!(parse(&["estop"]).cmd, RobotCmd::Estop));
    }

    #[test]
    fn outcome_names_name_the_faults() {
        assert_eq!(outcome_name(Outcome::Completed), "completed");
        assert_eq!(
            outcome_name(Outcome::Fault(Faults::STALL_RIGHT)),
            "fault (STALL_RIGHT)"
        );
    }
}
