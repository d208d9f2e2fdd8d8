//! Reports people want to look at: a folder with `report.html` (figures drawn like the
//! papers', numbers per stage), `summary.json` for scripts, and the figures as SVG (and PNG when
//! asked). Each stage of a run adds a [`StageReport`]; [`Report::write`] writes the folder.

pub mod figure;
pub mod html;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;

/// What one stage of a run did.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct StageReport {
    /// Short id (`strategy`, `rearrange`, `stable`).
    pub id: String,
    /// A title for people.
    pub title: String,
    /// Which paper and section it reproduces.
    pub paper: String,
    /// Whether it reached its goal.
    pub success: bool,
    /// Wall time it took, s.
    pub wall_s: f64,
    /// Mission time it took, s: robot motion on the robot's clock, host work (looking,
    /// planning) at wall-clock rate, as `LiveRobot` counts it.
    pub mission_s: f64,
    /// Numbers worth reporting (planner times, costs, errors …).
    pub numbers: serde_json::Map<String, serde_json::Value>,
    /// Figures written, relative to the report folder, with captions.
    pub figures: Vec<(String, String)>,
    /// What happened, in a few sentences (failures say why).
    pub notes: Vec<String>,
}

impl StageReport {
    /// An empty report of a stage.
    pub fn new(id: &str, title: &str, paper: &str) -> StageReport {
        StageReport {
            id: id.into(),
            title: title.into(),
            paper: paper.into(),
            success: false,
            wall_s: 0.0,
            mission_s: 0.0,
            numbers: serde_json::Map::new(),
            figures: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Record a number.
    pub fn number(&mut self, key: &str, value: impl Into<serde_json::Value>) {
        self.numbers.insert(key.into(), value.into());
    }
}

/// A report folder being written.
#[derive(Debug)]
pub struct Report {
    dir: PathBuf,
    title: String,
    stages: Vec<StageReport>,
    png: bool,
    /// Each figure's own size (by file name), for the page.
    sizes: std::sync::Mutex<std::collections::HashMap<String, [f64; 2]>>,
}

/// The summary written as `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary<'a> {
    /// The report's title.
    pub title: &'a str,
    /// Whether every stage succeeded.
    pub success: bool,
    /// The stages.
    pub stages: &'a [StageReport],
}

impl Report {
    /// Start a report in `dir` (created if missing); `png` also renders every figure as PNG.
    pub fn create(dir: &Path, title: &str, png: bool) -> Result<Report> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the report folder {}", dir.display()))?;
        Ok(Report {
            dir: dir.to_path_buf(),
            title: title.into(),
            stages: Vec::new(),
            png,
            sizes: Default::default(),
        })
    }

    /// The report folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Write a figure (SVG text) as `name.svg` (and `name.png` if asked); returns the file name
    /// to show.
    pub fn figure(&self, name: &str, svg: &str) -> Result<String> {
        let file = format!("{name}.svg");
        let path = self.dir.join(&file);
        std::fs::write(&path, svg).with_context(|| format!("writing {}", path.display()))?;
        let file = if self.png {
            let png = self.dir.join(format!("{name}.png"));
            crate::plot::svg_to_png(svg, &png)?;
            format!("{name}.png")
        } else {
            file
        };
        if let Some(size) = html::svg_size(svg)
            && let Ok(mut sizes) = self.sizes.lock()
        {
            sizes.insert(file.clone(), size);
        }
        Ok(file)
    }

    /// Add a finished stage.
    pub fn add(&mut self, stage: StageReport) {
        self.stages.push(stage);
    }

    /// The stages so far.
    pub fn stages(&self) -> &[StageReport] {
        &self.stages
    }

    /// Whether every stage succeeded.
    pub fn success(&self) -> bool {
        !self.stages.is_empty() && self.stages.iter().all(|s| s.success)
    }

    /// Write `summary.json` and `report.html`; returns the path of `report.html`.
    pub fn write(&self) -> Result<PathBuf> {
        let summary = Summary {
            title: &self.title,
            success: self.success(),
            stages: &self.stages,
        };
        let json = serde_json::to_string_pretty(&summary)?;
        let path = self.dir.join("summary.json");
        std::fs::write(&path, json).with_context(|| format!("writing {}", path.display()))?;
        let sizes = self.sizes.lock().map(|s| s.clone()).unwrap_or_default();
        let html = html::render(&self.title, &self.stages, &sizes);
        let path = self.dir.join("report.html");
        std::fs::write(&path, html).with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    }
}
