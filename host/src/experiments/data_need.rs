//! The data-need curve (`eval delivery --figure 7`): how many samples Lau, Mitani &
//! Igarashi's Algorithm 1 (§III-C initial collection, §III-D experimental evaluation) needs
//! before the learned delivery (§III-E, Algorithm 2) succeeds, for the paper's collection and
//! for the active one ([`crate::strategy::active`], [`crate::strategy::regression::Admission`]).
//!
//! For each object and each [`Variant`], one collection on the clear table runs to its streak
//! (or gives up); then the strategy as it was after every `every` samples (the samples are kept
//! in the order they were collected, so a prefix is the strategy at that point) delivers the
//! object from each of the scene's starts to its goal (§V, Fig. 10), `tests` deliveries in all.
//! Collections, then checkpoints, run in parallel on all cores; everything is seeded.

use anyhow::Result;
use indicatif::ProgressBar;
use pushbot_world::Scene;
use rayon::prelude::*;

use crate::exec::collect::{CollectParams, CollectReport, DEFAULT_INITIAL, collect};
use crate::exec::deliver::DeliveryParams;
use crate::experiments::strategy_eval::{Method, TrialSetup, run_start};
use crate::sim::robot::{SimRobot, SimRobotOptions};
use crate::strategy::active::Selection;
use crate::strategy::regression::{Admission, KernelParams, PushStrategy};
use crate::strategy::sample::Sample;

/// A way of collecting, drawn as one curve.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Variant {
    /// Its name in tables and figures.
    pub name: &'static str,
    /// How initial pushes are chosen.
    pub selection: Selection,
    /// K of the initial collection.
    pub initial: usize,
    /// Whether the evaluation keeps only informative pushes.
    pub informative: bool,
}

/// The curves drawn: the paper's Algorithm 1 (random pushes, K = 300, every push kept), and the
/// active collection with random, uncertain and exploring initial pushes (K =
/// [`DEFAULT_INITIAL`], informative pushes kept; exploring is the default).
pub const VARIANTS: [Variant; 4] = [
    Variant {
        name: "paper",
        selection: Selection::Random,
        initial: 300,
        informative: false,
    },
    Variant {
        name: "random",
        selection: Selection::Random,
        initial: DEFAULT_INITIAL,
        informative: true,
    },
    Variant {
        name: "uncertain",
        selection: Selection::Uncertain,
        initial: DEFAULT_INITIAL,
        informative: true,
    },
    Variant {
        name: "explore",
        selection: Selection::Explore,
        initial: DEFAULT_INITIAL,
        informative: true,
    },
];

/// Settings of a data-need run.
#[derive(Debug, Clone)]
pub struct DataNeedSetup {
    /// Samples between checkpoints.
    pub every: usize,
    /// Test deliveries per checkpoint, spread over the scene's starts in turn.
    pub tests: usize,
    /// Checkpoints stop at this many samples (a collection that never reaches its streak can
    /// grow far).
    pub max_samples: usize,
    /// Straight successes that end a collection.
    pub streak: usize,
    /// Seed of the collections and the test deliveries.
    pub seed: u64,
    /// Simulated robot (its seed is replaced by `seed`).
    pub sim: SimRobotOptions,
    /// Delivery parameters of the test deliveries.
    pub delivery: DeliveryParams,
    /// Kernel parameters of the regression.
    pub kernel: KernelParams,
    /// Start positions of the test deliveries.
    pub starts: Vec<String>,
}

/// One point of a curve.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CurvePoint {
    /// Samples in the strategy.
    pub samples: usize,
    /// Test deliveries run.
    pub tests: usize,
    /// Test deliveries that reached the goal.
    pub successes: usize,
}

impl CurvePoint {
    /// Successes in percent.
    pub fn rate(&self) -> f64 {
        100.0 * self.successes as f64 / self.tests.max(1) as f64
    }
}

/// One object's curve for one variant.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Curve {
    /// The scene of the object.
    pub scene: String,
    /// The variant.
    pub variant: Variant,
    /// Samples when the streak was reached (`None`: not reached).
    pub streak_at: Option<usize>,
    /// The collection's report.
    pub collection: CollectReport,
    /// Test delivery success after every `every` samples, and at the end.
    pub points: Vec<CurvePoint>,
}

/// The collection parameters of `v` under `setup`.
pub fn variant_params(v: &Variant, setup: &DataNeedSetup) -> CollectParams {
    CollectParams {
        initial: v.initial,
        selection: v.selection,
        admission: v.informative.then(Admission::default),
        streak: setup.streak,
        seed: setup.seed,
        ..CollectParams::default()
    }
}

/// Collect the strategy of `scene`'s first object with `params` on the clear table; the samples
/// in the order they were kept.
pub fn collect_clear(
    scene: &Scene,
    params: &CollectParams,
    setup: &DataNeedSetup,
) -> Result<(Vec<Sample>, CollectReport)> {
    let mut clear = scene.clone();
    clear.obstacles.clear();
    let sim = SimRobotOptions {
        seed: setup.seed,
        ..setup.sim
    };
    let mut io = SimRobot::new(clear, None, None, sim)?;
    let mut strategy = PushStrategy::new(Vec::new(), setup.kernel);
    let rep = collect(
        &mut io,
        &mut strategy,
        params,
        &mut |_| Ok(()),
        &ProgressBar::hidden(),
    )?;
    Ok((strategy.samples().to_vec(), rep))
}

/// The checkpoints of a collection of `total` samples: every `every`, capped at `max`, and the
/// end (when not beyond `max`).
pub fn checkpoints(total: usize, every: usize, max: usize) -> Vec<usize> {
    let every = every.max(1);
    let mut at: Vec<usize> = (1..)
        .map(|i| i * every)
        .take_while(|n| *n <= total.min(max))
        .collect();
    if total <= max && at.last() != Some(&total) && total > 0 {
        at.push(total);
    }
    at
}

/// Success of `tests` deliveries of `scene`'s object with the first `n` of `samples`, from the
/// starts in turn.
fn test_point(
    scene: &Scene,
    samples: &[Sample],
    n: usize,
    setup: &DataNeedSetup,
) -> Result<CurvePoint> {
    let trial_setup = TrialSetup {
        scene: scene.clone(),
        object: None,
        sim: SimRobotOptions {
            seed: setup.seed,
            ..setup.sim
        },
        delivery: setup.delivery,
        kernel: setup.kernel,
    };
    let mut successes = 0;
    let starts = setup.starts.len().max(1);
    for (i, start) in setup.starts.iter().enumerate() {
        let trials = setup.tests / starts + usize::from(i < setup.tests % starts);
        if trials > 0 {
            let (res, _) = run_start(&trial_setup, Method::Learned, &samples[..n], start, trials)?;
            successes += res.successes;
        }
    }
    Ok(CurvePoint {
        samples: n,
        tests: setup.tests,
        successes,
    })
}

/// The data-need curves of every scene × variant: collections in parallel, then every
/// checkpoint's test deliveries in parallel.
pub fn data_need(
    scenes: &[Scene],
    variants: &[Variant],
    setup: &DataNeedSetup,
) -> Result<Vec<Curve>> {
    let jobs: Vec<(&Scene, &Variant)> = scenes
        .iter()
        .flat_map(|s| variants.iter().map(move |v| (s, v)))
        .collect();
    let collected: Vec<(Vec<Sample>, CollectReport)> = jobs
        .par_iter()
        .map(|(s, v)| collect_clear(s, &variant_params(v, setup), setup))
        .collect::<Result<_>>()?;
    let points: Vec<(usize, usize)> = collected
        .iter()
        .enumerate()
        .flat_map(|(j, (samples, _))| {
            checkpoints(samples.len(), setup.every, setup.max_samples)
                .into_iter()
                .map(move |n| (j, n))
        })
        .collect();
    let tested: Vec<CurvePoint> = points
        .par_iter()
        .map(|(j, n)| test_point(jobs[*j].0, &collected[*j].0, *n, setup))
        .collect::<Result<_>>()?;
    let mut curves: Vec<Curve> = jobs
        .iter()
        .zip(collected)
        .map(|((s, v), (_, rep))| Curve {
            scene: s.name.clone(),
            variant: **v,
            streak_at: rep.streak_reached.then_some(rep.total_samples),
            collection: rep,
            points: Vec::new(),
        })
        .collect();
    for ((j, _), p) in points.into_iter().zip(tested) {
        curves[j].points.push(p);
    }
    Ok(curves)
}

/// The curves as a text table: per scene and variant, samples at the streak, then success %
/// at each checkpoint.
pub fn table(curves: &[Curve]) -> String {
    let mut out = String::new();
    for c in curves {
        let streak = c
            .streak_at
            .map_or("not reached".to_owned(), |n| format!("{n} samples"));
        out += &format!(
            "{:<22} {:<10} streak at {:<12} ({} initial + {} coverage + {} supplemental of {} evaluation pushes, {} queries, {:.0} min)\n",
            c.scene,
            c.variant.name,
            streak,
            c.collection.initial_samples,
            c.collection.coverage_samples,
            c.collection.supplemental_samples,
            c.collection.evaluation_pushes,
            c.collection.queries,
            c.collection.total_minutes,
        );
        let pts: Vec<String> = c
            .points
            .iter()
            .map(|p| format!("{}:{:.0}%", p.samples, p.rate()))
            .collect();
        out += &format!("    {}\n", pts.join(" "));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkpoints_step_and_end_at_the_collection() {
        assert_eq!(checkpoints(110, 25, 1000), vec![25, 50, 75, 100, 110]);
        assert_eq!(checkpoints(100, 25, 1000), vec![25, 50, 75, 100]);
        assert_eq!(checkpoints(900, 300, 600), vec![300, 600]);
        assert_eq!(checkpoints(0, 25, 1000), Vec::<usize>::new());
    }
}
