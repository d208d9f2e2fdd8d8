//! `pushbot bench stable`'s random scenes: the planner (Lynch & Mason 1996 §4) timed on the
//! seeded scenes of [`crate::planner::stable::random_scene`], per pusher, with how often it
//! finds a plan where one exists (a search on a grid halved in x, y and θ with ten times the
//! nodes finds one when the planner does not).

use serde_json::{Value, json};

use super::BenchStableArgs;
use crate::cli::CliError;
use crate::planner::stable::plan;
use crate::planner::stable::random_scene::{RandomPusher, random_scene};

/// The `q`-quantile (nearest rank) of sorted `v`.
fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[k - 1]
}

/// Median, p95 and worst of `times` (ms).
fn summary(times: &mut [f64]) -> Value {
    times.sort_by(f64::total_cmp);
    json!({
        "median_ms": quantile(times, 0.5),
        "p95_ms": quantile(times, 0.95),
        "worst_ms": times.last().copied().unwrap_or(f64::NAN),
    })
}

/// Plan every random scene of the arguments; per pusher and over all: scenes, plans found,
/// plans that exist, and planning times.
pub(super) fn bench_random(a: &BenchStableArgs) -> Result<Value, CliError> {
    if a.random == 0 {
        return Ok(Value::Null);
    }
    let kinds: Vec<RandomPusher> = if a.pushers.is_empty() {
        vec![RandomPusher::DiffDrive, RandomPusher::Car]
    } else {
        a.pushers
            .iter()
            .map(|k| RandomPusher::parse(k))
            .collect::<anyhow::Result<_>>()
            .map_err(CliError::BadInput)?
    };
    let mut all_times = Vec::new();
    let mut per = Vec::new();
    for kind in kinds {
        let (mut found, mut exists) = (0usize, 0usize);
        let mut times = Vec::new();
        let mut missed = Vec::new();
        let mut scenes = Vec::new();
        for seed in a.seed..a.seed + a.random {
            let rs = random_scene(seed, kind).map_err(CliError::Failed)?;
            let p = rs.problem().map_err(CliError::Failed)?;
            let pl = plan(&p);
            times.push(pl.plan_time_ms);
            scenes.push(json!({"seed": seed, "found": pl.found, "cost": pl.cost,
                "nodes_expanded": pl.nodes_expanded, "contact_changes": pl.contact_changes,
                "plan_time_ms": pl.plan_time_ms}));
            if pl.found {
                found += 1;
                exists += 1;
            } else if plan(&rs.refined_problem().map_err(CliError::Failed)?).found {
                exists += 1;
                missed.push(seed);
            }
        }
        all_times.extend_from_slice(&times);
        let mut row = summary(&mut times);
        row["pusher"] = json!(kind.name());
        row["scenes"] = json!(a.random);
        row["found"] = json!(found);
        row["exist"] = json!(exists);
        row["missed_seeds"] = json!(missed);
        row["runs"] = json!(scenes);
        per.push(row);
    }
    let mut all = summary(&mut all_times);
    all["scenes"] = json!(all_times.len());
    Ok(json!({"first_seed": a.seed, "pushers": per, "all": all}))
}

/// Print [`bench_random`]'s result as a table.
pub(super) fn print_random(r: &Value) {
    let Some(rows) = r["pushers"].as_array() else {
        return;
    };
    println!(
        "\nrandom scenes (seeds {}..): planning time over every scene, plans found / plans that exist",
        r["first_seed"]
    );
    println!(
        "{:<11} {:>6} {:>6} {:>6} {:>10} {:>10} {:>10}",
        "pusher", "scenes", "found", "exist", "median ms", "p95 ms", "worst ms"
    );
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    for row in rows.iter().chain(std::iter::once(&r["all"])) {
        println!(
            "{:<11} {:>6} {:>6} {:>6} {:>10.2} {:>10.2} {:>10.2}",
            row["pusher"].as_str().unwrap_or("all"),
            row["scenes"].to_string(),
            row["found"].as_u64().map_or("".into(), |v| v.to_string()),
            row["exist"].as_u64().map_or("".into(), |v| v.to_string()),
            f(&row["median_ms"]),
            f(&row["p95_ms"]),
            f(&row["worst_ms"])
        );
    }
}
