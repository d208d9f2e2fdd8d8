//! Trials of a delivery method and their statistics, as Lau, Mitani & Igarashi report them (§V,
//! Fig. 11): success rate, mean time and object path of the successful trials, failures by
//! reason; and the start positions a command names (`A..F`).

use std::collections::BTreeMap;

use crate::exec::deliver::{Delivery, Failure};

/// A delivery method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Algorithm 2 with the learned pushing strategy.
    Learned,
    /// The dipole field of Igarashi et al.
    Dipole,
}

/// The results of one method from one start position.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// Mean, over the successful trials, of the path length of the object's body (the centre
    /// of its outline's smallest enclosing circle) over the shortest collision-free path of
    /// that circle from where it started to where it ended.
    pub mean_path_ratio: Option<f64>,
    /// Largest of those ratios.
    pub max_path_ratio: Option<f64>,
    /// Each of those ratios, in trial order (a result written before they were kept has
    /// none).
    #[serde(default)]
    pub path_ratios: Vec<f64>,
    /// Failures by reason.
    pub failures: BTreeMap<String, usize>,
    /// Stalls recovered from (or given up on) over all trials (deliveries among obstacles).
    pub stall_recoveries: usize,
    /// Trials that ran out of time without a recovery attempt logged (among obstacles there
    /// should be none; on the clear table there is no recovery to log).
    pub silent_timeouts: usize,
}

fn mean(xs: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = xs.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Success rate, means over successful trials, failures by reason.
pub fn summarise(start: &str, method: Method, runs: &[Delivery]) -> StartResult {
    let ok: Vec<&Delivery> = runs.iter().filter(|d| d.success).collect();
    let ratios: Vec<f64> = ok
        .iter()
        .filter_map(|d| {
            d.shortest_path
                .filter(|s| *s > 0.01)
                .map(|s| d.body_path / s)
        })
        .collect();
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
        mean_path_ratio: mean(ratios.iter().copied()),
        max_path_ratio: ratios.iter().copied().reduce(f64::max),
        path_ratios: ratios,
        failures,
        stall_recoveries: runs.iter().map(|d| d.recoveries.len()).sum(),
        silent_timeouts: runs
            .iter()
            .filter(|d| d.failure == Some(Failure::TimeLimit) && d.recoveries.is_empty())
            .count(),
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

    fn run(failure: Option<Failure>, recoveries: usize) -> Delivery {
        Delivery {
            success: failure.is_none(),
            failure,
            time: 100.0,
            steps: 10,
            repositions: 1,
            recoveries: (0..recoveries)
                .map(|i| crate::exec::deliver::Recovery {
                    t: 10.0 * i as f64,
                    at: [0.5, 0.5],
                    subgoal: [0.6, 0.5],
                    action: "back off and re-plan".into(),
                })
                .collect(),
            // The marker swung further than the body's centre went: the ratio is the body's.
            object_path: 1.5,
            body_path: 1.2,
            robot_path: 2.0,
            shortest_path: Some(1.0),
            final_distance: 0.01,
            paths: Vec::new(),
            trajectory: Vec::new(),
        }
    }

    #[test]
    fn time_outs_without_a_recovery_are_counted() {
        let runs = [
            run(None, 1),
            run(Some(Failure::TimeLimit), 0),
            run(Some(Failure::TimeLimit), 2),
            run(Some(Failure::Stalled), 0),
        ];
        let r = summarise("A", Method::Learned, &runs);
        assert_eq!((r.trials, r.successes), (4, 1));
        assert_eq!(r.stall_recoveries, 3);
        assert_eq!(r.silent_timeouts, 1);
        assert_eq!(r.failures.get("time-limit"), Some(&2));
        assert_eq!(r.mean_path_ratio, Some(1.2));
    }

    /// Each successful trial's ratio is kept, in order; a failure's and one without a
    /// shortest path are not, and the mean and the largest are of the kept ones.
    #[test]
    fn path_ratios_are_kept_per_successful_trial() {
        let mut runs = [
            run(None, 0),
            run(Some(Failure::TimeLimit), 1),
            run(None, 0),
            run(None, 0),
        ];
        runs[2].body_path = 1.5;
        runs[3].shortest_path = None;
        let r = summarise("B", Method::Learned, &runs);
        assert_eq!(r.path_ratios, [1.2, 1.5]);
        assert_eq!(r.max_path_ratio, Some(1.5));
        assert!((r.mean_path_ratio.unwrap() - 1.35).abs() < 1e-12);
        // A result written before the ratios were kept still reads.
        let mut v = serde_json::to_value(&r).unwrap();
        v.as_object_mut().unwrap().remove("path_ratios");
        let back: StartResult = serde_json::from_value(v).unwrap();
        assert!(back.path_ratios.is_empty());
    }

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
