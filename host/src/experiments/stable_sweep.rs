//! `pushbot eval stable --resume FILE [--shard K/N]`: the stable-pushing trials (Lynch & Mason
//! §4, run closed or open loop in perturbed worlds) kept one a line as each is done
//! ([`super::jsonl`]), so an evaluation resumes where it stopped, and N shards of it
//! ([`super::shard`]) join in `pushbot eval merge`.
//!
//! A trial's outcome depends on the run's scene (or random scenes and their pusher), loop,
//! perturbation, seed, camera and the trial's number ([`StableKey`]), not on the other trials.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

use super::jsonl::{self, Appender};
use super::shard::Shard;
use super::stable_trials::StableTrial;

/// Version of the file's layout.
const FORMAT: u32 = 1;

/// What every trial of a stable evaluation depends on (the file's first line).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StableKey {
    /// Layout version of the file.
    pub format: u32,
    /// Always `stable`: tells this file from a delivery evaluation's.
    pub eval: String,
    /// The scene (preset or file), or `None` for random scenes.
    pub scene: Option<String>,
    /// Random scenes: their pusher (`diff-drive`, `car`).
    pub pusher: Option<String>,
    /// Closed loop (re-planning from the camera) or open loop.
    pub closed_loop: bool,
    /// Perturbed worlds.
    pub perturbed: bool,
    /// The run's seed.
    pub seed: u64,
    /// The first trial's number (a random scene's seed).
    pub first_trial: u64,
    /// How many trials.
    pub trials: u64,
    /// `truth` or `rendered`.
    pub camera: String,
    /// This file's share of the trials, if it is a shard's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<Shard>,
}

impl StableKey {
    /// The key of a run (the shard added with [`StableKey::shard`]).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scene: Option<String>,
        pusher: Option<String>,
        closed_loop: bool,
        perturbed: bool,
        seed: u64,
        first_trial: u64,
        trials: u64,
        camera: &str,
    ) -> StableKey {
        StableKey {
            format: FORMAT,
            eval: "stable".into(),
            scene,
            pusher,
            closed_loop,
            perturbed,
            seed,
            first_trial,
            trials,
            camera: camera.to_owned(),
            shard: None,
        }
    }

    /// The trials (numbers) of the whole run, in order.
    pub fn all_trials(&self) -> Vec<u64> {
        (self.first_trial..self.first_trial + self.trials).collect()
    }

    /// The trials this run (or shard) runs.
    pub fn mine(&self) -> Vec<u64> {
        self.all_trials()
            .into_iter()
            .enumerate()
            .filter(|(i, _)| self.shard.is_none_or(|s| s.owns(*i)))
            .map(|(_, t)| t)
            .collect()
    }

    /// What differs between this run and `file`'s, in words.
    pub fn differences(&self, file: &StableKey) -> Vec<String> {
        let opt = |o: &Option<String>| o.clone().unwrap_or_else(|| "none".into());
        let shard = |s: Option<Shard>| s.map_or("none".into(), |s| s.to_string());
        [
            ("format", self.format.to_string(), file.format.to_string()),
            ("evaluation", self.eval.clone(), file.eval.clone()),
            ("scene", opt(&self.scene), opt(&file.scene)),
            ("pusher", opt(&self.pusher), opt(&file.pusher)),
            (
                "closed loop",
                self.closed_loop.to_string(),
                file.closed_loop.to_string(),
            ),
            (
                "perturbed",
                self.perturbed.to_string(),
                file.perturbed.to_string(),
            ),
            ("seed", self.seed.to_string(), file.seed.to_string()),
            (
                "first trial",
                self.first_trial.to_string(),
                file.first_trial.to_string(),
            ),
            ("trials", self.trials.to_string(), file.trials.to_string()),
            ("camera", self.camera.clone(), file.camera.clone()),
            ("shard", shard(self.shard), shard(file.shard)),
        ]
        .into_iter()
        .filter(|(_, a, b)| a != b)
        .map(|(name, a, b)| format!("{name} {b} in the file, {a} now"))
        .collect()
    }
}

/// One finished trial, as a line of the file: a random scene without a plan has no run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TrialRecord {
    /// The trial's number.
    pub trial: u64,
    /// How it went (`None`: a random scene for which no plan exists).
    pub run: Option<StableTrial>,
}

/// A stable evaluation's file as read: its key, its trials by number, and the bytes of whole
/// lines.
pub type Read = (StableKey, BTreeMap<u64, TrialRecord>, usize);

/// Read a stable evaluation's file without changing it: its key and its trials by number.
pub fn read(path: &Path) -> Result<Option<Read>> {
    let Some(l) = jsonl::read::<StableKey, TrialRecord>(path, "pushbot eval stable --resume")?
    else {
        return Ok(None);
    };
    if l.header.eval != "stable" {
        bail!("{} is not the file of a stable evaluation", path.display());
    }
    let trials = l.records.into_iter().map(|(_, r)| (r.trial, r)).collect();
    Ok(Some((l.header, trials, l.keep)))
}

/// The file of a resumable stable evaluation: the trials it holds, and appending new ones.
#[derive(Debug)]
pub struct StableFile {
    done: BTreeMap<u64, TrialRecord>,
    file: Appender,
}

impl StableFile {
    /// Open (or start) the file of run `key` at `path`, reading back its trials; a file of
    /// another run is refused with what differs, and left as it is.
    pub fn open(path: &Path, key: &StableKey) -> Result<StableFile> {
        let (done, keep) = match read(path)? {
            Some((header, done, keep)) => {
                if &header != key {
                    bail!(
                        "{} holds the trials of another run ({}): pass another file, or delete \
                         it to start over",
                        path.display(),
                        key.differences(&header).join("; ")
                    );
                }
                (done, keep)
            }
            None => (BTreeMap::new(), 0),
        };
        Ok(StableFile {
            done,
            file: Appender::open(path, keep, key)?,
        })
    }

    /// The trial numbered `trial`, if the file holds it.
    pub fn get(&self, trial: u64) -> Option<&TrialRecord> {
        self.done.get(&trial)
    }

    /// Trials read back from the file.
    pub fn len(&self) -> usize {
        self.done.len()
    }

    /// Whether the file held no trial.
    pub fn is_empty(&self) -> bool {
        self.done.is_empty()
    }

    /// Append a finished trial.
    pub fn record(&self, r: &TrialRecord) -> Result<()> {
        self.file.append(r)
    }
}
