//! `pushbot calibrate lens` (the camera's intrinsics and lens distortion from frames of a printed
//! board, [`crate::vision::lens_calib`]) and `pushbot calibrate board` (the printable board and
//! its layout file); `pushbot calibrate` without a subcommand calibrates the table
//! ([`super::vision::calibrate`]).

use std::path::PathBuf;

use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pushbot_world::board::BoardLayout;
use pushbot_world::lens_file::{LensFormat, write_intrinsics};

use super::{CliError, CliResult, Global, Status, vision};
use crate::vision::detect::{DetectorKind, make_detector};
use crate::vision::folder::FolderSource;
use crate::vision::frame::FrameSource;
use crate::vision::lens_calib::{BoardViews, LensFit, Requirements};

/// `pushbot calibrate`: the table (its flags), or `lens` / `board`.
#[derive(Args, Debug, Clone)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct CalibrateCommand {
    /// Calibrate the lens, or write the board to print.
    #[command(subcommand)]
    pub what: Option<CalibrateWhat>,
    /// Calibrate the table (no subcommand).
    #[command(flatten)]
    pub table: vision::CalibrateArgs,
}

/// `pushbot calibrate lens|board`.
#[derive(Subcommand, Debug, Clone)]
pub enum CalibrateWhat {
    /// The camera's intrinsics and lens distortion from frames of a printed AprilTag board
    /// (`calibrate board`): Zhang's method refined by Levenberg–Marquardt; writes a ROS or
    /// OpenCV intrinsics file for `--intrinsics`. Refuses (exit 1) a poor fit.
    Lens(LensArgs),
    /// Write the printable AprilTag calibration board (SVG at true size) and its layout file.
    Board(BoardArgs),
}

/// Intrinsics file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    /// ROS `camera_info` YAML.
    Ros,
    /// OpenCV `FileStorage` YAML.
    Opencv,
}

/// `pushbot calibrate lens`.
#[derive(Args, Debug, Clone)]
pub struct LensArgs {
    /// A folder of frames (PNG or JPEG) of the board, all from the camera at one size: 10–20
    /// frames, the board tilted 20–45° different ways and reaching every edge and corner of the
    /// image.
    #[arg(long, value_name = "DIR")]
    pub frames: PathBuf,
    /// The board's layout file (`calibrate board` writes it); default: the built-in board.
    #[arg(long, value_name = "FILE")]
    pub layout: Option<PathBuf>,
    /// Where to write the intrinsics.
    #[arg(long, default_value = "lens.yaml")]
    pub out: PathBuf,
    /// Intrinsics file format.
    #[arg(long, value_enum, default_value = "ros")]
    pub format: FormatArg,
    /// The camera's name in the file.
    #[arg(long, default_value = "pushbot_camera")]
    pub name: String,
    /// Refuse a fit whose RMS reprojection error is above this, pixels.
    #[arg(long, default_value_t = Requirements::default().max_rms_px)]
    pub max_rms: f64,
    /// Refuse a fit whose corners cover less than this fraction of the image (8 × 6 cells).
    #[arg(long, default_value_t = Requirements::default().min_coverage)]
    pub min_coverage: f64,
    /// Fewest usable views (frames showing at least 4 of the board's tags).
    #[arg(long, default_value_t = Requirements::default().min_views)]
    pub min_views: usize,
    /// Marker detector.
    #[arg(long, value_enum, default_value = "apriltag-c")]
    pub detector: DetectorKind,
}

/// `pushbot calibrate board`.
#[derive(Args, Debug, Clone)]
pub struct BoardArgs {
    /// Where to write the board (SVG, millimetres: print at 100 %).
    #[arg(long, default_value = "board.svg")]
    pub out: PathBuf,
    /// Draw this layout file (TOML); without it the built-in board is drawn and its layout
    /// written beside the SVG (same name, `.toml`).
    #[arg(long, value_name = "FILE")]
    pub layout: Option<PathBuf>,
}

/// Run `pushbot calibrate …`.
pub fn run(g: &Global, cmd: CalibrateCommand) -> CliResult {
    match cmd.what {
        Some(CalibrateWhat::Lens(a)) => lens(g, a),
        Some(CalibrateWhat::Board(a)) => board(g, a),
        None => vision::calibrate(g, cmd.table),
    }
}

fn load_layout(path: &Option<PathBuf>) -> Result<BoardLayout, CliError> {
    match path {
        Some(p) => BoardLayout::load(p).map_err(|e| CliError::bad_input(format!("--layout: {e}"))),
        None => Ok(BoardLayout::default()),
    }
}

fn write(path: &std::path::Path, text: &str) -> Result<(), CliError> {
    std::fs::write(path, text)
        .map_err(|e| CliError::bad_input(format!("cannot write {}: {e}", path.display())))
}

/// `pushbot calibrate board`.
#[cfg(feature = "sim")]
pub fn board(g: &Global, a: BoardArgs) -> CliResult {
    let layout = load_layout(&a.layout)?;
    let svg = crate::vision::board_svg::board_svg(&layout)
        .map_err(|e| CliError::bad_input(format!("board layout: {e}")))?;
    write(&a.out, &svg)?;
    let layout_file = match &a.layout {
        Some(p) => p.clone(),
        None => {
            let p = a.out.with_extension("toml");
            write(&p, &layout.to_toml())?;
            p
        }
    };
    if g.json {
        let v = serde_json::json!({"svg": a.out, "layout": layout_file, "board": layout,
            "description": layout.describe()});
        println!("{v}");
    } else {
        println!(
            "wrote {} ({}) and its layout {}: print at 100 %, then \
             `pushbot calibrate lens --frames DIR --layout {}`",
            a.out.display(),
            layout.describe(),
            layout_file.display(),
            layout_file.display()
        );
    }
    Ok(Status::Success)
}

/// `pushbot calibrate board` needs the tag patterns of the simulated camera's family tables.
#[cfg(not(feature = "sim"))]
pub fn board(_g: &Global, _a: BoardArgs) -> CliResult {
    Err(CliError::bad_input(
        "this build of pushbot has no tag patterns to draw a board with (built without the \
         `sim` feature): build it with default features",
    ))
}

fn progress(g: &Global, len: u64) -> ProgressBar {
    use std::io::IsTerminal;
    if g.json || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("frames {pos}/{len} {wide_bar} {msg}") {
        pb.set_style(style);
    }
    pb
}

/// `pushbot calibrate lens`.
pub fn lens(g: &Global, a: LensArgs) -> CliResult {
    let layout = load_layout(&a.layout)?;
    let req = Requirements {
        min_views: a.min_views,
        max_rms_px: a.max_rms,
        min_coverage: a.min_coverage,
    };
    if !(req.max_rms_px.is_finite() && req.max_rms_px > 0.0) {
        return Err(CliError::bad_input(
            "--max-rms must be a positive number of pixels",
        ));
    }
    if !(0.0..=1.0).contains(&req.min_coverage) {
        return Err(CliError::bad_input(
            "--min-coverage must be a fraction in 0..=1",
        ));
    }
    if req.min_views < 2 {
        return Err(CliError::bad_input("--min-views must be at least 2"));
    }
    let mut src = FolderSource::open(&a.frames, 30.0)
        .map_err(|e| CliError::bad_input(format!("--frames: {e}")))?;
    let files = src.files().to_vec();
    let mut det =
        make_detector(a.detector, &[layout.family]).map_err(|e| CliError::Failed(e.into()))?;
    let mut views = BoardViews::new(layout);
    let pb = progress(g, files.len() as u64);
    let mut seen = Vec::new();
    while let Some(frame) = src
        .next_frame()
        .map_err(|e| CliError::bad_input(format!("--frames: {e}")))?
    {
        let name = files
            .get(frame.seq as usize)
            .and_then(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| format!("frame {}", frame.seq));
        let dets = det.detect(&frame).map_err(|e| CliError::Failed(e.into()))?;
        let tags = views
            .add(&name, [frame.width, frame.height], &dets)
            .map_err(|e| CliError::bad_input(format!("--frames: {e}")))?;
        pb.set_message(format!("{name}: {tags} tags"));
        pb.inc(1);
        seen.push((name, tags));
    }
    pb.finish_and_clear();
    let fit = match views.fit(req.min_views) {
        Ok(f) => f,
        Err(e) => return Ok(super::task_failed(g, &format!("calibrate lens: {e}"))),
    };
    let refusal = fit.refusal(&req);
    if refusal.is_none() {
        let text = write_intrinsics(
            &fit.intrinsics,
            match a.format {
                FormatArg::Ros => LensFormat::Ros,
                FormatArg::Opencv => LensFormat::OpenCv,
            },
            &a.name,
        );
        write(&a.out, &text)?;
    }
    report(g, &a, &fit, &seen, refusal.as_deref())?;
    Ok(match refusal {
        Some(why) => super::task_failed(g, &format!("calibrate lens: refused: {why}")),
        None => Status::Success,
    })
}

/// Print the fit: one JSON object, or text.
fn report(
    g: &Global,
    a: &LensArgs,
    fit: &LensFit,
    seen: &[(String, usize)],
    refusal: Option<&str>,
) -> Result<(), CliError> {
    if g.json {
        // A refused fit prints only the error object (its message says why).
        if refusal.is_none() {
            let v = serde_json::json!({"intrinsics": fit.intrinsics, "rms_px": fit.rms_px,
                "max_px": fit.max_px, "coverage": fit.coverage, "points": fit.points,
                "outliers": fit.outliers, "frames": fit.frames, "views": fit.views,
                "out": a.out});
            println!("{v}");
        }
        return Ok(());
    }
    let l = &fit.intrinsics;
    let d = l.distortion;
    // Frames without the board (their tag count), or left out of many.
    let skipped: Vec<String> = seen
        .iter()
        .filter(|(n, _)| !fit.views.iter().any(|v| &v.name == n))
        .map(|(n, tags)| format!("{n} ({tags} tags)"))
        .collect();
    println!(
        "{} of {} frames used ({} corners, {} dropped as misread); not used: {}",
        fit.views.len(),
        fit.frames,
        fit.points,
        fit.outliers,
        if skipped.is_empty() {
            "none".to_string()
        } else {
            skipped.join(", ")
        }
    );
    for v in &fit.views {
        println!(
            "  {:<28} {:>3} tags  RMS {:.3} px  max {:.3} px",
            v.name, v.tags, v.rms_px, v.max_px
        );
    }
    println!(
        "{}×{}: fx {:.2} fy {:.2} cx {:.2} cy {:.2} px; k1 {:.5} k2 {:.5} p1 {:.5} p2 {:.5} k3 {:.5}",
        l.width, l.height, l.fx, l.fy, l.cx, l.cy, d.k1, d.k2, d.p1, d.p2, d.k3
    );
    println!(
        "reprojection RMS {:.3} px, max {:.3} px; corners cover {:.0} % of the image",
        fit.rms_px,
        fit.max_px,
        100.0 * fit.coverage
    );
    if refusal.is_none() {
        println!("saved {} (use it with --intrinsics)", a.out.display());
    }
    Ok(())
}
