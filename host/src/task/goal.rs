//! Goals the operator chooses — on the command line (`--goal X,Y[,DEG]`, `--goal ID=X,Y`) or by
//! dragging on the console's table — read and checked against the scene before anything moves:
//! a goal off the table, inside an obstacle, or where the robot cannot stand behind the object
//! to push it (Lau et al. §III-A: the object stays inside the boundary) is refused with a
//! message that says which and why.

use pushbot_world::Scene;

use crate::planner::global::polygon_distance;

/// A goal in the table frame: where the object's marker should end, and its heading if asked.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GoalPose {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Heading, degrees; `None`: any.
    pub deg: Option<f64>,
}

/// Why a goal is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct GoalError(pub String);

/// Read `X,Y` or `X,Y,DEG` (metres, degrees).
pub fn parse_goal(s: &str) -> Result<GoalPose, GoalError> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let bad = || {
        GoalError(format!(
            "goal {s:?}: give X,Y or X,Y,DEG (metres on the table, degrees), e.g. 1.0,0.6 or 1.0,0.6,90"
        ))
    };
    if !(2..=3).contains(&parts.len()) {
        return Err(bad());
    }
    let mut v = Vec::new();
    for p in &parts {
        let x: f64 = p.parse().map_err(|_| bad())?;
        if !x.is_finite() {
            return Err(bad());
        }
        v.push(x);
    }
    Ok(GoalPose {
        x: v[0],
        y: v[1],
        deg: v.get(2).copied(),
    })
}

/// Read `ID=X,Y[,DEG]`.
pub fn parse_id_goal(s: &str) -> Result<(String, GoalPose), GoalError> {
    let Some((id, rest)) = s.split_once('=') else {
        return Err(GoalError(format!(
            "goal {s:?}: give ID=X,Y (an object id and metres on the table), e.g. box1=0.35,0.45"
        )));
    };
    let id = id.trim();
    if id.is_empty() {
        return Err(GoalError(format!("goal {s:?}: the object id is empty")));
    }
    Ok((id.to_string(), parse_goal(rest)?))
}

/// What a goal must keep clear of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    /// The object's radius about its marker (its enclosing circle), m.
    pub object_radius: f64,
    /// How far inside the table's edge the object must stay so the robot can stand behind it, m.
    pub inset: f64,
}

/// Check `goal` for the object `id` of `scene`: on the table, out of every obstacle with the
/// object's body clear of it, and inside the region the robot can push it in.
pub fn check_goal(scene: &Scene, id: &str, goal: &GoalPose, reach: Reach) -> Result<(), GoalError> {
    let (w, h) = (scene.table.width, scene.table.height);
    let (x, y) = (goal.x, goal.y);
    if !(x.is_finite() && y.is_finite()) || goal.deg.is_some_and(|d| !d.is_finite()) {
        return Err(GoalError(format!("the goal of {id} is not a finite pose")));
    }
    if x < 0.0 || y < 0.0 || x > w || y > h {
        return Err(GoalError(format!(
            "the goal ({x:.3}, {y:.3}) of {id} is off the table ({w} × {h} m; x in 0..{w}, y in 0..{h})"
        )));
    }
    let p = nalgebra::Vector2::new(x, y);
    for (i, o) in scene.obstacles.iter().enumerate() {
        let d = polygon_distance(p, &o.outline);
        let name = obstacle_name(i, &o.outline);
        if d <= 0.0 {
            return Err(GoalError(format!(
                "the goal ({x:.3}, {y:.3}) of {id} is inside {name}"
            )));
        }
        if d < reach.object_radius {
            return Err(GoalError(format!(
                "the goal ({x:.3}, {y:.3}) of {id} is {:.1} cm from {name}: the object \
                 ({:.1} cm about its marker) would overlap it",
                d * 100.0,
                reach.object_radius * 100.0
            )));
        }
    }
    let m = reach.inset;
    if x < m || y < m || x > w - m || y > h - m {
        return Err(GoalError(format!(
            "the goal ({x:.3}, {y:.3}) of {id} is out of the robot's reach: the object must stay \
             {m:.2} m inside the table's edge (x in {m:.2}..{:.2}, y in {m:.2}..{:.2}) so the \
             robot can stand behind it to push",
            w - m,
            h - m
        )));
    }
    Ok(())
}

/// How an obstacle is named to the operator: its number in the scene and where it is.
pub fn obstacle_name(i: usize, outline: &[[f64; 2]]) -> String {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in outline {
        for k in 0..2 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    format!(
        "obstacle {} (x {:.2}..{:.2}, y {:.2}..{:.2} m)",
        i + 1,
        lo[0],
        hi[0],
        lo[1],
        hi[1]
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reach() -> Reach {
        Reach {
            object_radius: 0.05,
            inset: 0.2,
        }
    }

    #[test]
    fn goals_parse_and_bad_ones_say_how_to_write_them() {
        assert_eq!(
            parse_goal("1.0, 0.6").unwrap(),
            GoalPose {
                x: 1.0,
                y: 0.6,
                deg: None
            }
        );
        assert_eq!(parse_goal("1,0.6,90").unwrap().deg, Some(90.0));
        for bad in ["1.0", "a,b", "1,2,3,4", "nan,1", ""] {
            assert!(parse_goal(bad).unwrap_err().0.contains("X,Y"), "{bad}");
        }
        let (id, g) = parse_id_goal("box1=0.35,0.45").unwrap();
        assert_eq!((id.as_str(), g.x, g.y), ("box1", 0.35, 0.45));
        assert!(parse_id_goal("0.35,0.45").is_err());
    }

    #[test]
    fn a_goal_inside_an_obstacle_names_it() {
        let scene = Scene::preset("lau-zigzag-l").unwrap();
        let o = &scene.obstacles[0].outline;
        let (cx, cy) = (
            o.iter().map(|v| v[0]).sum::<f64>() / o.len() as f64,
            o.iter().map(|v| v[1]).sum::<f64>() / o.len() as f64,
        );
        let inside =
            scene.obstacles.iter().enumerate().find(|(_, ob)| {
                polygon_distance(nalgebra::Vector2::new(cx, cy), &ob.outline) <= 0.0
            });
        let g = GoalPose {
            x: cx,
            y: cy,
            deg: None,
        };
        let e = check_goal(&scene, "l-shape", &g, reach()).unwrap_err().0;
        if let Some((i, _)) = inside {
            assert!(e.contains(&format!("inside obstacle {}", i + 1)), "{e}");
        } else {
            assert!(e.contains("obstacle"), "{e}");
        }
    }

    #[test]
    fn goals_off_the_table_or_out_of_reach_are_refused_and_a_free_one_passes() {
        let scene = Scene::preset("lau-irregular").unwrap();
        let g = |x, y| GoalPose { x, y, deg: None };
        let e = check_goal(&scene, "irregular", &g(-0.1, 0.5), reach())
            .unwrap_err()
            .0;
        assert!(e.contains("off the table"), "{e}");
        let e = check_goal(&scene, "irregular", &g(0.05, 0.5), reach())
            .unwrap_err()
            .0;
        assert!(e.contains("out of the robot's reach"), "{e}");
        check_goal(&scene, "irregular", &g(1.0, 0.6), reach()).unwrap();
    }
}
