//! Evaluation of delivery as in Lau, Mitani & Igarashi §V (Fig. 10–11): trials from each named
//! start position of a scene to its goal, with the learned strategy and the dipole-field
//! baseline side by side, in the in-process simulation.

use std::collections::BTreeMap;

use anyhow::{Result, anyhow};
use nalgebra::Vector2;
use pushbot_sim::Scene;

use super::deliver::{Delivery, DeliveryParams, deliver_dipole, deliver_learned};
use super::obstacles::{ObstacleParams, deliver_among_obstacles, scene_obstacles};
use super::regression::{KernelParams, PushStrategy};
use super::robot_io::RobotIo;
use super::sample::Sample;
use crate::sim::robot::{SimRobot, SimRobotOptions};

/// A delivery method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Algorithm 2 with the learned pushing strategy.
    Learned,
    /// The dipole field of Igarashi et al.
    Dipole,
}

/// The results of one method from one start position.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StartResult {
    /// Start position name (A–F).
    pub start: String,
    /// Method.
    pub method: Method,
    /// Trials run.
    pub trials: usize,
    /// Trials that reached the goal.
    pub successes: usize,
    /// Successes in percent.
    pub success_rate: f64,
    /// Mean time of the successful trials, s (simulated).
    pub mean_time_s: Option<f64>,
    /// Mean object path length of the successful trials, m.
    pub mean_object_path_m: Option<f64>,
    /// Mean robot path length of the successful trials, m.
    pub mean_robot_path_m: Option<f64>,
    /// Failures by reason.
    pub failures: BTreeMap<String, usize>,
}

/// Everything a batch of trials needs.
#[derive(Debug, Clone)]
pub struct TrialSetup {
    /// The scene (its first goal for the object is the goal).
    pub scene: Scene,
    /// The object's id (the scene's first object when `None`).
    pub object: Option<String>,
    /// Simulated robot settings (the seed is varied per trial from this one).
    pub sim: SimRobotOptions,
    /// Delivery parameters.
    pub delivery: DeliveryParams,
    /// Kernel parameters of the regression.
    pub kernel: KernelParams,
}

impl TrialSetup {
    /// The goal position of the object.
    pub fn goal(&self) -> Result<Vector2<f64>> {
        let id = match &self.object {
            Some(id) => id.clone(),
            None => self
                .scene
                .objects
                .first()
                .map(|o| o.id.clone())
                .ok_or_else(|| anyhow!("scene {} has no object", self.scene.name))?,
        };
        let g = self
            .scene
            .goals
            .iter()
            .find(|g| g.object == id)
            .ok_or_else(|| anyhow!("scene {} has no goal for {id:?}", self.scene.name))?;
        Ok(Vector2::new(g.pose.x, g.pose.y))
    }

    /// A simulated robot for trial `trial` from `start`.
    pub fn robot(&self, start: &str, trial: usize) -> Result<SimRobot> {
        let mut opts = self.sim;
        opts.seed = self
            .sim
            .seed
            .wrapping_mul(1_000_003)
            .wrapping_add(trial as u64 * 131 + u64::from(start.bytes().next().unwrap_or(0)));
        SimRobot::new(
            self.scene.clone(),
            self.object.as_deref(),
            Some(start),
            opts,
        )
    }
}

/// Run `trials` deliveries from `start` with `method`; the learned method starts each trial
/// from `samples` (supplemental samples are used within a trial, not carried to the next) and,
/// in a scene with obstacles, follows a global path through sub-goals.
pub fn run_start(
    setup: &TrialSetup,
    method: Method,
    samples: &[Sample],
    start: &str,
    trials: usize,
) -> Result<(StartResult, Vec<Delivery>)> {
    let goal = setup.goal()?;
    let mut runs = Vec::with_capacity(trials);
    for t in 0..trials {
        let mut io = setup.robot(start, t)?;
        let (ws, o) = (io.workspace(), io.true_object_pose());
        if !ws.boundary.contains(o.position()) {
            anyhow::bail!(
                "start {start} puts the object's marker at ({:.3}, {:.3}), outside the boundary \
                 x {:.3}..{:.3}, y {:.3}..{:.3} (a smaller --boundary-inset or a larger \
                 --table-margin brings it inside)",
                o.x,
                o.y,
                ws.boundary.min[0],
                ws.boundary.max[0],
                ws.boundary.min[1],
                ws.boundary.max[1]
            );
        }
        let d = match method {
            Method::Learned if !setup.scene.obstacles.is_empty() => {
                let mut strat = PushStrategy::new(samples.iter().copied(), setup.kernel);
                deliver_among_obstacles(
                    &mut io,
                    &mut strat,
                    goal,
                    &scene_obstacles(&setup.scene),
                    &setup.delivery,
                    &ObstacleParams::default(),
                    &mut |_| Ok(()),
                )?
                .delivery
            }
            Method::Learned => {
                let mut strat = PushStrategy::new(samples.iter().copied(), setup.kernel);
                deliver_learned(&mut io, &mut strat, goal, &setup.delivery, &mut |_| Ok(()))?
            }
            Method::Dipole => deliver_dipole(&mut io, goal, &setup.delivery)?,
        };
        runs.push(d);
    }
    Ok((summarise(start, method, &runs), runs))
}

fn mean(xs: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = xs.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Success rate, means over successful trials, failures by reason.
pub fn summarise(start: &str, method: Method, runs: &[Delivery]) -> StartResult {
    let ok: Vec<&Delivery> = runs.iter().filter(|d| d.success).collect();
    let mut failures = BTreeMap::new();
    for d in runs {
        if let Some(f) = d.failure {
            let name = serde_json::to_value(f)
                .ok()
                .and_then(|v| v.as_str().map(str::to_owned))
                .unwrap_or_else(|| format!("{f:?}"));
            *failures.entry(name).or_insert(0) += 1;
        }
    }
    StartResult {
        start: start.to_owned(),
        method,
        trials: runs.len(),
        successes: ok.len(),
        success_rate: if runs.is_empty() {
            0.0
        } else {
            100.0 * ok.len() as f64 / runs.len() as f64
        },
        mean_time_s: mean(ok.iter().map(|d| d.time)),
        mean_object_path_m: mean(ok.iter().map(|d| d.object_path)),
        mean_robot_path_m: mean(ok.iter().map(|d| d.robot_path)),
        failures,
    }
}

/// Parse start positions: `A..F`, `A,C,E` or `B`.
pub fn parse_starts(s: &str) -> Result<Vec<String>, String> {
    let s = s.trim();
    if let Some((a, b)) = s.split_once("..") {
        let (a, b) = (a.trim(), b.trim());
        let (Some(ca), Some(cb)) = (single_letter(a), single_letter(b)) else {
            return Err(format!("a range of starts is like A..F, not {s:?}"));
        };
        if ca > cb {
            return Err(format!("empty range of starts {s:?}"));
        }
        return Ok((ca..=cb).map(|c| c.to_string()).collect());
    }
    let v: Vec<String> = s
        .split(',')
        .map(|x| x.trim().to_owned())
        .filter(|x| !x.is_empty())
        .collect();
    if v.is_empty() {
        return Err("no start position given".into());
    }
    Ok(v)
}

fn single_letter(s: &str) -> Option<char> {
    let mut it = s.chars();
    match (it.next(), it.next()) {
        (Some(c), None) if c.is_ascii_alphabetic() => Some(c.to_ascii_uppercase()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_parse() {
        assert_eq!(parse_starts("A..C").unwrap(), ["A", "B", "C"]);
        assert_eq!(parse_starts("a..b").unwrap(), ["A", "B"]);
        assert_eq!(parse_starts("B, D").unwrap(), ["B", "D"]);
        assert!(parse_starts("F..A").is_err());
        assert!(parse_starts("AB..C").is_err());
        assert!(parse_starts(" ").is_err());
    }
}
