//! A delivery sweep spread over shards, as a scheduler runs it: `pushbot eval delivery
//! --shard K/N --resume FILE` in three processes at once, then `pushbot eval merge` of their
//! files, which must equal the same sweep run whole, cell for cell and figure for figure; and
//! the merge refuses what is not one whole sweep.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use serde_json::Value;

fn strategies() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../results/fig11-rendered/strategies")
}

/// `pushbot eval delivery --figure 11` on two starts, one trial a cell, and `extra`.
fn sweep(extra: &[&str]) -> Command {
    let mut c = Command::new(pushbot_tests::bin("pushbot"));
    c.args([
        "--json",
        "eval",
        "delivery",
        "--figure",
        "11",
        "--trials",
        "1",
        "--start",
        "A,B",
        "--time-limit",
        "8",
        "--sim-camera",
        "truth",
        "--strategy-dir",
    ])
    .arg(strategies())
    .args(extra);
    c
}

fn json(out: &Output) -> Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)))
}

fn merge(files: &[&Path], svg: &Path) -> Output {
    Command::new(pushbot_tests::bin("pushbot"))
        .args(["--json", "eval", "merge"])
        .args(files)
        .arg("--svg")
        .arg(svg)
        .output()
        .unwrap()
}

#[test]
fn three_shards_merged_equal_the_sweep_run_whole() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    // The three shards at once, as three jobs of an array.
    let shards: Vec<_> = (1..=3)
        .map(|k| {
            sweep(&["--shard", &format!("{k}/3"), "--resume"])
                .arg(p(&format!("cells-{k}.jsonl")))
                .spawn()
                .unwrap()
        })
        .collect();
    let whole = sweep(&["--svg"]).arg(p("whole.svg")).output().unwrap();
    let whole_json = json(&whole);
    let mut dealt = 0;
    for (k, s) in shards.into_iter().enumerate() {
        let out = s.wait_with_output().unwrap();
        assert!(out.status.code().is_some(), "shard {} crashed", k + 1);
        // Each shard ran its share only: the other cells are not in its file.
        let text = std::fs::read_to_string(p(&format!("cells-{}.jsonl", k + 1))).unwrap();
        let cells = text.lines().count() - 1;
        assert!((7..=9).contains(&cells), "shard {}: {cells} cells", k + 1);
        dealt += cells;
    }
    assert_eq!(
        dealt, 24,
        "six objects × two starts × two methods, each once"
    );
    let files: Vec<PathBuf> = (1..=3).map(|k| p(&format!("cells-{k}.jsonl"))).collect();
    let mut shuffled: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    shuffled.reverse();
    let merged = merge(&shuffled, &p("merged.svg"));
    assert_eq!(
        merged.status.code(),
        whole.status.code(),
        "the same exit status"
    );
    let merged_json = json(&merged);
    let (a, b) = (&whole_json["scenes"], &merged_json["scenes"]);
    assert_eq!(a.as_array().unwrap().len(), 6);
    for (sa, sb) in a.as_array().unwrap().iter().zip(b.as_array().unwrap()) {
        assert_eq!(sa["results"].as_array().unwrap().len(), 4, "{sa}");
        assert_eq!(sa, sb, "the merged cells equal the whole run's");
    }
    assert_eq!(a, b);
    assert_eq!(whole_json["trials"], merged_json["trials"]);
    assert_eq!(whole_json["camera"], merged_json["camera"]);
    assert_eq!(
        std::fs::read_to_string(p("whole.svg")).unwrap(),
        std::fs::read_to_string(p("merged.svg")).unwrap(),
        "the same figure"
    );

    // Not one whole sweep: a shard missing, a shard given twice, a shard of another sweep.
    let err = |out: Output| {
        assert_eq!(out.status.code(), Some(2));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let e = err(merge(&[&files[0], &files[2]], &p("x.svg")));
    assert!(e.contains("shard 2/3 of the sweep not given"), "{e}");
    let e = err(merge(&[&files[0], &files[1], &files[1]], &p("x.svg")));
    assert!(e.contains("both shard 2/3"), "{e}");
    let text = std::fs::read_to_string(&files[1]).unwrap();
    let (header, cells) = text.split_once('\n').unwrap();
    let mut h: Value = serde_json::from_str(header).unwrap();
    h["seed"] = Value::from(7);
    std::fs::write(p("other.jsonl"), format!("{h}\n{cells}")).unwrap();
    let e = err(merge(
        &[&files[0], &p("other.jsonl"), &files[2]],
        &p("x.svg"),
    ));
    assert!(e.contains("another sweep") && e.contains("seed 7"), "{e}");
    assert!(!p("x.svg").exists(), "nothing drawn from a refused merge");
    // A shard's file cut short: its cells are missing, and named.
    let first_two: String = text.split_inclusive('\n').take(2).collect();
    std::fs::write(p("short.jsonl"), first_two).unwrap();
    let e = err(merge(
        &[&files[0], &p("short.jsonl"), &files[2]],
        &p("x.svg"),
    ));
    assert!(
        e.contains("cells are in no file") && e.contains("(shard 2/3)"),
        "{e}"
    );
    // A shard run again with another shard's file is refused, and the file kept.
    let before = std::fs::read(&files[0]).unwrap();
    let again = sweep(&["--shard", "2/3", "--resume"])
        .arg(&files[0])
        .output()
        .unwrap();
    let e = err(again);
    assert!(e.contains("shard 1/3 in the file, 2/3 now"), "{e}");
    assert_eq!(std::fs::read(&files[0]).unwrap(), before);
}

/// `pushbot eval stable` spread over three shards at once: the merge equals the evaluation run
/// whole, trial for trial, for one scene in perturbed worlds and for random scenes; a shard
/// run again with its file runs nothing again.
#[test]
fn stable_trials_in_three_shards_merge_into_the_whole_evaluation() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    for (what, args, rows) in [
        (
            "fig15",
            &["--scene", "fig15", "--perturb", "--trials", "7"][..],
            "trials",
        ),
        (
            "random",
            &["--random", "8", "--pusher", "car"][..],
            "scenes",
        ),
    ] {
        let stable = |extra: &[&str]| {
            let mut c = Command::new(pushbot_tests::bin("pushbot"));
            c.args(["--json", "eval", "stable"]).args(args).args(extra);
            c
        };
        let files: Vec<PathBuf> = (1..=3).map(|k| p(&format!("{what}-{k}.jsonl"))).collect();
        let shards: Vec<_> = (1..=3)
            .map(|k| {
                stable(&["--shard", &format!("{k}/3"), "--resume"])
                    .arg(&files[k - 1])
                    .stdout(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        let whole = json(&stable(&[]).output().unwrap());
        let mut counts = Vec::new();
        for s in shards {
            let out = s.wait_with_output().unwrap();
            let v = json(&out);
            assert!(v["summary"]["shard"].is_string(), "{v}");
            counts.push(v[rows].as_array().unwrap().len());
        }
        assert_eq!(
            counts.iter().sum::<usize>(),
            whole[rows].as_array().unwrap().len()
        );
        assert!(counts.iter().all(|&c| c >= 2), "{what}: {counts:?}");
        let out = Command::new(pushbot_tests::bin("pushbot"))
            .args(["--json", "eval", "merge"])
            .args(files.iter().rev())
            .output()
            .unwrap();
        let merged = json(&out);
        assert_eq!(
            merged[rows], whole[rows],
            "{what}: the merge equals the whole run"
        );
        for k in ["reached", "trials", "seed", "perturbed", "closed_loop"] {
            assert_eq!(merged["summary"][k], whole["summary"][k], "{what}: {k}");
        }
        // Run again with its file, a shard finds every trial done and prints the same.
        let before = std::fs::read(&files[1]).unwrap();
        let again = stable(&["--shard", "2/3", "--resume"])
            .arg(&files[1])
            .output()
            .unwrap();
        assert!(
            String::from_utf8_lossy(&again.stderr).contains("not run again"),
            "{}",
            String::from_utf8_lossy(&again.stderr)
        );
        assert_eq!(
            std::fs::read(&files[1]).unwrap(),
            before,
            "nothing appended"
        );
        // A shard's file given twice does not merge.
        let e = Command::new(pushbot_tests::bin("pushbot"))
            .args(["eval", "merge"])
            .arg(&files[0])
            .arg(&files[0])
            .output()
            .unwrap();
        assert_eq!(e.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&e.stderr).contains("both shard 1/3"));
    }
}
