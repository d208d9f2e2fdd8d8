//! The test cases of Ben-Shahar & Rivlin §V-A (A1–A4, B1–B2, C1–C2, D1) and how the grid
//! planner reads a scene: every scene is one of the shared format (`pushbot_world::Scene`) with a
//! `[rearrange]` section, rasterised by [`super::scene::problem_from_scene`]. The cases are the
//! simulator's presets `bsr-a1` … `bsr-d1` (`sim-target/src/presets/bsr-*.toml`); their paper
//! names `A1` … `D1` are accepted as aliases.

use pushbot_world::Scene;

use super::problem::Problem;

/// Why a scene could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

/// The cases: (paper name, preset, what the paper shows).
pub const CASES: &[(&str, &str, &str)] = &[
    ("A1", "bsr-a1", "Fig. 9: one box at a time, mass metric"),
    ("A2", "bsr-a2", "Fig. 10: up to two boxes at once"),
    (
        "A3",
        "bsr-a3",
        "Fig. 11: two at once, a rough region changes the route",
    ),
    (
        "A4",
        "bsr-a4",
        "Fig. 12: one at a time, distance limit 7: the robot fetches the second box",
    ),
    (
        "B1",
        "bsr-b1",
        "Fig. 13: exchanging two boxes needs an intermediate placement",
    ),
    (
        "B2",
        "bsr-b2",
        "Fig. 14: a rough region changes the exchange",
    ),
    (
        "C1",
        "bsr-c1",
        "Fig. 16: a complex movable pushed by a small robot",
    ),
    (
        "C2",
        "bsr-c2",
        "Fig. 17: the same with a large robot, some pushes no longer fit",
    ),
    ("D1", "bsr-d1", "Fig. 19: rotational pushes in clutter"),
];

/// The preset a name stands for: a case's paper name (case-insensitive) or a preset's name.
pub fn preset_name(name: &str) -> Option<&'static str> {
    CASES
        .iter()
        .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
        .map(|c| c.1)
        .or_else(|| {
            pushbot_world::scene::PRESETS
                .iter()
                .find(|p| **p == name)
                .copied()
        })
}

/// The grid problem of a scene's TOML text (the shared format with a `[rearrange]` section);
/// `file` names the source in errors, which give its line and field.
pub fn problem_from_toml(text: &str, file: &str) -> Result<Problem, SceneError> {
    // Parsed once (a fine outline makes a scene file large); the old format is told apart
    // only when the scene does not parse.
    let scene = Scene::from_toml(text, file).map_err(|e| {
        if toml::from_str::<toml::Table>(text)
            .is_ok_and(|t| !t.get("table").is_some_and(|v| v.is_table()))
        {
            SceneError(format!(
                "{file}: not a scene: it has no [table] section (the shared scene format needs \
                 [table], and [rearrange] for the grid planner; the old grid format with `map`, \
                 [robot] at and [[movable]] is no longer read: see docs/src/scenes.md)"
            ))
        } else {
            SceneError(e.to_string())
        }
    })?;
    super::scene::problem_from_scene(&scene, Some(text), file)
        .map_err(|e| SceneError(e.to_string()))
}

/// Load a scene by name (a case `A1` … `D1`, or any simulator preset with a `[rearrange]`
/// section) or from a file in the shared scene format.
pub fn load_scene(name_or_path: &str) -> Result<Problem, SceneError> {
    if let Some(preset) = preset_name(name_or_path) {
        let scene = Scene::preset(preset).map_err(|e| SceneError(e.to_string()))?;
        return super::scene::problem_from_scene(&scene, None, &format!("preset {preset}"))
            .map_err(|e| SceneError(e.to_string()));
    }
    let text = std::fs::read_to_string(name_or_path).map_err(|e| {
        SceneError(format!(
            "scene `{name_or_path}`: not a preset (the cases {}, or a scene preset) and not a \
             readable file: {e}",
            CASES.iter().map(|c| c.0).collect::<Vec<_>>().join(", ")
        ))
    })?;
    problem_from_toml(&text, name_or_path)
}
