//! Built-in scenes, as TOML text in the scene format (so every preset also exercises the
//! parser): the papers' set-ups with our own plausible geometry where the papers give none.
//!
//! * `empty` — the first cut's 1.2 m × 0.9 m table, nothing on it.
//! * `lau-irregular`, `lau-irregular-corner`, `lau-l-shape`, `lau-wire-cutter`, `lau-scissors`,
//!   `lau-snake` — the six objects of Lau, Mitani & Igarashi (Fig. 6: robot and objects of
//!   5–15 cm; the irregular shape once with its marker near the middle, once near a corner) in
//!   their test layout (Fig. 10): a bounded table, start positions `A`–`F` (the object starts
//!   at `A`), one goal. `lau-obstacles`: the irregular object's layout with a wall between
//!   start and goal (delivery among obstacles, §III-E); `lau-door`, `lau-zigzag` (and `-l`, the
//!   L-shape, as `lau-obstacles-l`): a wall with a 0.3 m door, two staggered walls.
//! * `bsr-a` … `bsr-d` — Ben-Shahar & Rivlin's test cases A–D: boxes in rooms joined by doors
//!   (A: two boxes to move to the other room; B: two boxes to exchange in a corridor; C: a
//!   complex (U-shaped) movable through a door; D: an L-shaped movable in a cluttered room),
//!   on a grid of 0.1 m units.
//! * `bsr-a1` … `bsr-a4`, `bsr-b1`, `bsr-b2`, `bsr-c1`, `bsr-c2`, `bsr-d1` — the exact grids of
//!   Ben-Shahar & Rivlin's test cases (§V-A, Figs. 9–19) in cells of 0.1 m, with a
//!   `[rearrange]` section carrying what the grid planner needs beyond the polygons (robot
//!   size, rough cells, rules, metric, contact modes); the host accepts them as `A1` … `D1`
//!   too (files in `presets/`).
//! * `lynch-mason-fig12` — a rectangular slider pushed among obstacles to a goal pose.
//! * `three-boxes` — three 8 cm boxes in a row ahead of the robot (benchmarks, chain pushes).
//! * `fig13`, `fig15`, `fig16`, `fig17`, `fig18` — Lynch & Mason's stable-pushing problems
//!   (§4.4), with a `[stable]` section for the host's planner (files in `presets/`).

/// Names of the presets.
pub const NAMES: &[&str] = &[
    "empty",
    "lau-irregular",
    "lau-irregular-corner",
    "lau-l-shape",
    "lau-wire-cutter",
    "lau-scissors",
    "lau-snake",
    "lau-obstacles",
    "lau-obstacles-l",
    "lau-door",
    "lau-door-l",
    "lau-zigzag",
    "lau-zigzag-l",
    "bsr-a",
    "bsr-b",
    "bsr-c",
    "bsr-d",
    "bsr-a1",
    "bsr-a2",
    "bsr-a3",
    "bsr-a4",
    "bsr-b1",
    "bsr-b2",
    "bsr-c1",
    "bsr-c2",
    "bsr-d1",
    "lynch-mason-fig12",
    "three-boxes",
    "fig13",
    "fig15",
    "fig16",
    "fig17",
    "fig18",
];

/// The TOML text of a preset.
pub fn text(name: &str) -> Option<String> {
    Some(match name {
        "empty" => EMPTY.to_owned(),
        "lau-irregular" => lau(name, IRREGULAR, [0.0, 0.0], 0.15, SUPPORT_UNIFORM),
        "lau-irregular-corner" => lau(name, IRREGULAR, [0.04, 0.03], 0.15, SUPPORT_UNIFORM),
        "lau-l-shape" => lau(name, L_SHAPE, [-0.04, -0.035], 0.2, SUPPORT_UNIFORM),
        "lau-wire-cutter" => lau(
            name,
            WIRE_CUTTER,
            [0.03, 0.0],
            0.12,
            // Most of the weight is in the steel jaws.
            "{ kind = \"points\", points = [[0.05, 0.0], [0.01, 0.0], [-0.06, 0.02], [-0.06, -0.02]], weights = [3.0, 2.0, 1.0, 1.0] }",
        ),
        "lau-scissors" => lau(
            name,
            SCISSORS,
            [-0.035, 0.0],
            0.08,
            "{ kind = \"points\", points = [[0.06, 0.0], [-0.045, 0.025], [-0.045, -0.025]] }",
        ),
        "lau-snake" => lau(name, SNAKE, [0.0, 0.0], 0.1, SUPPORT_UNIFORM),
        // The irregular object at A behind a wall from the top edge down to y = 0.55 m, leaving a
        // gap of 0.35 m above the boundary of a live run (inset 0.2 m) to push the object through.
        // Position D of the layout (0.85, 0.95) is inside that wall: here it moves to the
        // wall's start side, 0.2 m right of A.
        "lau-obstacles" => {
            lau(name, IRREGULAR, [0.0, 0.0], 0.15, SUPPORT_UNIFORM).replace(
                "pose = { x = 0.85, y = 0.95, theta = -1.5708 }",
                "pose = { x = 0.65, y = 0.95, theta = -1.5708 }",
            ) + &obstacle(7.8, 5.5, 8.8, 12.0)
        }
        // The same wall with the L-shape.
        "lau-obstacles-l" => {
            lau(name, L_SHAPE, [-0.04, -0.035], 0.2, SUPPORT_UNIFORM).replace(
                "pose = { x = 0.85, y = 0.95, theta = -1.5708 }",
                "pose = { x = 0.65, y = 0.95, theta = -1.5708 }",
            ) + &obstacle(7.8, 5.5, 8.8, 12.0)
        }
        // Wall layouts the strategy never saw, for delivery among obstacles (§III-E): a wall
        // across the table with a 0.3 m door (y 0.45–0.75 m) before the goal, and a zigzag of
        // two staggered walls (one from the bottom edge up to y = 0.8 m, one from the top edge
        // down to y = 0.4 m); each with the irregular object and the L-shape.
        "lau-door" => lau(name, IRREGULAR, [0.0, 0.0], 0.15, SUPPORT_UNIFORM) + &door(),
        "lau-door-l" => lau(name, L_SHAPE, [-0.04, -0.035], 0.2, SUPPORT_UNIFORM) + &door(),
        "lau-zigzag" => lau(name, IRREGULAR, [0.0, 0.0], 0.15, SUPPORT_UNIFORM) + &zigzag(),
        "lau-zigzag-l" => lau(name, L_SHAPE, [-0.04, -0.035], 0.2, SUPPORT_UNIFORM) + &zigzag(),
        "bsr-a" => bsr_a(),
        "bsr-b" => bsr_b(),
        "bsr-c" => bsr_c(),
        "bsr-d" => bsr_d(),
        "bsr-a1" => include_str!("presets/bsr-a1.toml").to_owned(),
        "bsr-a2" => include_str!("presets/bsr-a2.toml").to_owned(),
        "bsr-a3" => include_str!("presets/bsr-a3.toml").to_owned(),
        "bsr-a4" => include_str!("presets/bsr-a4.toml").to_owned(),
        "bsr-b1" => include_str!("presets/bsr-b1.toml").to_owned(),
        "bsr-b2" => include_str!("presets/bsr-b2.toml").to_owned(),
        "bsr-c1" => include_str!("presets/bsr-c1.toml").to_owned(),
        "bsr-c2" => include_str!("presets/bsr-c2.toml").to_owned(),
        "bsr-d1" => include_str!("presets/bsr-d1.toml").to_owned(),
        "lynch-mason-fig12" => LYNCH_MASON.to_owned(),
        "three-boxes" => three_boxes(),
        "fig13" => include_str!("presets/fig13.toml").to_owned(),
        "fig15" => include_str!("presets/fig15.toml").to_owned(),
        "fig16" => include_str!("presets/fig16.toml").to_owned(),
        "fig17" => include_str!("presets/fig17.toml").to_owned(),
        "fig18" => include_str!("presets/fig18.toml").to_owned(),
        _ => return None,
    })
}

const EMPTY: &str = r#"
name = "empty"
[table]
width = 1.2
height = 0.9
[robot]
start = { x = 0.6, y = 0.45, theta = 0.0 }
"#;

const SUPPORT_UNIFORM: &str = "{ kind = \"uniform\" }";

/// An irregular blob, about 15 cm × 12 cm.
const IRREGULAR: &str = "[[-0.06, -0.04], [0.02, -0.055], [0.07, -0.01], [0.055, 0.045], [-0.01, 0.06], [-0.045, 0.035], [-0.075, 0.0]]";
/// An L of 12 cm × 14 cm with 4 cm arms.
const L_SHAPE: &str =
    "[[-0.06, -0.06], [0.06, -0.06], [0.06, -0.02], [-0.02, -0.02], [-0.02, 0.08], [-0.06, 0.08]]";
/// Wire cutters, 15.5 cm long: jaws to +x, two handles to −x with a notch between them.
const WIRE_CUTTER: &str = "[[0.075, 0.0], [0.04, 0.012], [0.0, 0.015], [-0.075, 0.03], [-0.08, 0.018], [-0.01, 0.0], [-0.08, -0.018], [-0.075, -0.03], [0.0, -0.015], [0.04, -0.012]]";
/// Scissors, 15.5 cm long: blades to +x, two finger loops to −x.
const SCISSORS: &str = "[[0.09, 0.0], [0.0, 0.012], [-0.02, 0.035], [-0.06, 0.04], [-0.065, 0.01], [-0.03, 0.0], [-0.065, -0.01], [-0.06, -0.04], [-0.02, -0.035], [0.0, -0.012]]";
/// A snake: an S-shaped band 14 cm long and 2.4 cm wide.
const SNAKE: &str = "[[-0.07, 0.012], [-0.035, 0.032], [0.0, 0.012], [0.035, -0.008], [0.07, 0.012], [0.07, -0.012], [0.035, -0.032], [0.0, -0.012], [-0.035, 0.008], [-0.07, -0.012]]";

/// Lau et al.'s layout (Fig. 10) with one object at `A`.
fn lau(name: &str, outline: &str, marker_at: [f64; 2], mass: f64, support: &str) -> String {
    let [mx, my] = marker_at;
    format!(
        r#"
name = "{name}"
# Lau, Mitani & Igarashi, Fig. 10: a bounded table, start positions A–F, one goal.
[table]
width = 1.6
height = 1.2

[robot]
start = {{ x = 0.15, y = 0.6, theta = 0.0 }}

[[objects]]
id = "object"
outline = {outline}
pose = {{ x = 0.45, y = 0.95, theta = 0.0 }}
mass = {mass}
support = {support}
support_friction = 0.3
pusher_friction = 0.4
marker = {{ id = 1, x = {mx}, y = {my}, size = 0.05 }}

[[goals]]
object = "object"
pose = {{ x = 1.25, y = 0.6, theta = 0.0 }}
tolerance = 0.022
marker = {{ id = 20, x = 0.0, y = 0.0, size = 0.05 }}

[[positions]]
name = "A"
pose = {{ x = 0.45, y = 0.95, theta = 0.0 }}
[[positions]]
name = "B"
pose = {{ x = 0.45, y = 0.6, theta = 1.5708 }}
[[positions]]
name = "C"
pose = {{ x = 0.45, y = 0.25, theta = 3.1416 }}
[[positions]]
name = "D"
pose = {{ x = 0.85, y = 0.95, theta = -1.5708 }}
[[positions]]
name = "E"
pose = {{ x = 0.85, y = 0.25, theta = 0.7854 }}
[[positions]]
name = "F"
pose = {{ x = 1.3, y = 0.95, theta = 2.3562 }}

# The robot's marker sits 3 cm behind its middle, out of the way of what it pushes: in the
# middle it covers a thin object's marker whenever the robot stands against it.
[camera]
robot_marker = {{ id = 0, x = -0.03, y = 0.0, size = 0.05 }}
"#
    )
}

/// An axis-aligned rectangle as a TOML outline, from grid units of 0.1 m.
fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> String {
    let u = 0.1;
    let (a, b, c, d) = (x0 * u, y0 * u, x1 * u, y1 * u);
    format!("[[{a:.3}, {b:.3}], [{c:.3}, {b:.3}], [{c:.3}, {d:.3}], [{a:.3}, {d:.3}]]")
}

fn obstacle(x0: f64, y0: f64, x1: f64, y1: f64) -> String {
    format!("\n[[obstacles]]\noutline = {}\n", rect(x0, y0, x1, y1))
}

/// A wall across the table at x 1.0–1.1 m with a 0.3 m door at y 0.45–0.75 m.
fn door() -> String {
    obstacle(10.0, 0.0, 11.0, 4.5) + &obstacle(10.0, 7.5, 11.0, 12.0)
}

/// Two staggered walls: x 0.6–0.7 m up from the bottom edge to y 0.8 m, x 1.0–1.1 m down from
/// the top edge to y 0.4 m.
fn zigzag() -> String {
    obstacle(6.0, 0.0, 7.0, 8.0) + &obstacle(10.0, 4.0, 11.0, 12.0)
}

/// A box of `w` × `h` grid units centred at grid (cx, cy), with a goal at grid (gx, gy).
fn boxed(id: &str, w: f64, h: f64, c: (f64, f64), g: (f64, f64), marker: u32, mass: f64) -> String {
    let (hw, hh) = (w * 0.05, h * 0.05);
    format!(
        r#"
[[objects]]
id = "{id}"
outline = [[{a:.3}, {b:.3}], [{hw:.3}, {b:.3}], [{hw:.3}, {hh:.3}], [{a:.3}, {hh:.3}]]
pose = {{ x = {cx:.3}, y = {cy:.3}, theta = 0.0 }}
mass = {mass}
support_friction = 0.35
pusher_friction = 0.5
marker = {{ id = {marker}, x = 0.0, y = 0.0, size = 0.04 }}

[[goals]]
object = "{id}"
pose = {{ x = {gx:.3}, y = {gy:.3}, theta = 0.0 }}
tolerance = 0.03
"#,
        a = -hw,
        b = -hh,
        cx = c.0 * 0.1,
        cy = c.1 * 0.1,
        gx = g.0 * 0.1,
        gy = g.1 * 0.1,
    )
}

fn header(name: &str, comment: &str, w: f64, h: f64, start: (f64, f64)) -> String {
    format!(
        "name = \"{name}\"\n# {comment}\n[table]\nwidth = {w}\nheight = {h}\n\n[robot]\nstart = {{ x = {:.3}, y = {:.3}, theta = 0.0 }}\n",
        start.0 * 0.1,
        start.1 * 0.1
    )
}

/// Test case A: two rooms joined by a door; two boxes to bring from the left room to the right.
fn bsr_a() -> String {
    let mut s = header(
        "bsr-a",
        "Ben-Shahar & Rivlin, test case A: two boxes to the other room (grid unit 0.1 m).",
        2.0,
        1.2,
        (2.0, 2.0),
    );
    // Dividing wall at x = 10..10.5 with a door from y = 5 to 8.
    s += &obstacle(10.0, 0.0, 10.5, 5.0);
    s += &obstacle(10.0, 8.0, 10.5, 12.0);
    s += &boxed("box-1", 1.5, 1.5, (5.0, 4.0), (15.0, 3.0), 1, 0.3);
    s += &boxed("box-2", 1.5, 1.5, (5.0, 8.0), (15.0, 9.0), 2, 0.5);
    s
}

/// Test case B: a corridor; the robot must exchange two boxes (one goes aside first).
fn bsr_b() -> String {
    let mut s = header(
        "bsr-b",
        "Ben-Shahar & Rivlin, test case B: exchange two boxes in a corridor with one bay.",
        2.0,
        1.0,
        (1.5, 5.0),
    );
    // Corridor y = 3.5..6.5 with a bay above it at x = 9..12.
    s += &obstacle(0.0, 0.0, 20.0, 3.5);
    s += &obstacle(0.0, 6.5, 9.0, 10.0);
    s += &obstacle(12.0, 6.5, 20.0, 10.0);
    s += &boxed("box-1", 1.5, 1.5, (6.0, 5.0), (14.0, 5.0), 1, 0.3);
    s += &boxed("box-2", 1.5, 1.5, (14.0, 5.0), (6.0, 5.0), 2, 0.3);
    s
}

/// Test case C: a complex (U-shaped) movable through a door into the next room.
fn bsr_c() -> String {
    let mut s = header(
        "bsr-c",
        "Ben-Shahar & Rivlin, test case C: a complex movable through a door.",
        2.0,
        1.2,
        (2.0, 6.0),
    );
    s += &obstacle(10.0, 0.0, 10.5, 3.5);
    s += &obstacle(10.0, 8.5, 10.5, 12.0);
    s += r#"
[[objects]]
id = "u-shape"
outline = [[-0.12, -0.08], [0.12, -0.08], [0.12, 0.08], [0.06, 0.08], [0.06, -0.02], [-0.06, -0.02], [-0.06, 0.08], [-0.12, 0.08]]
pose = { x = 0.6, y = 0.6, theta = 0.0 }
mass = 0.5
support_friction = 0.35
pusher_friction = 0.5
marker = { id = 1, x = 0.0, y = -0.05, size = 0.04 }

[[goals]]
object = "u-shape"
pose = { x = 1.5, y = 0.6, theta = 0.0 }
tolerance = 0.03
angle_tolerance = 0.2
"#;
    s
}

/// Test case D: an L-shaped movable that must be rotated by 90° among clutter.
fn bsr_d() -> String {
    let mut s = header(
        "bsr-d",
        "Ben-Shahar & Rivlin, test case D: nontranslational pushes in a cluttered room.",
        1.6,
        1.2,
        (2.0, 2.0),
    );
    s += &obstacle(5.0, 0.0, 6.0, 4.0);
    s += &obstacle(9.0, 3.0, 10.0, 8.0);
    s += &obstacle(4.0, 8.0, 7.0, 9.0);
    s += &obstacle(12.0, 0.0, 13.0, 3.0);
    s += r#"
[[objects]]
id = "l-shape"
outline = [[-0.1, -0.1], [0.1, -0.1], [0.1, -0.04], [-0.04, -0.04], [-0.04, 0.1], [-0.1, 0.1]]
pose = { x = 0.3, y = 0.6, theta = 0.0 }
mass = 0.4
support_friction = 0.35
pusher_friction = 0.5
marker = { id = 1, x = -0.07, y = -0.07, size = 0.04 }

[[goals]]
object = "l-shape"
pose = { x = 1.3, y = 0.8, theta = 1.5708 }
tolerance = 0.03
angle_tolerance = 0.2
"#;
    s
}

const LYNCH_MASON: &str = r#"
name = "lynch-mason-fig12"
# Lynch & Mason, Fig. 12: a slider pushed with stable line contact among obstacles.
[table]
width = 1.5
height = 1.0

[robot]
start = { x = 0.1, y = 0.2, theta = 0.0 }

[[obstacles]]
outline = [[0.45, 0.0], [0.55, 0.0], [0.55, 0.55], [0.45, 0.55]]
[[obstacles]]
outline = [[0.9, 0.45], [1.0, 0.45], [1.0, 1.0], [0.9, 1.0]]
[[obstacles]]
outline = [[0.65, 0.75], [0.75, 0.75], [0.75, 0.85], [0.65, 0.85]]

[[objects]]
id = "slider"
outline = [[-0.04, -0.06], [0.04, -0.06], [0.04, 0.06], [-0.04, 0.06]]
pose = { x = 0.25, y = 0.2, theta = 0.0 }
mass = 0.25
support_friction = 0.35
pusher_friction = 0.5
marker = { id = 1, x = 0.0, y = 0.0, size = 0.05 }

[[goals]]
object = "slider"
pose = { x = 1.25, y = 0.2, theta = 1.5708 }
tolerance = 0.02
angle_tolerance = 0.1
"#;

/// Three boxes in a row ahead of the robot, each with a goal further on.
fn three_boxes() -> String {
    let mut s = header(
        "three-boxes",
        "Three 8 cm boxes in a row ahead of the robot.",
        1.6,
        1.0,
        (2.0, 5.0),
    );
    s += &boxed("box-1", 0.8, 0.8, (4.0, 5.0), (12.0, 5.0), 1, 0.2);
    s += &boxed("box-2", 0.8, 0.8, (6.0, 7.0), (12.0, 7.0), 2, 0.2);
    s += &boxed("box-3", 0.8, 0.8, (6.0, 3.0), (12.0, 3.0), 3, 0.2);
    s
}
