//! Resumable evaluations. `pushbot eval delivery --resume FILE` appends every finished cell
//! (scene × start × method: its [`StartResult`] and first trajectory) to a JSON-lines file the
//! moment the cell is done. Run again with the same file, the cells already in it are read
//! back rather than run again, so an evaluation of hours (Fig. 11 with the rendered camera)
//! survives an interruption and loses at most the cells that were running.
//!
//! A cell's results depend on the run's trials, seed and camera ([`RunKey`], the file's first
//! line) and on its scene's setup and strategy ([`SceneKey`], a checksum of each, kept with the
//! cell) — not on which other starts, methods or scenes run beside it. So a run may add
//! cells to a file (the dipole after the learned method, more scenes); a file of other trials,
//! seed or camera, or a cell whose scene's setup or strategy changed, is refused with what
//! differs, never mixed in. A last line cut short by the interruption is dropped (and cut from
//! the file before anything is appended); any other line that does not read is an error that
//! names it, and the file is left as it is.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

use super::jsonl::Appender;
use super::shard::Sweep;
use super::strategy_eval::{LabelledRun, Method, StartResult, TrialSetup};
use crate::strategy::sample::Sample;

/// Version of the file's layout.
const FORMAT: u32 = 1;

/// One scene of a run: what its cells' results depend on besides the run's own settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneKey {
    /// The scene's name.
    pub scene: String,
    /// CRC-64 of the trial setup (scene, simulated robot, delivery and kernel parameters).
    pub setup_crc: u64,
    /// Samples of the strategy.
    pub samples: usize,
    /// CRC-64 of the strategy's samples.
    pub samples_crc: u64,
}

impl SceneKey {
    /// The key of one scene's setup and strategy.
    pub fn new(setup: &TrialSetup, samples: &[Sample]) -> SceneKey {
        SceneKey {
            scene: setup.scene.name.clone(),
            setup_crc: crc64(&format!("{setup:?}")),
            samples: samples.len(),
            samples_crc: crc64(&format!("{samples:?}")),
        }
    }
}

/// What every cell of a run depends on besides its scene: a file is resumed only by a run
/// of the same.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunKey {
    /// Layout version of the file.
    pub format: u32,
    /// Trials per cell.
    pub trials: usize,
    /// The run's seed.
    pub seed: u64,
    /// `truth` or `rendered`.
    pub camera: String,
    /// The sweep and its share, for a shard's file (`--shard`); `None` for a whole run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep: Option<Sweep>,
}

impl RunKey {
    /// The key of a run.
    pub fn new(trials: usize, seed: u64, camera: &str) -> RunKey {
        RunKey {
            format: FORMAT,
            trials,
            seed,
            camera: camera.to_owned(),
            sweep: None,
        }
    }

    /// The key of a shard's run: its sweep and share.
    pub fn sharded(self, sweep: Sweep) -> RunKey {
        RunKey {
            sweep: Some(sweep),
            ..self
        }
    }

    /// What differs between this run and `file`'s, in words.
    pub fn differences(&self, file: &RunKey) -> Vec<String> {
        let mut out: Vec<String> = [
            ("format", self.format.to_string(), file.format.to_string()),
            ("trials", self.trials.to_string(), file.trials.to_string()),
            ("seed", self.seed.to_string(), file.seed.to_string()),
            ("camera", self.camera.clone(), file.camera.clone()),
        ]
        .into_iter()
        .filter(|(_, a, b)| a != b)
        .map(|(name, a, b)| format!("{name} {b} in the file, {a} now"))
        .collect();
        match (&self.sweep, &file.sweep) {
            (Some(a), Some(b)) => out.extend(a.differences(b)),
            (Some(a), None) => out.push(format!("a whole run in the file, shard {} now", a.shard)),
            (None, Some(b)) => out.push(format!("shard {} in the file, a whole run now", b.shard)),
            (None, None) => {}
        }
        out
    }
}

impl SceneKey {
    /// What differs between this scene and `file`'s, in words.
    pub fn differences(&self, file: &SceneKey) -> Vec<String> {
        let mut out = Vec::new();
        if self.setup_crc != file.setup_crc {
            out.push(format!(
                "{}: the scene or the robot, delivery or kernel settings",
                self.scene
            ));
        }
        if (self.samples, self.samples_crc) != (file.samples, file.samples_crc) {
            out.push(format!(
                "{}: the strategy ({} samples in the file, {} now)",
                self.scene, file.samples, self.samples
            ));
        }
        out
    }
}

/// One finished cell, as a line of the file.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CellRecord {
    /// The scene, its setup and strategy.
    pub scene: SceneKey,
    /// The cell's results.
    pub result: StartResult,
    /// Its first trial's trajectory (for the figure).
    pub first: Option<LabelledRun>,
}

/// The file of a resumable run: the cells it holds, and appending new ones.
#[derive(Debug)]
pub struct Checkpoint {
    done: HashMap<(String, String, Method), CellRecord>,
    file: Appender,
}

/// A file's header and its whole cells, read without changing it.
#[derive(Debug)]
pub struct FileCells {
    /// The run's key (line 1).
    pub header: RunKey,
    /// Every whole cell, with its line number (from 1).
    pub cells: Vec<(usize, CellRecord)>,
    /// Bytes up to the end of the last whole line (a last line cut short is not counted).
    pub keep: usize,
}

impl FileCells {
    /// Read the file at `path`: `None` when there is none or it is empty. A last line cut
    /// short (an interrupted run) is dropped; any other line that does not read is an error
    /// naming it.
    pub fn read(path: &Path) -> Result<Option<FileCells>> {
        Ok(
            super::jsonl::read(path, "pushbot eval delivery --resume")?.map(|l| FileCells {
                header: l.header,
                cells: l.records,
                keep: l.keep,
            }),
        )
    }
}

impl Checkpoint {
    /// Open (or start) the file of run `key` at `path`, reading back the cells it holds of
    /// `scenes` (the cells of other scenes stay in the file, unused).
    pub fn open(path: &Path, key: &RunKey, scenes: &[SceneKey]) -> Result<Checkpoint> {
        let shown = path.display();
        let read = FileCells::read(path)?;
        let mut done = HashMap::new();
        // Bytes up to the end of the last complete line.
        let mut keep = 0;
        if let Some(read) = read {
            if &read.header != key {
                let what = key.differences(&read.header);
                bail!(
                    "{shown} holds the cells of another run ({}): pass another file, or delete \
                     it to start over",
                    if what.is_empty() {
                        "its header differs".to_owned()
                    } else {
                        what.join("; ")
                    }
                );
            }
            keep = read.keep;
            for (line, c) in read.cells {
                let Some(now) = scenes.iter().find(|s| s.scene == c.scene.scene) else {
                    continue;
                };
                let what = now.differences(&c.scene);
                if !what.is_empty() {
                    bail!(
                        "{shown} line {line}: its cell was run with another {}: pass another \
                         file, or delete it to start over",
                        what.join("; ")
                    );
                }
                let k = (
                    c.scene.scene.clone(),
                    c.result.start.clone(),
                    c.result.method,
                );
                done.insert(k, c);
            }
        }
        Ok(Checkpoint {
            done,
            file: Appender::open(path, keep, key)?,
        })
    }

    /// The cell of `scene`, `start` and `method` if the file holds it.
    pub fn cell(&self, scene: &str, start: &str, method: Method) -> Option<&CellRecord> {
        self.done.get(&(scene.to_owned(), start.to_owned(), method))
    }

    /// Cells read back from the file.
    pub fn cells(&self) -> usize {
        self.done.len()
    }

    /// Append a finished cell (one line, written through to the disk).
    pub fn record(&self, cell: &CellRecord) -> Result<()> {
        self.file.append(cell)
    }
}

/// CRC-64 (XZ) of a text.
fn crc64(text: &str) -> u64 {
    crc::Crc::<u64>::new(&crc::CRC_64_XZ).checksum(text.as_bytes())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;

    fn key(trials: usize) -> RunKey {
        RunKey::new(trials, 1, "truth")
    }

    fn scene(samples_crc: u64) -> SceneKey {
        SceneKey {
            scene: "lau-irregular".into(),
            setup_crc: 7,
            samples: 200,
            samples_crc,
        }
    }

    fn cell(start: &str, successes: usize) -> CellRecord {
        CellRecord {
            scene: scene(9),
            result: StartResult {
                start: start.into(),
                method: Method::Learned,
                trials: 5,
                successes,
                success_rate: successes as f64 * 20.0,
                mean_time_s: Some(81.5),
                mean_object_path_m: None,
                mean_robot_path_m: Some(1.25),
                mean_path_ratio: None,
                max_path_ratio: None,
                path_ratios: Vec::new(),
                failures: BTreeMap::from([("time-limit".to_owned(), 5 - successes)]),
                stall_recoveries: 0,
                silent_timeouts: 0,
            },
            first: Some(("A Learned".into(), vec![Default::default(); 2])),
        }
    }

    /// Cells written are read back as they were; a line cut short by an interruption is
    /// dropped and cut from the file, so the next cell appended is a whole line.
    #[test]
    fn cells_survive_a_restart_and_a_cut_last_line_is_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cells.jsonl");
        let c = Checkpoint::open(&path, &key(5), &[scene(9)]).unwrap();
        assert_eq!(c.cells(), 0);
        c.record(&cell("A", 5)).unwrap();
        c.record(&cell("B", 3)).unwrap();
        drop(c);
        let c = Checkpoint::open(&path, &key(5), &[scene(9)]).unwrap();
        assert_eq!(c.cells(), 2);
        let b = c.cell("lau-irregular", "B", Method::Learned).unwrap();
        assert_eq!(b.result, cell("B", 3).result);
        assert_eq!(b.first, cell("B", 3).first);
        assert!(c.cell("lau-irregular", "B", Method::Dipole).is_none());
        drop(c);
        // An interrupted write: half of a third line, no newline.
        let whole = std::fs::read_to_string(&path).unwrap();
        let half = serde_json::to_string(&cell("C", 1)).unwrap();
        std::fs::write(&path, format!("{whole}{}", &half[..half.len() / 2])).unwrap();
        let c = Checkpoint::open(&path, &key(5), &[scene(9)]).unwrap();
        assert_eq!(c.cells(), 2);
        c.record(&cell("C", 4)).unwrap();
        drop(c);
        let c = Checkpoint::open(&path, &key(5), &[scene(9)]).unwrap();
        assert_eq!(c.cells(), 3);
        assert_eq!(
            c.cell("lau-irregular", "C", Method::Learned)
                .unwrap()
                .result
                .successes,
            4
        );
    }

    /// Another run's file is refused with what differs, and is left as it was; so is a file
    /// with a broken line in its middle.
    #[test]
    fn another_runs_file_or_a_broken_line_is_an_error_that_loses_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cells.jsonl");
        let c = Checkpoint::open(&path, &key(5), &[scene(9)]).unwrap();
        c.record(&cell("A", 5)).unwrap();
        drop(c);
        let before = std::fs::read(&path).unwrap();
        let e = Checkpoint::open(&path, &key(6), &[scene(9)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("trials 5 in the file, 6 now"), "{e}");
        let e = format!(
            "{:#}",
            Checkpoint::open(&path, &key(5), &[scene(10)]).unwrap_err()
        );
        assert!(
            e.contains("line 2: its cell was run with another lau-irregular: the strategy"),
            "{e}"
        );
        // A run of other scenes leaves this scene's cells in the file, unused.
        let other = SceneKey {
            scene: "lau-snake".into(),
            ..scene(10)
        };
        let c = Checkpoint::open(&path, &key(5), &[other]).unwrap();
        assert_eq!(c.cells(), 0);
        drop(c);
        assert_eq!(std::fs::read(&path).unwrap(), before);
        // A broken line that is not the last.
        let text = String::from_utf8(before).unwrap();
        let line = serde_json::to_string(&cell("B", 2)).unwrap();
        let broken = format!("{text}{{\"scene\": 3}}\n{line}\n");
        std::fs::write(&path, &broken).unwrap();
        let e = Checkpoint::open(&path, &key(5), &[scene(9)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), broken);
        // Not a file of ours at all.
        std::fs::write(&path, "hello\n").unwrap();
        let e = Checkpoint::open(&path, &key(5), &[scene(9)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1 is not the header"), "{e}");
    }
}
