//! `pushbot scene …`: check a scene file in the shared format (`pushbot_world::scene`) before
//! handing it to a command, and list the built-in presets. `check` also says what the loader
//! normalised (a clockwise outline stored counter-clockwise), as `note:` lines or `notes`.

use clap::{Args, Subcommand};
use serde_json::json;

use super::{CliError, CliResult, Global, Status};

/// `pushbot scene`.
#[derive(Subcommand, Debug)]
pub enum SceneCommand {
    /// Parse and check a scene (preset name or TOML file); errors name the file, the line and
    /// column, and the field.
    Check(CheckArgs),
    /// List the built-in presets, by the commands that take them.
    List,
}

/// `pushbot scene check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// The scene: a preset name or a TOML file.
    #[arg(long, value_name = "PRESET|FILE")]
    pub scene: String,
}

/// Run `pushbot scene …`.
pub fn run(g: &Global, cmd: SceneCommand) -> CliResult {
    match cmd {
        SceneCommand::Check(a) => {
            let (s, notes) = pushbot_world::Scene::preset_or_file_noted(&a.scene)
                .map_err(|e| CliError::bad_input(e.to_string()))?;
            let notes: Vec<String> = notes.iter().map(|n| n.to_string()).collect();
            let ids: Vec<&str> = s.objects.iter().map(|o| o.id.as_str()).collect();
            if g.json {
                let v = json!({
                    "scene": a.scene, "name": s.name, "table": [s.table.width, s.table.height],
                    "obstacles": s.obstacles.len(), "objects": ids, "goals": s.goals.len(),
                    "positions": s.positions.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(),
                    "notes": notes,
                });
                println!("{v}");
            } else {
                for n in &notes {
                    println!("note: {n}");
                }
                println!(
                    "{}: ok — `{}`, table {} × {} m, {} obstacles, objects [{}], {} goals, {} named positions",
                    a.scene,
                    s.name,
                    s.table.width,
                    s.table.height,
                    s.obstacles.len(),
                    ids.join(", "),
                    s.goals.len(),
                    s.positions.len()
                );
            }
            Ok(Status::Success)
        }
        SceneCommand::List => {
            let shared = pushbot_world::scene::PRESETS;
            let rearrange: Vec<&str> = crate::planner::rearrange::cases::CASES
                .iter()
                .map(|c| c.0)
                .collect();
            let stable = crate::planner::stable::presets::PRESETS;
            if g.json {
                let v = json!({"scenes": shared, "rearrange": rearrange, "stable": stable});
                println!("{v}");
            } else {
                println!(
                    "scenes (robot, collect, eval, calibrate, track, scene check, pushbot-sim):"
                );
                for n in shared {
                    println!("  {n}");
                }
                println!(
                    "rearrangement cases (plan rearrange): {}",
                    rearrange.join(" ")
                );
                println!(
                    "stable-pushing presets (mechanics, plan stable): {}",
                    stable.join(" ")
                );
            }
            Ok(Status::Success)
        }
    }
}
