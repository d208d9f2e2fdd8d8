//! `pushbot run stable` and `pushbot eval stable`, the real binary: bad input — a
//! malformed `[perturb]` section, a scene that is neither a preset nor a file, a scene whose
//! pusher the robot is not — exits 2 with the reason and where; and one perturbed trial in
//! process with `--json`, whose summary carries `trials` and `reached`.

use pushbot_tests::run_bin;

mod bad_input_common;

use bad_input_common::{Files, assert_bad_input, pushbot};

/// Fig. 15's scene text with `extra` appended.
fn fig15_with(extra: &str) -> String {
    let mut t = pushbot_world::presets::text("fig15").expect("the fig15 preset");
    t.push_str(extra);
    t
}

#[test]
fn a_bad_perturb_section_is_refused_with_its_field() {
    let f = Files::new();
    for (extra, needles) in [
        (
            "\n[perturb]\nstart_theta_deg = -5.0\n",
            &["perturb.start_theta_deg", "must be a number in 0..=45"][..],
        ),
        (
            "\n[perturb]\npusher_friction = 1.5\n",
            &["perturb.pusher_friction", "0..=0.9"][..],
        ),
        (
            "\n[perturb]\nwheel_slipp = 0.01\n",
            &["unknown field `wheel_slipp`"][..],
        ),
    ] {
        let p = f.write("perturbed.toml", fig15_with(extra));
        let mut with_file: Vec<&str> = needles.to_vec();
        with_file.push(&p);
        assert_bad_input(
            &pushbot(&[
                "eval",
                "stable",
                "--scene",
                &p,
                "--trials",
                "2",
                "--perturb",
            ]),
            &with_file,
        );
        assert_bad_input(&pushbot(&["scene", "check", "--scene", &p]), &with_file);
    }
    // The same file with a good section checks clean.
    let p = f.write(
        "good.toml",
        fig15_with("\n[perturb]\nstart_theta_deg = 2.0\ncof_offset = 0.0\n"),
    );
    let r = pushbot(&["scene", "check", "--scene", &p]);
    assert_eq!(r.code, Some(0), "{r:?}");
}

#[test]
fn a_bad_scene_is_refused() {
    let r = pushbot(&["run", "stable", "--scene", "fig99"]);
    assert_bad_input(&r, &["fig99"]);
    let f = Files::new();
    let p = f.write(
        "arm.toml",
        pushbot_world::presets::text("fig16").expect("the fig16 preset"),
    );
    assert_bad_input(
        &pushbot(&["eval", "stable", "--scene", &p, "--trials", "1"]),
        &["pusher is \"arm\"", "diff-drive"],
    );
    assert_bad_input(
        &pushbot(&["eval", "stable", "--scene", "fig15", "--trials", "0"]),
        &["--trials"],
    );
}

#[test]
fn one_perturbed_trial_prints_a_json_summary() {
    let r = run_bin(
        "pushbot",
        &[
            "eval",
            "stable",
            "--scene",
            "fig15",
            "--trials",
            "1",
            "--trial",
            "2",
            "--perturb",
            "--json",
        ],
    );
    assert_eq!(r.code, Some(0), "{r:?}");
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    let s = &v["summary"];
    assert_eq!(s["trials"], 1, "{v}");
    assert_eq!(s["reached"], 1, "{v}");
    assert_eq!(s["perturbed"], true, "{v}");
    let t = &v["trials"][0];
    assert_eq!(t["trial"], 2, "{v}");
    assert!(
        t["final_error_m"].as_f64().is_some_and(|e| e < 0.061 * 1.5),
        "{v}"
    );
}
