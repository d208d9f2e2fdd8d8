//! The guide's command-line reference, `docs/src/cli.md`, is generated from the clap definitions
//! of `pushbot` ([`pushbot::cli::command`]) and must equal the committed page, so it cannot drift
//! from the program. After changing a command, an option or a help text, write it anew with
//!
//! ```sh
//! UPDATE_CLI_DOC=1 cargo test -p pushbot --test cli_reference
//! ```

use std::path::PathBuf;

/// The page as the code defines it.
fn generated() -> String {
    let options = clap_markdown::MarkdownOptions::new()
        .title("Command-line reference".to_owned())
        .show_footer(false)
        .show_table_of_contents(true);
    let body = clap_markdown::help_markdown_command_custom(&pushbot::cli::command(), &options);
    let body = escape_html(&body);
    // The page's own first lines say where it comes from; clap-markdown's title follows them.
    format!(
        "<!-- Generated from the clap definitions of `pushbot` by host/tests/cli_reference.rs; do not \
         edit. Regenerate: UPDATE_CLI_DOC=1 cargo test -p pushbot --test cli_reference -->\n\n{}",
        body.trim_end()
    ) + "\n"
}

/// Help texts are plain text: a `<` outside code (`PUSHBOT_LOG=<filter>`) is written as `&lt;`,
/// so that Markdown does not read it as an HTML tag.
fn escape_html(markdown: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        }
        if fenced || line.trim_start().starts_with("```") {
            out.push_str(line);
        } else {
            for (i, part) in line.split('`').enumerate() {
                if i > 0 {
                    out.push('`');
                }
                if i % 2 == 0 {
                    out.push_str(&part.replace('<', "&lt;"));
                } else {
                    out.push_str(part);
                }
            }
        }
        out.push('\n');
    }
    out
}

fn page() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/src/cli.md")
}

#[test]
fn the_committed_cli_reference_is_the_generated_one() {
    let want = generated();
    if std::env::var_os("UPDATE_CLI_DOC").is_some() {
        std::fs::write(page(), &want).expect("write docs/src/cli.md");
        eprintln!("wrote {}", page().display());
        return;
    }
    let have = std::fs::read_to_string(page()).unwrap_or_default();
    if have != want {
        let line = have
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| have.lines().count().min(want.lines().count()));
        panic!(
            "docs/src/cli.md differs from the command line the code defines (first at line {}: \
             committed {:?}, generated {:?}).\nRegenerate it: UPDATE_CLI_DOC=1 cargo test -p \
             pushbot --test cli_reference",
            line + 1,
            have.lines().nth(line).unwrap_or("<end of file>"),
            want.lines().nth(line).unwrap_or("<end of file>"),
        );
    }
}

#[test]
fn the_reference_names_every_command() {
    // Every subcommand, at every depth, has its own section in the page.
    fn walk(cmd: &clap::Command, path: &str, out: &mut Vec<String>) {
        for sub in cmd.get_subcommands() {
            let p = format!("{path} {}", sub.get_name());
            out.push(p.clone());
            walk(sub, &p, out);
        }
    }
    let mut paths = Vec::new();
    walk(&pushbot::cli::command(), "pushbot", &mut paths);
    assert!(paths.len() > 20, "only {} commands found", paths.len());
    let text = generated();
    for p in paths {
        assert!(
            text.contains(&format!("## `{p}`")),
            "the reference has no section for `{p}`"
        );
    }
}

/// `line` with every `${NAME}` replaced by `1`.
fn expand_variables(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    while let Some(at) = rest.find("${") {
        out.push_str(&rest[..at]);
        match rest[at..].find('}') {
            Some(end) => {
                out.push('1');
                rest = &rest[at + end + 1..];
            }
            None => {
                out.push_str(&rest[at..]);
                rest = "";
            }
        }
    }
    out.push_str(rest);
    out
}

/// The `pushbot` command lines of every shell block in README.md and the guide.
fn documented_command_lines() -> Vec<(String, String)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = vec![root.join("README.md")];
    let mut dirs = vec![root.join("docs/src")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).expect("docs/src") {
            let p = e.expect("a directory entry").path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "md") {
                files.push(p);
            }
        }
    }
    let mut out = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).expect("a Markdown file");
        let name = f.strip_prefix(&root).unwrap_or(&f).display().to_string();
        let mut shell = false;
        let mut pending = String::new();
        for line in text.lines() {
            let t = line.trim();
            if let Some(lang) = t.strip_prefix("```") {
                shell = !shell && matches!(lang, "sh" | "bash");
                continue;
            }
            if !shell {
                continue;
            }
            // One command: continuation lines joined, the comment cut, the part after `&&`.
            pending.push_str(t.trim_end_matches('\\'));
            pending.push(' ');
            if t.ends_with('\\') {
                continue;
            }
            let command = std::mem::take(&mut pending);
            let command = command.split(" #").next().unwrap_or_default();
            for part in command.split("&&") {
                let part = part.trim();
                let args = part
                    .strip_prefix("cargo run --release -p pushbot -- ")
                    .or_else(|| part.strip_prefix("cargo run -p pushbot -- "))
                    .map(|rest| format!("pushbot {rest}"))
                    .or_else(|| part.starts_with("pushbot ").then(|| part.to_owned()));
                if let Some(args) = args {
                    out.push((name.clone(), args));
                }
            }
        }
    }
    out
}

#[test]
fn every_command_line_in_the_docs_parses() {
    let lines = documented_command_lines();
    assert!(lines.len() > 30, "only {} command lines found", lines.len());
    let mut bad = Vec::new();
    for (file, line) in &lines {
        // A shell variable (a job array's index) stands for a value that parses: 1.
        let line = &expand_variables(line);
        let args = line.split_whitespace().map(|w| w.trim_matches('"'));
        if let Err(e) = pushbot::cli::command().try_get_matches_from(args) {
            let first = e.render().to_string();
            let first = first.lines().next().unwrap_or_default().to_owned();
            bad.push(format!("{file}: `{line}`: {first}"));
        }
    }
    assert!(
        bad.is_empty(),
        "command lines in the docs that pushbot refuses:\n{}",
        bad.join("\n")
    );
}
