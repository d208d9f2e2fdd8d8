//! The demo's pipeline (`pushbot demo`): the three papers' tasks run one after the other on a
//! robot seen by a camera — the built-in simulated target or a real robot — each stage with a
//! progress bar, into a report folder (`report.html`, `summary.json`, figures, `demo.log`):
//!
//! 1. **strategy** (Lau, Mitani & Igarashi): collect a pushing strategy for an irregular object
//!    (or reuse the cached one), then deliver the object to its goal among obstacles;
//! 2. **rearrange** (Ben-Shahar & Rivlin): plan an optimal rearrangement of two boxes (cost map
//!    and restoration) and execute it, re-observing and snapping to the grid;
//! 3. **stable** (Lynch & Mason): plan stable pushes of the slider among obstacles and drive
//!    them closed loop (the camera watching every push).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use indicatif::{ProgressBar, ProgressStyle};
use pushbot_world::Scene;

use crate::exec::record::{Recorder, TracePoint, TruthProbe};
use crate::exec::{LiveOptions, LiveRobot};
use crate::planner::rearrange::Problem as RearrangeProblem;
use crate::report::{Report, StageReport, figure};
use crate::robot::{LinkOptions, Recovery};
use crate::sim::SimTarget;
use crate::sim::target::LinkFaults;
use crate::strategy::sample::Pose2;

/// The stages, in the order they run.
pub const STAGES: [&str; 3] = ["strategy", "rearrange", "stable"];

/// What the demo runs, checked by the caller (scenes loaded, stages known).
#[derive(Debug, Clone)]
pub struct DemoOptions {
    /// Folder for the report (created; files in it are replaced).
    pub out: PathBuf,
    /// Stages to run, in order (names of [`STAGES`]).
    pub stages: Vec<String>,
    /// The strategy stage's scene.
    pub strategy_scene: Scene,
    /// The rearrangement case's name and its grid problem.
    pub rearrange: (String, RearrangeProblem),
    /// The stable stage's preset or file.
    pub stable_name: String,
    /// A real robot's serial port and camera; `None`: the built-in simulated target.
    pub robot: Option<(String, String)>,
    /// Simulated seconds per wall second of the built-in target.
    pub speed: f64,
    /// Seed of every random draw.
    pub seed: u64,
    /// Also render every figure as PNG.
    pub png: bool,
    /// Where collected pushing strategies are cached (default: OUT/cache).
    pub cache: Option<PathBuf>,
    /// Keep a live view in OUT/live/live.html.
    pub view: bool,
    /// No progress bars (`--json`).
    pub quiet: bool,
    /// Link faults injected between the host and the built-in simulated target (not with a
    /// real robot).
    pub faults: Option<LinkFaults>,
    /// Objects moved by hand mid-run on the built-in simulated target (each applies in the
    /// stages whose scene has that object).
    pub disturb: Vec<crate::sim::target::Disturbance>,
    /// The serial link's settings (how long to wait for a port that went away).
    pub link: LinkOptions,
    /// Recover a broken link and go on (`--no-recover` turns it off).
    pub recover: bool,
    /// The camera's lens (`--intrinsics`); `None`: each stage scene's own, if any.
    pub lens: Option<pushbot_world::lens::Intrinsics>,
    /// Record the run into this MCAP file (Foxglove schemas; see [`crate::recording`]).
    pub record: Option<PathBuf>,
    /// Serve the recording's channels live to Foxglove on this address (`HOST:PORT`).
    pub foxglove: Option<String>,
}

/// Run the demo's stages into a report; a stage that fails is recorded as failed and the next
/// one runs. Returns the report, written.
pub fn run(opts: &DemoOptions) -> Result<(Report, PathBuf)> {
    let report = Report::create(&opts.out, "pushbot demo", opts.png)?;
    let log = std::fs::File::create(opts.out.join("demo.log"))
        .map_err(|e| anyhow!("creating demo.log: {e}"))?;
    let recording = match &opts.record {
        Some(path) => {
            let mut rec = crate::recording::Recording::create(path)?;
            if let Some(addr) = &opts.foxglove {
                let at = rec.serve_foxglove(addr)?;
                tracing::info!("Foxglove live view: connect to ws://{at}");
            }
            Some(crate::recording::RecordingHandle::new(rec))
        }
        None => None,
    };
    let mut ctx = Ctx {
        opts,
        report,
        log,
        recoveries: Vec::new(),
        recording,
    };
    for stage in &opts.stages {
        let started = std::time::Instant::now();
        let result = match stage.as_str() {
            "strategy" => stage_strategy(&mut ctx, &opts.strategy_scene),
            "rearrange" => stage_rearrange(&mut ctx, &opts.rearrange.0, &opts.rearrange.1),
            _ => stage_stable(&mut ctx, &opts.stable_name),
        };
        let mut rep = match result {
            Ok(r) => r,
            Err(e) => {
                let mut r = StageReport::new(stage, stage, "");
                r.notes.push(format!("error: {e:#}"));
                r
            }
        };
        rep.wall_s = started.elapsed().as_secs_f64();
        let recoveries = std::mem::take(&mut ctx.recoveries);
        rep.number("link_recoveries", recoveries.len());
        for r in &recoveries {
            rep.notes.push(recovery_note(r));
        }
        if let Some(rec) = &ctx.recording {
            // The stage's report goes into the recording with its figures' SVG text, so that a
            // replay writes the same report.
            let mut svgs = std::collections::BTreeMap::new();
            for (file, _) in &rep.figures {
                let stem = file.rsplit_once('.').map_or(file.as_str(), |(s, _)| s);
                if let Ok(svg) =
                    std::fs::read_to_string(ctx.report.dir().join(format!("{stem}.svg")))
                {
                    svgs.insert(stem.to_string(), svg);
                }
            }
            rec.with(|r| r.stage_report(&rep, &svgs));
        }
        ctx.log(&format!(
            "stage {stage}: {} in {:.1} s wall, {:.1} s mission time",
            if rep.success { "reached" } else { "FAILED" },
            rep.wall_s,
            rep.mission_s
        ));
        for n in &rep.notes {
            ctx.log(&format!("  {n}"));
        }
        ctx.report.add(rep);
    }
    let page = ctx.report.write()?;
    if let Some(h) = &ctx.recording {
        h.finish()?;
    }
    Ok((ctx.report, page))
}

/// One line for the report on a recovery of the link.
fn recovery_note(r: &Recovery) -> String {
    let what = r.interrupted.as_ref().map_or(String::new(), |i| {
        format!(
            "; {} #{} {}",
            i.command,
            i.seq,
            i.outcome.as_deref().unwrap_or("outcome unknown")
        )
    });
    format!(
        "link recovered at robot time {:.1} s in {:.2} s ({}{what})",
        r.robot_time_s, r.wall_s, r.cause
    )
}

/// Everything a stage needs.
struct Ctx<'a> {
    opts: &'a DemoOptions,
    report: Report,
    log: std::fs::File,
    /// Recoveries of the link during the stage running.
    recoveries: Vec<Recovery>,
    recording: Option<crate::recording::RecordingHandle>,
}

impl Ctx<'_> {
    fn log(&mut self, line: &str) {
        let _ = writeln!(self.log, "{line}");
        if let Some(h) = &self.recording {
            h.with(|r| r.log(2, "demo", line));
        }
        tracing::info!("{line}");
    }

    fn bar(&self, stage: &str) -> ProgressBar {
        let pb = if self.opts.quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new_spinner()
        };
        pb.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {prefix:10} {wide_msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        pb.set_prefix(stage.to_string());
        pb.enable_steady_tick(std::time::Duration::from_millis(120));
        pb
    }

    /// Run `f` on the robot: the built-in simulated target serving `scene`, or the real one.
    fn with_robot<T>(
        &mut self,
        scene: &Scene,
        object: Option<&str>,
        ids: &[String],
        f: impl FnOnce(&mut Recorder<'_>) -> Result<T>,
    ) -> Result<(T, Vec<TracePoint>)> {
        let speed = if self.opts.robot.is_some() {
            1.0
        } else {
            self.opts.speed
        };
        let opts = LiveOptions {
            object: object.map(str::to_owned),
            // With link faults injected the watchdog is the real robot's (1 s of robot time),
            // so that a cut stops the robot as it would on the table; otherwise it grows with
            // the simulation's speed (the host's threads get less wall time per robot second).
            watchdog_ms: if self.opts.faults.is_some() {
                1000
            } else {
                (1000.0 * speed.max(1.0)).min(5000.0) as u16
            },
            view_dir: self.opts.view.then(|| self.opts.out.join("live")),
            link: self.opts.link.clone(),
            recover: self.opts.recover,
            lens: self.opts.lens,
            recording: self.recording.clone(),
            ..LiveOptions::default()
        };
        match &self.opts.robot {
            Some((port, camera)) => {
                let mut live = LiveRobot::connect(port, camera, scene, opts)?;
                let mut rec =
                    Recorder::new(&mut live, ids, None).with_recording(self.recording.clone());
                let out = f(&mut rec);
                let trace = rec.into_trace();
                self.recoveries.extend(live.recoveries());
                Ok((out?, trace))
            }
            None => {
                // The built-in camera is seen through the lens the host is told of.
                let mut seen = scene.clone();
                if self.opts.lens.is_some() {
                    seen.camera.lens = self.opts.lens;
                }
                let disturb: Vec<_> = self
                    .opts
                    .disturb
                    .iter()
                    .filter(|d| scene.objects.iter().any(|o| o.id == d.object))
                    .cloned()
                    .collect();
                let target = SimTarget::start_with(
                    &seen,
                    self.opts.seed,
                    speed,
                    None,
                    self.opts.faults,
                    disturb,
                )?;
                self.log(&format!(
                    "simulated target: serial {} camera {}",
                    target.port(),
                    target.camera()
                ));
                let result = {
                    let mut live = LiveRobot::connect(target.port(), target.camera(), scene, opts)?;
                    let probe: TruthProbe<'_> = Box::new(|| {
                        let t = target.sim().truth().pose;
                        let objects = target
                            .sim()
                            .objects()
                            .into_iter()
                            .map(|(id, p)| (id, Pose2::new(p.x, p.y, p.theta)))
                            .collect();
                        (Pose2::new(t.x, t.y, t.theta), objects)
                    });
                    let mut rec = Recorder::new(&mut live, ids, Some(probe))
                        .with_recording(self.recording.clone());
                    let out = f(&mut rec);
                    let trace = rec.into_trace();
                    self.recoveries.extend(live.recoveries());
                    out.map(|o| (o, trace))
                };
                target.shutdown()?;
                result
            }
        }
    }
}

/// Lau et al.: collect (or reuse) the strategy, deliver among obstacles through the link.
fn stage_strategy(ctx: &mut Ctx<'_>, scene: &Scene) -> Result<StageReport> {
    use crate::exec::collect::CollectParams;
    use crate::exec::deliver::DeliveryParams;
    use crate::exec::deliver_path::deliver_among_obstacles;
    use crate::experiments::delivery::collect_or_load;
    use crate::planner::global::{ObstacleParams, scene_goal, scene_obstacles};
    use crate::sim::robot::SimRobotOptions;
    use crate::strategy::figures::strategy_svg;
    use crate::strategy::regression::{KernelParams, PushStrategy};

    let mut st = StageReport::new(
        "strategy",
        "Learned pushing strategy: deliver an irregular object among obstacles",
        "Lau, Mitani & Igarashi §III-C–E (Algorithms 1, 2)",
    );
    let object = scene
        .objects
        .first()
        .ok_or_else(|| anyhow!("scene {} has no object", scene.name))?
        .clone();
    let cache_dir = ctx
        .opts
        .cache
        .clone()
        .unwrap_or_else(|| ctx.opts.out.join("cache"));
    std::fs::create_dir_all(&cache_dir)
        .with_context(|| format!("creating {}", cache_dir.display()))?;
    let cache = cache_dir.join(format!("{}-{}.strategy", scene.name, object.id));
    let pb = ctx.bar("strategy");
    pb.set_message(format!(
        "pushing strategy for {} ({})",
        object.id,
        cache.display()
    ));
    let kernel = KernelParams::default();
    let sim = SimRobotOptions {
        seed: ctx.opts.seed,
        ..SimRobotOptions::default()
    };
    let (samples, collection) = collect_or_load(
        scene,
        Some(&object.id),
        &cache,
        sim,
        &CollectParams::default(),
        kernel,
        &pb,
    )?;
    st.number("samples", samples.len());
    st.number("collected_now", collection.is_some());
    if let Some(c) = &collection {
        st.number("collection", serde_json::to_value(c)?);
    }
    let marker = object.marker.map_or([0.0, 0.0], |m| [m.x, m.y]);
    let outline: Vec<[f64; 2]> = object
        .outline
        .iter()
        .map(|v| [v[0] - marker[0], v[1] - marker[1]])
        .collect();
    let f = ctx
        .report
        .figure("strategy-samples", &strategy_svg(&samples, &outline))?;
    st.figures.push((
        f,
        format!(
            "The pushing strategy of {} (Fig. 7): each sample's robot motion from where it pushed, and the object's motion",
            object.id
        ),
    ));
    pb.set_message("delivering through the serial port and the camera");
    let goal = scene_goal(scene, Some(&object.id))?;
    let obstacles = scene_obstacles(scene);
    let ids = vec![object.id.clone()];
    let (res, trace) = ctx.with_robot(scene, Some(&object.id), &ids, |io| {
        let mut strategy = PushStrategy::new(samples.iter().copied(), kernel);
        deliver_among_obstacles(
            io,
            &mut strategy,
            goal,
            &obstacles,
            &DeliveryParams::default(),
            &ObstacleParams::default(),
            &mut |_| Ok(()),
        )
    })?;
    pb.finish_and_clear();
    let d = &res.delivery;
    st.success = d.success;
    st.mission_s = d.time;
    st.number("steps", d.steps);
    st.number("repositions", d.repositions);
    st.number("legs", res.subgoals.len());
    st.number("final_distance_m (camera)", d.final_distance);
    if let Some(last) = trace.last().and_then(|p| p.truth.clone()) {
        let m = scene_marker_truth(&object, &last.1);
        if let Some(m) = m {
            st.number(
                "final_distance_m (truth)",
                (m[0] - goal.x).hypot(m[1] - goal.y),
            );
        }
    }
    if let Some(why) = &d.failure {
        st.notes.push(format!("delivery failed: {why:?}"));
    }
    st.notes.push(format!(
        "{} samples ({}); delivered in {} pushes, {:.0} s of mission time",
        samples.len(),
        if collection.is_some() {
            "collected now"
        } else {
            "from the cache"
        },
        d.steps,
        d.time
    ));
    let f = ctx.report.figure(
        "strategy-delivery",
        &figure::run_svg(scene, &trace, "delivery among obstacles (truth)", true),
    )?;
    st.figures.push((
        f,
        "Delivery (Fig. 8): robot blue, object red, start dashed, goal green".into(),
    ));
    Ok(st)
}

/// Where the object's marker truly is, from its true body pose.
fn scene_marker_truth(
    object: &pushbot_world::scene::Object,
    truth: &[(String, Pose2)],
) -> Option<[f64; 2]> {
    let (_, p) = truth.iter().find(|(id, _)| *id == object.id)?;
    let m = object.marker.map_or([0.0, 0.0], |m| [m.x, m.y]);
    let (s, c) = p.theta.sin_cos();
    Some([p.x + c * m[0] - s * m[1], p.y + s * m[0] + c * m[1]])
}

/// Ben-Shahar & Rivlin: cost map, restoration, execution through the link with snapping.
fn stage_rearrange(
    ctx: &mut Ctx<'_>,
    case: &str,
    problem: &crate::planner::rearrange::Problem,
) -> Result<StageReport> {
    use crate::exec::rearrange::{ExecOptions, execute};
    use crate::planner::rearrange::to_scene::{SceneOptions, scene_for};
    use crate::planner::rearrange::{Model, cost_map, restore, svg::plan_svg_in};

    let mut st = StageReport::new(
        "rearrange",
        &format!("Optimal rearrangement of {case} by pushing"),
        "Ben-Shahar & Rivlin §IV (cost map, restoration), §V",
    );
    let pb = ctx.bar("rearrange");
    pb.set_message("cost map");
    let model = Model::new(problem).map_err(|e| anyhow!("{e}"))?;
    let map = cost_map(&model).map_err(|e| anyhow!("{e}"))?;
    st.number("states_mapped", map.stats.states_mapped);
    st.number("map_ms", map.stats.map_ms);
    let start = model
        .pack(&problem.start)
        .ok_or_else(|| anyhow!("the start of {case} is not free"))?;
    let plan = restore(&model, &map, start).map_err(|e| anyhow!("{e}"))?;
    st.number("plan_cost", plan.cost);
    st.number("plan_steps", plan.steps.len());
    let f = ctx.report.figure(
        "rearrange-plan",
        &plan_svg_in(&model, &plan, Some(SceneOptions::default().cell)),
    )?;
    st.figures.push((
        f,
        format!(
            "The optimal plan of {case}, step by step (Figs. 9–19 style): robot blue, boxes where each stage leaves them, goals dashed; axes in metres"
        ),
    ));
    let scene_opts = SceneOptions::default();
    let scene = scene_for(problem, &scene_opts)?;
    let ids: Vec<String> = scene.objects.iter().map(|o| o.id.clone()).collect();
    pb.set_message("executing through the serial port and the camera");
    let exec = ExecOptions {
        cell: scene_opts.cell,
        fill: scene_opts.fill,
        ..ExecOptions::default()
    };
    let (rep, trace) = ctx.with_robot(&scene, None, &ids, |io| execute(&model, &map, io, &exec))?;
    pb.finish_and_clear();
    st.success = rep.reached;
    st.mission_s = rep.time_s;
    st.number("executed_cost", rep.executed_cost);
    st.number("pushes", rep.pushes);
    st.number("deviations_snapped", rep.deviations);
    // Every re-plan: a box not where the plan had put it, continued from where it was.
    st.number("replans", rep.replans.len());
    if !rep.replans.is_empty() {
        st.number(
            "replanned_from",
            serde_json::to_value(&rep.replans).unwrap_or_default(),
        );
    }
    let f = ctx.report.figure(
        "rearrange-run",
        &figure::run_svg(&scene, &trace, "executed rearrangement (truth)", true),
    )?;
    st.figures.push((
        f,
        "Execution on the simulated target: robot blue, boxes red".into(),
    ));
    Ok(st)
}

/// Lynch & Mason: plan stable pushes for the plated robot (the preset's robot-scale version,
/// [`crate::experiments::stable_trials::ROBOT_SCALE`]), drive them closed loop
/// ([`crate::exec::stable_feedback`]): the camera watches the slider during every push.
fn stage_stable(ctx: &mut Ctx<'_>, name: &str) -> Result<StageReport> {
    use crate::exec::stable_feedback::{FeedbackParams, execute_closed_loop};
    use crate::experiments::stable_trials::StableTask;
    use crate::planner::stable::svg;

    let mut st = StageReport::new(
        "stable",
        &format!("Stable pushing of the slider among obstacles ({name}), closed loop"),
        "Lynch & Mason §3 (STABLE), §4 (planner); closed loop inside the stable set",
    );
    let pb = ctx.bar("stable");
    pb.set_message("planning stable pushes for the plated robot");
    let task = match StableTask::load(name) {
        Ok(t) => t,
        Err(e) => {
            st.notes.push(format!("{e:#}"));
            return Ok(st);
        }
    };
    let (p, pl) = (&task.problem, &task.plan);
    st.number("found", pl.found);
    st.number("plan_cost", pl.cost);
    st.number("pushes_planned", pl.pushes);
    st.number("nodes_expanded", pl.nodes_expanded);
    st.number("plan_ms", pl.plan_time_ms);
    let scene = task.sim_scene()?;
    pb.set_message("pushing closed loop through the serial port and the camera");
    let ids = vec!["slider".to_string()];
    let (run, trace) = ctx.with_robot(&scene, Some("slider"), &ids, |io| {
        execute_closed_loop(p, pl, io, &FeedbackParams::default())
    })?;
    pb.finish_and_clear();
    // The truth where the simulated target reports it, else the camera.
    let end = trace
        .last()
        .and_then(|t| t.truth.as_ref())
        .and_then(|(_, objects)| objects.iter().find(|(id, _)| id == "slider"))
        .map_or(run.end, |(_, q)| {
            crate::planner::stable::Pose::new(q.x, q.y, q.theta)
        });
    st.success = p.in_goal(&end);
    st.mission_s = trace.last().map_or(0.0, |t| t.t - trace[0].t);
    st.number("pushed_m", run.pushed);
    st.number("replans", run.replans);
    st.number("contact_losses", run.contact_losses);
    st.number("replan_ms", run.replan_ms);
    st.number("end_x", end.x);
    st.number("end_y", end.y);
    st.number("end_theta_deg", end.theta.to_degrees());
    st.number(
        "final_error_mm",
        (end.x - p.goal.x).hypot(end.y - p.goal.y) * 1e3,
    );
    if let Some(why) = &run.failure {
        st.notes.push(format!("the closed loop stopped: {why}"));
    }
    if !st.success {
        st.notes.push(format!(
            "the slider ended at ({:.3}, {:.3}, {:.1}°), outside the goal neighbourhood",
            end.x,
            end.y,
            end.theta.to_degrees()
        ));
    }
    let f = ctx
        .report
        .figure("stable-plan", &svg::render_executed(p, Some(pl), &run.path))?;
    st.figures.push((
        f,
        "The plan over stable pushes (Fig. 13–18 style, planned path blue) and the slider's \
         executed path as the camera saw it (green)"
            .into(),
    ));
    let f = ctx.report.figure(
        "stable-run",
        &figure::run_svg(
            &scene,
            &trace,
            "stable pushes executed closed loop (truth)",
            true,
        ),
    )?;
    st.figures.push((
        f,
        "Closed-loop execution on the robot: robot blue, slider red".into(),
    ));
    Ok(st)
}
