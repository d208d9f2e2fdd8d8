//! Lau, Mitani & Igarashi's collection (Algorithm 1) and delivery (Algorithm 2) on the simulated
//! robot in process, and the dipole baseline beside it.

use indicatif::ProgressBar;
use nalgebra::Vector2;
use pushbot::exec::collect::{CollectParams, collect, reset_robot_obj_boundary, safe_spin};
use pushbot::exec::deliver::{DeliveryParams, deliver_learned};
use pushbot::exec::io::RobotIo;
use pushbot::experiments::strategy_eval::{Method, TrialSetup, run_start};
use pushbot::sim::robot::{SimRobot, SimRobotOptions};
use pushbot::strategy::regression::{KernelParams, PushStrategy};
use pushbot::strategy::sample::Sample;
use pushbot::strategy::store::{StrategyWriter, load};
use pushbot_sim::{Pose, Scene};

fn initial_only(k: usize, seed: u64) -> CollectParams {
    CollectParams {
        initial: k,
        streak: 0,
        max_queries: 0,
        seed,
        ..CollectParams::default()
    }
}

/// The in-process simulated robot on the preset `scene`, seeded.
fn sim_robot(scene: &str, seed: u64) -> SimRobot {
    SimRobot::new(
        Scene::preset(scene).unwrap(),
        None,
        None,
        SimRobotOptions {
            seed,
            ..SimRobotOptions::default()
        },
    )
    .unwrap()
}

fn collect_samples(
    scene: &str,
    k: usize,
    seed: u64,
    mut w: Option<&mut StrategyWriter>,
) -> Vec<Sample> {
    let mut io = sim_robot(scene, seed);
    let mut strat = PushStrategy::new(Vec::new(), KernelParams::default());
    let rep = collect(
        &mut io,
        &mut strat,
        &initial_only(k, seed),
        &mut |s| {
            if let Some(w) = w.as_deref_mut() {
                w.append(s)?;
            }
            Ok(())
        },
        &ProgressBar::hidden(),
    )
    .unwrap();
    assert_eq!(rep.initial_samples, k, "{rep:?}");
    assert_eq!(strat.len(), k + rep.coverage_samples);
    strat.samples().to_vec()
}

#[test]
fn collected_samples_reload_identically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("irregular.strategy");
    let (mut w, before) = StrategyWriter::open(&path, "irregular").unwrap();
    assert!(before.is_empty());
    let samples = collect_samples("lau-irregular", 25, 3, Some(&mut w));
    drop(w);
    let file = load(&path).unwrap();
    assert_eq!(file.object, "irregular");
    assert_eq!(file.samples, samples);
    // Every sample is a push that moved the object, with the robot near it beforehand.
    for s in &samples {
        assert!(s.s_len() >= 0.003, "{s:?}");
        assert!(s.p[0].hypot(s.p[1]) < 0.25, "{s:?}");
    }
}

#[test]
fn learned_delivery_succeeds_from_two_starts_and_dipole_runs_beside_it() {
    let samples = collect_samples("lau-irregular", 160, 5, None);
    let setup = TrialSetup {
        scene: Scene::preset("lau-irregular").unwrap(),
        object: None,
        sim: SimRobotOptions {
            seed: 11,
            ..SimRobotOptions::default()
        },
        delivery: DeliveryParams {
            time_limit: 240.0,
            ..DeliveryParams::default()
        },
        kernel: KernelParams::default(),
    };
    let goal = setup.goal().unwrap();
    for start in ["A", "C"] {
        let (res, runs) = run_start(&setup, Method::Learned, &samples, start, 1).unwrap();
        assert_eq!(res.successes, 1, "{start}: {res:?} {:?}", runs[0]);
        // The verdict saw the marker within 2.2 cm; one more (noisy) look agrees: the two
        // looks differ by σ√2 per axis (σ = 1 mm), so within 3σ√2 ≈ 4.2 mm.
        assert!(
            runs[0].final_distance < 0.022 + 0.0042,
            "{:?}",
            runs[0].final_distance
        );
        // The object really travelled from its start to the goal.
        let p = setup.scene.position(start).unwrap();
        let straight = (goal - Vector2::new(p.x, p.y)).norm();
        assert!(runs[0].object_path >= straight - 0.03, "{runs:?}");
    }
    // The baseline on the same set-up: it runs to a verdict, and it pushes.
    let (res, runs) = run_start(&setup, Method::Dipole, &[], "A", 1).unwrap();
    assert_eq!(res.trials, 1);
    assert!(runs[0].success || runs[0].failure.is_some());
    assert!(runs[0].robot_path > 0.1, "{:?}", runs[0]);
}

#[test]
fn reset_robot_obj_boundary_brings_the_object_back() {
    let mut scene = Scene::preset("lau-irregular").unwrap();
    // Object 3.5 cm past the lower boundary (inset 0.1 m), robot above it.
    scene.objects[0].pose = Pose::new(0.8, 0.065, 0.3);
    scene.robot.start = Pose::new(0.8, 0.25, -1.5);
    let mut io = SimRobot::new(scene, None, None, SimRobotOptions::default()).unwrap();
    let ws = io.workspace();
    assert!(!ws.boundary.contains(io.object_pose().position()));
    let back = reset_robot_obj_boundary(&mut io, 0.02, 0.004).unwrap();
    let o = io.true_object_pose();
    assert!(back, "object at {o:?}");
    assert!(ws.boundary.contains(o.position()), "{o:?}");
}

#[test]
fn delivery_adds_supplemental_samples_at_once() {
    let samples = collect_samples("lau-scissors", 60, 8, None);
    let scene = Scene::preset("lau-scissors").unwrap();
    let mut io = SimRobot::new(scene, None, Some("B"), SimRobotOptions::default()).unwrap();
    let mut strat = PushStrategy::new(samples.iter().copied(), KernelParams::default());
    let mut added = Vec::new();
    let goal = Vector2::new(0.8, 0.6);
    let d = deliver_learned(
        &mut io,
        &mut strat,
        goal,
        &DeliveryParams {
            time_limit: 60.0,
            ..DeliveryParams::default()
        },
        &mut |s| {
            added.push(*s);
            Ok(())
        },
    )
    .unwrap();
    assert!(d.steps > 0);
    assert!(!added.is_empty());
    assert_eq!(strat.len(), samples.len() + added.len());
    assert_eq!(&strat.samples()[samples.len()..], &added[..]);
}

#[test]
fn collect_once_then_deliver_around_a_wall_from_the_cache() {
    use pushbot::experiments::delivery::{collect_and_deliver, collect_or_load};
    use pushbot::planner::global::{
        ObstacleParams, clearance, path_length, scene_obstacles, shortest_object_path,
    };
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("irregular.strategy");
    let scene = Scene::preset("lau-obstacles").unwrap();
    let sim = SimRobotOptions {
        seed: 4,
        ..SimRobotOptions::default()
    };
    let params = initial_only(160, 4);
    let pb = ProgressBar::hidden();
    // First call collects (on the table without the wall) and writes the cache …
    let (first, rep) = collect_or_load(
        &scene,
        None,
        &cache,
        sim,
        &params,
        KernelParams::default(),
        &pb,
    )
    .unwrap();
    assert_eq!(rep.unwrap().initial_samples, 160);
    // … the second reuses it.
    let (again, rep) = collect_or_load(
        &scene,
        None,
        &cache,
        sim,
        &params,
        KernelParams::default(),
        &pb,
    )
    .unwrap();
    assert!(rep.is_none());
    assert_eq!(first, again);
    let out = collect_and_deliver(
        &scene,
        None,
        &cache,
        sim,
        &params,
        &DeliveryParams::default(),
        &ObstacleParams::default(),
        &pb,
    )
    .unwrap();
    assert!(out.collection.is_none());
    let d = &out.result.delivery;
    assert!(
        d.success,
        "{:?} after sub-goals {:?}",
        d.failure, out.result.subgoals
    );
    assert!(d.final_distance < 0.022);
    // The global path keeps the object's bounding circle off the wall, and the object really
    // went around the wall's lower end (x 0.78–0.88 m, y ≥ 0.55 m).
    let wall = scene_obstacles(&scene);
    for q in &out.result.path {
        assert!(clearance(Vector2::new(q[0], q[1]), &wall) > 0.07, "{q:?}");
    }
    let (start, goal) = (out.start.position(), Vector2::new(1.25, 0.6));
    assert!(start.x < 0.78 && goal.x > 0.88);
    let crossing = d
        .trajectory
        .iter()
        .map(|(_, o)| o.position())
        .find(|o| (0.78..=0.88).contains(&o.x))
        .expect("the object passed the wall's x");
    assert!(crossing.y < 0.55, "crossed at {crossing:?}");
    // Following the path's moving sub-goal, the object's path is within 1.3× the shortest
    // collision-free path of its bounding circle, measured on the camera's track.
    let shortest = shortest_object_path(
        &SimRobot::new(scene.clone(), None, None, sim)
            .unwrap()
            .workspace(),
        &wall,
        start,
        goal,
        &ObstacleParams::default(),
    )
    .expect("a shortest path");
    let ratio = d.object_path / path_length(&shortest);
    assert!((1.0..1.3).contains(&ratio), "path ratio {ratio}");
}

/// The live layout (`pushbot eval delivery --hil`): the robot cannot leave the table, and the
/// boundary lies 0.2 m inside it.
fn live_like(scene: Scene, seed: u64) -> SimRobot {
    SimRobot::new(
        scene,
        None,
        None,
        SimRobotOptions {
            seed,
            table_margin: 0.0,
            boundary_inset: 0.2,
            ..SimRobotOptions::default()
        },
    )
    .unwrap()
}

#[test]
fn a_random_push_towards_the_boundary_is_drawn_again() {
    use rand::SeedableRng;
    let mut scene = Scene::preset("lau-irregular").unwrap();
    // Object 2 cm inside the left boundary, the robot below it heading up and to the left.
    scene.objects[0].pose = Pose::new(0.22, 0.6, 0.0);
    scene.robot.start = Pose::new(0.3, 0.45, 1.87);
    let mut io = live_like(scene, 3);
    let ws = io.workspace();
    let params = initial_only(1, 3);
    let (r, o) = (io.robot_pose(), io.object_pose().position());
    let end = |a: f64| o + params.push_max * Vector2::new((r.theta + a).cos(), (r.theta + a).sin());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    // Straight ahead would push the marker out: another heading, whose push stays inside.
    assert!(!ws.boundary.contains(end(0.0)));
    let a = safe_spin(&mut io, &mut rng, 0.0, &params);
    assert!(
        ws.boundary.contains(end(a)),
        "spin {a} ends at {:?}",
        end(a)
    );
    assert!(a.abs() <= params.spin_max + 1e-12);
    // A safe draw is kept as drawn (the paper's random pushes are unchanged away from the edge).
    let safe = -1.0;
    assert!(ws.boundary.contains(end(safe)));
    assert_eq!(safe_spin(&mut io, &mut rng, safe, &params), safe);
}

#[test]
fn an_object_against_the_edge_is_reported_not_slid_into_the_corner() {
    let mut scene = Scene::preset("lau-irregular").unwrap();
    // Object 2 cm from the top edge of the table, where the robot cannot get behind it.
    scene.objects[0].pose = Pose::new(0.6, 1.12, 0.0);
    scene.robot.start = Pose::new(0.45, 0.9, 0.5);
    let mut io = live_like(scene, 4);
    let before = io.true_object_pose();
    let back = reset_robot_obj_boundary(&mut io, 0.02, 0.004).unwrap();
    let after = io.true_object_pose();
    assert!(!back, "object at {after:?}");
    assert!(
        (after.position() - before.position()).norm() < 0.01,
        "the reset moved the object from {before:?} to {after:?}"
    );
    // The collection stops with an error that says where the object is.
    let mut strat = PushStrategy::new(Vec::new(), KernelParams::default());
    let err = collect(
        &mut io,
        &mut strat,
        &initial_only(10, 4),
        &mut |_| Ok(()),
        &ProgressBar::hidden(),
    )
    .unwrap_err();
    assert!(
        format!("{err:#}").contains("stuck outside the boundary"),
        "{err:#}"
    );
}

#[test]
fn a_delivery_started_beside_the_boundary_stays_inside_it() {
    // A small strategy (the HIL test's 120 pushes) and start C, 5 cm inside the live boundary:
    // its pushes drift sideways, and the boundary guard keeps the object inside. (Without the
    // guard such a start loses the object over the edge in a few per cent of trials — 13 of 480
    // in the README's sweep — too rare to show in the handful of trials a test can afford.)
    let scene = Scene::preset("lau-irregular").unwrap();
    let mut io = live_like(scene.clone(), 8);
    let mut strat = PushStrategy::new(Vec::new(), KernelParams::default());
    collect(
        &mut io,
        &mut strat,
        &initial_only(120, 8),
        &mut |_| Ok(()),
        &ProgressBar::hidden(),
    )
    .unwrap();
    let samples = strat.samples().to_vec();
    let ws_boundary = io.workspace().boundary;
    let setup = |delivery: DeliveryParams| TrialSetup {
        scene: scene.clone(),
        object: None,
        sim: SimRobotOptions {
            seed: 8,
            table_margin: 0.0,
            boundary_inset: 0.2,
            ..SimRobotOptions::default()
        },
        delivery,
        kernel: KernelParams::default(),
    };
    let (res, runs) = run_start(
        &setup(DeliveryParams::default()),
        Method::Learned,
        &samples,
        "C",
        6,
    )
    .unwrap();
    assert_eq!(res.successes, 6, "with the guard: {res:?}");
    // The verdict saw the marker within 2.2 cm; one more (noisy) look agrees within 3σ√2.
    let finals: Vec<f64> = runs.iter().map(|d| d.final_distance).collect();
    assert!(finals.iter().all(|&d| d < 0.022 + 0.0042), "{finals:?}");
    // Every trial kept the object inside the boundary the whole way.
    assert!(
        runs.iter().all(|d| d
            .trajectory
            .iter()
            .all(|(_, o)| ws_boundary.contains(o.position()))),
        "the object left the boundary with the guard"
    );
}

#[test]
fn a_boundary_reset_does_not_slide_an_off_centre_marker_along_the_edge() {
    // The marker near a corner of the object: a push aimed at it turns the object, which then
    // slides along the boundary instead of going back in. Each round of the reset stops once the
    // object has slid `SLIDE_LIMIT` (5 cm) along the edge, so it stays where the robot can get
    // behind it. Without that limit, from two of these headings it slid 46 cm into the corner.
    let base = Scene::preset("lau-irregular-corner").unwrap();
    let m = base.objects[0].marker.as_ref().unwrap();
    let (mx, my) = (m.x, m.y);
    let mut inside = 0;
    for k in 0..8 {
        let th = k as f64 * std::f64::consts::FRAC_PI_4;
        let mut scene = base.clone();
        // The marker 1.3 cm outside the left boundary (x = 0.2), half-way up the table.
        let (s, c) = th.sin_cos();
        scene.objects[0].pose = Pose::new(0.187 - (c * mx - s * my), 0.6 - (s * mx + c * my), th);
        scene.robot.start = Pose::new(0.45, 0.6, std::f64::consts::PI);
        let mut io = live_like(scene, 20 + k);
        let before = io.object_pose().position();
        let back = reset_robot_obj_boundary(&mut io, 0.02, 0.004).unwrap();
        let after = io.object_pose().position();
        eprintln!("heading {k}×45°: back {back}, marker {before:?} → {after:?}");
        inside += usize::from(back);
        assert!(
            (after.y - before.y).abs() < 0.15,
            "heading {k}×45°: the marker slid from {before:?} to {after:?}"
        );
    }
    assert_eq!(inside, 8, "back inside from {inside} of 8 headings");
}

/// The collection explores with the paper's keys whatever the strategy's turn weight (the
/// special case's preference for pushes that do not turn the object, Algorithm 2 beyond the
/// paper), and gives the strategy its own parameters back: on the snake, whose pushes turn it
/// most, a collection with test deliveries makes the same samples either way.
#[test]
fn the_collection_keeps_the_papers_keys_and_gives_the_strategy_its_own_back() {
    let run = |turn_weight: f64| {
        let mut io = sim_robot("lau-snake", 5);
        let kernel = KernelParams {
            turn_weight,
            ..KernelParams::default()
        };
        let mut strat = PushStrategy::new(Vec::new(), kernel);
        let params = CollectParams {
            initial: 40,
            streak: 3,
            max_queries: 3,
            seed: 5,
            ..CollectParams::default()
        };
        let rep = collect(
            &mut io,
            &mut strat,
            &params,
            &mut |_| Ok(()),
            &ProgressBar::hidden(),
        )
        .unwrap();
        assert_eq!(strat.params(), kernel, "the strategy's own parameters");
        (rep.queries, strat.samples().to_vec())
    };
    let (queries, paper) = run(0.0);
    let (_, weighted) = run(0.1);
    assert!(queries > 0, "the collection made test deliveries");
    assert_eq!(paper.len(), weighted.len());
    assert!(paper == weighted, "the samples differ");
}

/// The command succeeded; its error output shown if not.
fn assert_ran(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `eval delivery --resume FILE`: a run interrupted after some of its cells (here the file
/// keeps the header and start A's cell, that cell's robot path altered so that reading it back
/// shows) runs only the cells missing, and its results are otherwise the whole run's. A run
/// with a start more adds that start's cell. Another run's file (other `--trials`) is refused
/// with what differs, and left as it was.
#[test]
fn an_evaluation_resumed_from_its_file_runs_only_the_missing_cells() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("cells.jsonl");
    let run_from = |starts: &str, trials: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
            .args([
                "eval",
                "delivery",
                "--scene",
                "lau-irregular",
                "--method",
                "dipole",
            ])
            .args([
                "--start",
                starts,
                "--trials",
                trials,
                "--sim-camera",
                "truth",
                "--json",
            ])
            .arg("--resume")
            .arg(&file)
            .output()
            .unwrap()
    };
    let run = |trials: &str| run_from("A,B", trials);
    let results = |out: &std::process::Output| -> Vec<serde_json::Value> {
        assert_ran(out);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["scenes"][0]["results"].as_array().unwrap().clone()
    };
    let whole = results(&run("2"));
    assert_eq!(whole.len(), 2);
    let text = std::fs::read_to_string(&file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "a header and two cells: {text}");
    let mut a: serde_json::Value = lines[1..]
        .iter()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .find(|c| c["result"]["start"] == "A")
        .unwrap();
    a["result"]["mean_robot_path_m"] = serde_json::json!(123.0);
    std::fs::write(&file, format!("{}\n{a}\n", lines[0])).unwrap();
    let resumed = results(&run("2"));
    assert_eq!(resumed[0]["start"], "A");
    assert_eq!(
        resumed[0]["mean_robot_path_m"], 123.0,
        "start A was run again"
    );
    let mut expected = whole[0].clone();
    expected["mean_robot_path_m"] = serde_json::json!(123.0);
    assert_eq!(resumed[0], expected);
    assert_eq!(resumed[1], whole[1], "start B, run again, differs");
    assert_eq!(std::fs::read_to_string(&file).unwrap().lines().count(), 3);
    let more = results(&run_from("A..C", "2"));
    assert_eq!(more.len(), 3);
    assert_eq!(more[..2], resumed[..]);
    assert_eq!(more[2]["start"], "C");
    assert_eq!(std::fs::read_to_string(&file).unwrap().lines().count(), 4);
    // Another run's file.
    let before = std::fs::read(&file).unwrap();
    let other = run("3");
    assert!(!other.status.success());
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(err.contains("trials 2 in the file, 3 now"), "{err}");
    assert_eq!(std::fs::read(&file).unwrap(), before);
}

/// `eval delivery --trace-dir DIR` writes every trial it runs: a JSON file with its steps
/// (as many as its trajectory) and a drawing, named by scene, start, method and trial.
#[test]
fn every_trial_run_is_traced_to_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let traces = dir.path().join("traces");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args(["eval", "delivery", "--scene", "lau-irregular", "--method"])
        .args([
            "dipole",
            "--start",
            "A,B",
            "--trials",
            "2",
            "--sim-camera",
            "truth",
        ])
        .args(["--json", "--trace-dir"])
        .arg(&traces)
        .output()
        .unwrap();
    assert_ran(&out);
    let mut names: Vec<String> = std::fs::read_dir(&traces)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let want: Vec<String> = ["A", "B"]
        .iter()
        .flat_map(|s| (0..2).map(move |t| format!("lau-irregular-{s}-dipole-{t:03}")))
        .flat_map(|n| [format!("{n}.json"), format!("{n}.svg")])
        .collect();
    assert_eq!(names, want);
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(traces.join("lau-irregular-B-dipole-001.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(v["start"], "B");
    assert_eq!(v["trial"], 1);
    let steps = v["trajectory"].as_array().unwrap().len();
    assert!(steps > 10, "{steps} steps");
    assert_eq!(v["delivery"]["success"], true);
}
