//! `pushbot eval delivery --figure 11` end to end (Lau et al. Fig. 11: six objects × starts A–F,
//! both methods, on all cores), and a delivery with the rendered camera in the loop.

use std::process::Command;

/// The whole figure (two of the starts) at one trial per bar, small strategies and a short time limit (what is
/// checked is that every cell runs and lands in the table, the JSON and the figure, not the
/// success rates, which `--trials 50` measures).
#[test]
fn figure_11_runs_every_cell_and_draws_them() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("f11.svg");
    let out = Command::new(pushbot_tests::bin("pushbot"))
        .args([
            "eval",
            "delivery",
            "--figure",
            "11",
            "--trials",
            "1",
            "--initial",
            "40",
            "--streak",
            "0",
            "--time-limit",
            "30",
            "--start",
            "A,F",
            "--sim-camera",
            "truth",
            "--json",
            "--svg",
        ])
        .arg(&svg)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)));
    let scenes = v["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 6, "the six objects");
    let mut cells = 0;
    for s in scenes {
        assert!(s["scene"].as_str().unwrap().starts_with("lau-"));
        // 40 initial pushes, then the exploring collection's push for each way of moving the
        // object they did not cover.
        let c = &s["collection"];
        assert_eq!(c["initial_samples"].as_u64(), Some(40), "{s}");
        assert_eq!(
            s["samples"].as_u64(),
            Some(40 + c["coverage_samples"].as_u64().unwrap()),
            "{s}"
        );
        let results = s["results"].as_array().unwrap();
        assert_eq!(results.len(), 4, "starts A and F × both methods: {s}");
        cells += results.len();
    }
    assert_eq!(cells, 24);
    assert_eq!(v["camera"], "truth");
    let text = std::fs::read_to_string(&svg).unwrap();
    // A bar per cell that succeeded: as many bars of full height as successes (one trial each).
    let successes = scenes
        .iter()
        .flat_map(|s| s["results"].as_array().unwrap())
        .filter(|r| r["successes"].as_u64() == Some(1))
        .count();
    assert_eq!(text.matches("height=\"120\"").count(), successes);
    assert!(dir.path().join("f11.png").metadata().unwrap().len() > 1000);
}

#[test]
fn figure_11_refuses_a_scene_and_other_figures() {
    for args in [
        &["--figure", "11", "--scene", "lau-snake"][..],
        &["--figure", "12"],
    ] {
        let out = Command::new(pushbot_tests::bin("pushbot"))
            .args(["eval", "delivery"])
            .args(args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--figure"), "{args:?}: {err}");
    }
}

/// `pushbot bench eval --json`: the same cells with the truth camera and the rendered one, each
/// with its trials per second and the simulation's real-time factor, consistent with the wall
/// and simulated times it reports.
#[test]
fn bench_eval_times_the_trials_with_each_camera() {
    let strategies = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../results/fig11-rendered/strategies");
    let out = Command::new(pushbot_tests::bin("pushbot"))
        .args([
            "--json",
            "bench",
            "eval",
            "--scene",
            "lau-irregular",
            "--start",
            "A",
            "--method",
            "learned",
            "--time-limit",
            "20",
            "--strategy-dir",
        ])
        .arg(&strategies)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(v["scene"], "lau-irregular");
    for camera in ["truth", "rendered"] {
        let c = &v[camera];
        assert_eq!(c["camera"], camera);
        assert_eq!(c["trials"].as_u64(), Some(1), "{c}");
        let (wall, sim) = (c["wall_s"].as_f64().unwrap(), c["sim_s"].as_f64().unwrap());
        assert!(wall > 0.0 && sim > 0.0 && sim <= 21.0, "{c}");
        let rate = c["trials_per_s"].as_f64().unwrap();
        assert!((rate - 1.0 / wall).abs() < 1e-9 * rate.max(1.0), "{c}");
        let factor = c["realtime_factor"].as_f64().unwrap();
        assert!((factor - sim / wall).abs() < 1e-9 * factor.max(1.0), "{c}");
    }
    // The rendered camera draws and reads a frame at every look: its simulated seconds cost
    // more wall time.
    assert!(
        v["rendered"]["realtime_factor"].as_f64() < v["truth"]["realtime_factor"].as_f64(),
        "{v}"
    );
}
