//! `pushbot bench eval`: how fast the delivery evaluation of Lau, Mitani & Igarashi (§V,
//! Fig. 11) runs, with each of the simulated robot's cameras. The same cells (start × method,
//! [`super::strategy_eval::evaluate_scene`]) are run once with the simulator's truth and once
//! with the rendered camera in the loop, on every core as the evaluation runs them; each run
//! says its trials per second of wall time and its real-time factor (simulated seconds of the
//! trials over wall seconds).

use std::sync::Mutex;
use std::time::Instant;

use anyhow::Result;

use super::strategy_eval::{Method, TrialSetup, evaluate_scene};
use crate::sim::robot::SimCamera;
use crate::strategy::sample::Sample;

/// One camera's run of the bench's cells.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CameraRate {
    /// `truth` or `rendered`.
    pub camera: &'static str,
    /// Trials run.
    pub trials: usize,
    /// Trials that reached the goal.
    pub successes: usize,
    /// Wall time of the run, s.
    pub wall_s: f64,
    /// Simulated time of all its trials, s.
    pub sim_s: f64,
    /// Trials per second of wall time.
    pub trials_per_s: f64,
    /// Simulated seconds per wall second, all cores together.
    pub realtime_factor: f64,
    /// Cores the cells ran on.
    pub threads: usize,
}

/// What [`bench()`] measured.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EvalBench {
    /// The scene's name.
    pub scene: String,
    /// Start positions of the cells.
    pub starts: Vec<String>,
    /// Methods of the cells.
    pub methods: Vec<Method>,
    /// Trials a cell.
    pub trials_per_cell: usize,
    /// The truth camera's run.
    pub truth: CameraRate,
    /// The rendered camera's run.
    pub rendered: CameraRate,
}

/// Run the cells `starts` × `methods` of `setup` (`trials` each; the learned method from
/// `samples`) with the truth camera, then with the rendered one, and time both.
pub fn bench(
    setup: &TrialSetup,
    methods: &[Method],
    samples: &[Sample],
    starts: &[String],
    trials: usize,
) -> Result<EvalBench> {
    let run = |camera: SimCamera, name: &'static str| -> Result<CameraRate> {
        let mut s = setup.clone();
        s.sim.camera = camera;
        let sim_s = Mutex::new(0.0);
        let start = Instant::now();
        let (results, _) = evaluate_scene(
            &s,
            methods,
            samples,
            starts,
            trials,
            &|_, _| None,
            &|_, _, runs| {
                let t: f64 = runs.unwrap_or_default().iter().map(|d| d.time).sum();
                if let Ok(mut sum) = sim_s.lock() {
                    *sum += t;
                }
                Ok(())
            },
        )?;
        let wall_s = start.elapsed().as_secs_f64().max(1e-9);
        let sim_s = sim_s.into_inner().unwrap_or(0.0);
        let run: usize = results.iter().map(|r| r.trials).sum();
        Ok(CameraRate {
            camera: name,
            trials: run,
            successes: results.iter().map(|r| r.successes).sum(),
            wall_s,
            sim_s,
            trials_per_s: run as f64 / wall_s,
            realtime_factor: sim_s / wall_s,
            threads: rayon::current_num_threads().min(starts.len() * methods.len() * trials),
        })
    };
    let truth = run(SimCamera::Truth, "truth")?;
    let rendered = run(SimCamera::Rendered, "rendered")?;
    Ok(EvalBench {
        scene: setup.scene.name.clone(),
        starts: starts.to_vec(),
        methods: methods.to_vec(),
        trials_per_cell: trials,
        truth,
        rendered,
    })
}
