//! What a user meets first in the real `pushbot` binary: `--version` names the build, and each
//! command's `--help` lists the options a user needs before its research and tuning knobs.

use std::process::Command;

fn pushbot(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args(args)
        .output()
        .expect("run pushbot");
    assert!(out.status.success(), "pushbot {args:?}: {out:?}");
    String::from_utf8(out.stdout).expect("UTF-8")
}

#[test]
fn version_names_the_crate_version_and_the_git_revision() {
    let revision = Command::new("git")
        .args(["rev-parse", "--short=10", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .filter(|r| !r.is_empty())
        .unwrap_or_else(|| "unknown".into());
    assert_eq!(
        pushbot(&["--version"]).trim(),
        format!("pushbot {} ({revision})", env!("CARGO_PKG_VERSION"))
    );
}

/// The options `help` lists under each heading, in order (`--help` itself not counted).
fn sections(help: &str) -> Vec<(String, Vec<String>)> {
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for line in help.lines() {
        let heading = line.strip_suffix(':').filter(|h| {
            h.chars().next().is_some_and(|c| c.is_ascii_uppercase()) && !h.starts_with(' ')
        });
        if let Some(h) = heading {
            out.push((h.to_owned(), Vec::new()));
            continue;
        }
        let t = line.trim_start();
        let indent = line.len() - t.len();
        if (2..=6).contains(&indent) && t.starts_with('-') {
            let name = t
                .split([' ', ','])
                .find(|w| w.starts_with("--"))
                .unwrap_or(t)
                .to_owned();
            if name != "--help"
                && let Some((_, opts)) = out.last_mut()
            {
                opts.push(name);
            }
        }
    }
    out
}

/// `pushbot ARGS --help` and `-h`: at most 10 options before the "Advanced options" heading,
/// which holds `advanced`.
fn check(args: &[&str], advanced: &[&str]) {
    for flag in ["--help", "-h"] {
        let mut a = args.to_vec();
        a.push(flag);
        let help = pushbot(&a);
        let s = sections(&help);
        let at = s
            .iter()
            .position(|(h, _)| h == "Advanced options")
            .unwrap_or_else(|| panic!("pushbot {a:?}: no \"Advanced options\" heading:\n{help}"));
        let first: Vec<&String> = s[..at].iter().flat_map(|(_, o)| o).collect();
        assert!(
            !first.is_empty() && first.len() <= 10,
            "pushbot {a:?}: {} options before \"Advanced options\": {first:?}",
            first.len()
        );
        for o in advanced {
            assert!(
                s[at].1.iter().any(|x| x == o),
                "pushbot {a:?}: {o} is not under \"Advanced options\": {s:?}"
            );
        }
    }
}

#[test]
fn collect_shows_what_a_user_needs_first() {
    check(
        &["collect"],
        &[
            "--novel-distance",
            "--surprise-deg",
            "--boundary-inset",
            "--turn-weight",
            "--selection",
            "--kernel-width",
        ],
    );
    // And what a user needs is there, before.
    let s = sections(&pushbot(&["collect", "--help"]));
    for o in ["--object", "--scene", "--out", "--port", "--camera"] {
        assert!(s[0].1.iter().any(|x| x == o), "{o} not first: {s:?}");
    }
}

#[test]
fn other_commands_with_research_knobs_keep_them_apart() {
    check(
        &["eval", "delivery"],
        &["--boundary-guard", "--turn-weight", "--keep"],
    );
    check(&["demo"], &["--sim-speed", "--disturb"]);
    check(&["track"], &["--detector", "--whole-frames"]);
}

#[test]
fn the_count_sees_every_option() {
    // The check's own reading of a help page: a page with eleven options before its advanced
    // heading is over the limit.
    let mut page = String::from("Usage: x\n\nOptions:\n");
    for i in 0..11 {
        page.push_str(&format!("      --opt{i} <V>  what it does\n"));
    }
    page.push_str("  -h, --help  Print help\n\nAdvanced options:\n      --knob  a knob\n");
    let s = sections(&page);
    assert_eq!(s[0].1.len(), 11);
    assert_eq!(
        s[1],
        ("Advanced options".to_owned(), vec!["--knob".to_owned()])
    );
}
