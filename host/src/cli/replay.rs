//! `pushbot replay FILE.mcap`: re-run tracking from a recording and write its report; prints
//! how far the replayed poses are from the recorded ones (the same frames through the same
//! pipeline: they should agree to far below a tenth of a millimetre).

use std::path::PathBuf;

use clap::Args;

use super::{CliError, CliResult, Global, Status};
use crate::recording::{reader, replay};

/// Poses farther apart than this, m, make the replay disagree with the live run (exit 1).
pub const TOLERANCE_M: f64 = 1e-4;

/// `pushbot replay`.
#[derive(Args, Debug, Clone)]
pub struct ReplayArgs {
    /// The recording (`pushbot demo` writes OUT/run.mcap; `--record FILE` elsewhere).
    #[arg(value_name = "FILE.mcap")]
    pub file: PathBuf,
    /// Folder for the replay's report (default: FILE's folder, `replay/`).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Run `pushbot replay`.
pub fn run(g: &Global, args: ReplayArgs) -> CliResult {
    let contents = reader::read(&args.file).map_err(CliError::BadInput)?;
    let rep = replay::replay(&contents).map_err(CliError::BadInput)?;
    let out = args.out.clone().unwrap_or_else(|| {
        args.file
            .parent()
            .map_or_else(|| PathBuf::from("replay"), |d| d.join("replay"))
    });
    let page = crate::recording::report::write(&rep, &out, &args.file)?;
    let agree = rep.max_diff_m <= TOLERANCE_M;
    if g.json {
        let v = serde_json::json!({
            "recording": args.file,
            "report": page,
            "agree": agree,
            "frames": rep.frames,
            "max_diff_m": rep.max_diff_m,
            "max_diff_rad": rep.max_diff_rad,
            "cut": rep.cut,
            "sessions": rep.sessions,
        });
        println!("{v}");
    } else {
        for s in &rep.sessions {
            println!(
                "session {} {:12} {:5} frames, largest difference {:.6} mm",
                s.session,
                s.label,
                s.frames,
                s.max_diff_m * 1e3
            );
        }
        if let Some(c) = &rep.cut {
            println!("note: {c}");
        }
        println!("report: {}", page.display());
    }
    if agree {
        Ok(Status::Success)
    } else {
        Ok(super::task_failed(
            g,
            &format!(
                "the replayed poses differ from the recorded ones by up to {:.3} mm",
                rep.max_diff_m * 1e3
            ),
        ))
    }
}
