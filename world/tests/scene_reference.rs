//! The guide's scene reference (`docs/src/scenes.md`) against the parser, both ways:
//!
//! - its example (every `toml` block of the page, together) parses as a [`Scene`], and the keys
//!   of the example are exactly the keys of the reference tables, so every documented key is one
//!   the parser takes;
//! - every key the parser accepts, in every table the example has, is documented: an unknown key
//!   put into each of those tables is refused (every scene table denies unknown keys), and the
//!   refusal lists the keys the parser knows there.

use std::collections::BTreeSet;
use std::path::PathBuf;

use pushbot_world::Scene;
use toml::{Table, Value};

const PROBE: &str = "undocumented_probe_key";

/// Tables whose keys the parser does not list when it refuses one: a value that is either a
/// path or a table (an untagged choice) is refused as a whole. Their keys are still checked by
/// the example's parse.
const UNLISTED: &[&str] = &["camera.intrinsics"];

fn page() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/src/scenes.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every ```toml block of the page, joined.
fn example(page: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for line in page.lines() {
        match (inside, line.trim()) {
            (false, "```toml") => inside = true,
            (true, "```") => inside = false,
            (true, _) => {
                out.push_str(line);
                out.push('\n');
            }
            _ => {}
        }
    }
    out
}

/// The first cell of every row of the reference tables: `| `key` | … |`.
fn documented(page: &str) -> BTreeSet<String> {
    let reference = page
        .split("\n## Reference")
        .nth(1)
        .expect("the page has a `## Reference` section");
    let reference = reference.split("\n## ").next().unwrap_or(reference);
    reference
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .map(str::to_owned)
        .collect()
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_owned()
    } else {
        format!("{prefix}.{key}")
    }
}

fn tables_of(v: &Value) -> Option<Vec<&Table>> {
    match v {
        Value::Table(t) => Some(vec![t]),
        Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table) => {
            Some(a.iter().filter_map(Value::as_table).collect())
        }
        _ => None,
    }
}

/// Every key path of `table` (`objects[].marker.z`), and the paths that are tables.
fn keys(prefix: &str, table: &Table, all: &mut BTreeSet<String>, tables: &mut Vec<String>) {
    for (k, v) in table {
        let path = join(prefix, k);
        all.insert(path.clone());
        if let Some(ts) = tables_of(v) {
            let inner = if v.is_array() {
                format!("{path}[]")
            } else {
                path.clone()
            };
            tables.push(inner.clone());
            for t in ts {
                keys(&inner, t, all, tables);
            }
        }
    }
}

/// The table at `path` (`objects[].marker`: the first object's marker).
fn table_at<'a>(root: &'a mut Table, path: &str) -> &'a mut Table {
    if path.is_empty() {
        return root;
    }
    let mut t = root;
    for seg in path.split('.') {
        let (name, array) = match seg.strip_suffix("[]") {
            Some(n) => (n, true),
            None => (seg, false),
        };
        let v = t
            .get_mut(name)
            .unwrap_or_else(|| panic!("no {name} in {path}"));
        let v = if array {
            v.as_array_mut()
                .and_then(|a| a.first_mut())
                .expect("an array of tables")
        } else {
            v
        };
        t = v
            .as_table_mut()
            .unwrap_or_else(|| panic!("{path} is not a table"));
    }
    t
}

fn parse(table: Table) -> Result<Scene, String> {
    Value::Table(table)
        .try_into::<Scene>()
        .map_err(|e| e.to_string())
}

/// The backticked names after "expected" in an unknown-key refusal.
fn expected_keys(message: &str) -> Option<Vec<String>> {
    let rest = message.split(&format!("unknown field `{PROBE}`")).nth(1)?;
    let rest = rest.split("expected").nth(1)?;
    // The list ends with its line; what follows names where the key was (`in \`camera\``).
    let rest = rest.lines().next().unwrap_or_default();
    Some(
        rest.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_owned)
            .collect(),
    )
}

#[test]
fn the_example_parses_and_has_exactly_the_documented_keys() {
    let page = page();
    let text = example(&page);
    let table: Table = toml::from_str(&text).expect("the page's example is TOML");
    parse(table.clone()).expect("the page's example parses as a scene");
    let (mut all, mut tables) = (BTreeSet::new(), Vec::new());
    keys("", &table, &mut all, &mut tables);
    let doc = documented(&page);
    let undocumented: Vec<_> = all.difference(&doc).collect();
    let not_in_example: Vec<_> = doc.difference(&all).collect();
    assert!(
        undocumented.is_empty(),
        "keys of the example missing from the reference tables: {undocumented:?}"
    );
    assert!(
        not_in_example.is_empty(),
        "documented keys missing from the example (so not checked against the parser): \
         {not_in_example:?}"
    );
}

#[test]
fn every_key_the_parser_accepts_is_documented() {
    let page = page();
    let table: Table = toml::from_str(&example(&page)).expect("the page's example is TOML");
    let (mut all, mut tables) = (BTreeSet::new(), vec![String::new()]);
    keys("", &table, &mut all, &mut tables);
    let doc = documented(&page);
    let mut missing = Vec::new();
    let mut unlisted = Vec::new();
    for path in &tables {
        let mut probed = table.clone();
        table_at(&mut probed, path).insert(PROBE.into(), Value::Integer(0));
        let message = match parse(probed) {
            Ok(_) => panic!("an unknown key in `{path}` was accepted"),
            Err(m) => m,
        };
        match expected_keys(&message) {
            Some(names) => {
                assert!(!names.is_empty(), "`{path}`: no keys listed in {message:?}");
                let base = path.trim_end_matches("[]");
                let prefix = if path.ends_with("[]") {
                    format!("{base}[]")
                } else {
                    base.to_owned()
                };
                for n in names {
                    let key = join(&prefix, &n);
                    if !doc.contains(&key) {
                        missing.push(key);
                    }
                }
            }
            None => unlisted.push((path.clone(), message)),
        }
    }
    assert!(
        missing.is_empty(),
        "keys the parser accepts that the reference does not document: {missing:?}"
    );
    let unexpected: Vec<_> = unlisted
        .iter()
        .filter(|(p, _)| !UNLISTED.contains(&p.as_str()))
        .collect();
    assert!(
        unexpected.is_empty(),
        "tables whose unknown key was refused without the list of known keys: {unexpected:?}"
    );
    // The root, every section and every nested table of the example were probed.
    assert!(tables.len() > 20, "only {} tables probed", tables.len());
}
