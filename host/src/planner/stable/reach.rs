//! Infeasibility before the search (Lynch & Mason 1996 §4.2.4 ends a search only at MAXCOST or
//! the node limit; this decides the plainest "no plan" first): the slider's centre of friction
//! can only pass where the largest disk about it inside the slider fits among the obstacles and
//! the walls. If no cell of that free space around the goal neighbourhood is connected to the
//! start's, no push sequence reaches the goal, whatever the pusher.
//!
//! Sound, not complete: a cell is counted blocked only when every point of it is closer than
//! the disk's radius to an obstacle, and cells connect to all eight neighbours, so the centre's
//! path (continuous, always at least that radius from every obstacle) runs through unblocked,
//! connected cells. An answer of "reachable" says nothing.

use std::fmt;

use parry2d_f64::math::{Pose as PPose, Vector as PVec};
use parry2d_f64::query::PointQuery;

use super::Problem;
use crate::mechanics::{Slider, V2};

/// Most cells of the connectivity grid.
const MAX_CELLS: usize = 250_000;

/// Why the goal cannot be reached.
#[derive(Debug, Clone, PartialEq)]
pub struct Unreachable {
    /// Radius of the disk about the centre of friction inside the slider (m).
    pub radius: f64,
    /// Cells of the start's component.
    pub component_cells: usize,
    /// The obstacles (indices into the world's) that bound the start's component: together
    /// they cut the start off from the goal.
    pub blockers: Vec<usize>,
    /// Their names, as the scene gives them.
    pub names: Vec<String>,
}

impl fmt::Display for Unreachable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let who = match self.names.as_slice() {
            [] => "obstacles and walls".to_string(),
            [one] => one.clone(),
            [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
        };
        write!(
            f,
            "the goal is unreachable from the start: {who} cut the start off from the goal \
             (the slider's centre of friction, with the {:.1} mm disk about it that lies inside \
             the slider, cannot get from its start to the goal neighbourhood; {} grid cells \
             reached)",
            self.radius * 1e3,
            self.component_cells
        )
    }
}

/// Radius of the largest disk about the centre of friction (the slider frame's origin) inside
/// the slider: the distance to its nearest edge, 0 if the origin is outside (a concave slider).
pub fn inner_radius(slider: &Slider) -> f64 {
    let v = &slider.vertices;
    let n = v.len();
    let mut inside = false;
    let mut d = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        if (a.y > 0.0) != (b.y > 0.0) && a.x + (0.0 - a.y) * (b.x - a.x) / (b.y - a.y) > 0.0 {
            inside = !inside;
        }
        let e = b - a;
        let t = (-a.dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
        d = d.min((a + e * t).norm());
    }
    if inside { d } else { 0.0 }
}

/// `Some` when the goal neighbourhood is surely not connected to the start in the free space
/// of the slider's inner disk ([`inner_radius`]); `None` when it may be.
pub fn unreachable(p: &Problem) -> Option<Unreachable> {
    let r = inner_radius(&p.slider);
    let (w, h) = p.world.table;
    if !(r > 0.0 && w > 0.0 && h > 0.0) {
        return None;
    }
    // Cells of side s: blocked when the centre is closer than r − s/√2 to an obstacle.
    let s = (r / 2.0).max((w * h / MAX_CELLS as f64).sqrt());
    let margin = r - s * std::f64::consts::FRAC_1_SQRT_2;
    if margin <= 0.0 {
        return None;
    }
    let (nx, ny) = ((w / s).ceil() as usize, (h / s).ceil() as usize);
    let centre = |i: usize, j: usize| V2::new((i as f64 + 0.5) * s, (j as f64 + 0.5) * s);
    // The obstacle that blocks the cell centred at `c` (walls by their index in the world).
    let blocker = |c: V2| -> Option<usize> {
        let walls = [c.y, h - c.y, c.x, w - c.x];
        // The world's first four obstacles are the walls, in this order (`World::new`).
        if let Some(i) = walls.iter().position(|&d| d < margin) {
            return Some(i);
        }
        let n = p.world.n_walls;
        p.world.obstacles[n..]
            .iter()
            .position(|o| {
                let b = o.bounds;
                let dx = (b[0] - c.x).max(c.x - b[2]).max(0.0);
                let dy = (b[1] - c.y).max(c.y - b[3]).max(0.0);
                dx * dx + dy * dy < margin * margin
                    && o.shape()
                        .distance_to_point(&PPose::identity(), PVec::new(c.x, c.y), true)
                        < margin
            })
            .map(|i| n + i)
    };
    let mut blockers: Vec<usize> = Vec::new();
    let cell = |x: f64, y: f64| {
        let i = ((x / s).floor().max(0.0) as usize).min(nx - 1);
        let j = ((y / s).floor().max(0.0) as usize).min(ny - 1);
        (i, j)
    };
    let mut seen = vec![false; nx * ny];
    let (si, sj) = cell(p.start.x, p.start.y);
    let mut stack = vec![(si, sj)];
    seen[sj * nx + si] = true;
    let g = p.params.goal_xy;
    let (gi0, gj0) = cell(p.goal.x - g, p.goal.y - g);
    let (gi1, gj1) = cell(p.goal.x + g, p.goal.y + g);
    let mut count = 0;
    while let Some((i, j)) = stack.pop() {
        count += 1;
        if (gi0..=gi1).contains(&i) && (gj0..=gj1).contains(&j) {
            return None;
        }
        for (di, dj) in [
            (-1, -1),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ] {
            let (a, b) = (i as i64 + di, j as i64 + dj);
            if a < 0 || b < 0 || a >= nx as i64 || b >= ny as i64 {
                continue;
            }
            let (a, b) = (a as usize, b as usize);
            if !seen[b * nx + a] {
                seen[b * nx + a] = true;
                match blocker(centre(a, b)) {
                    None => stack.push((a, b)),
                    Some(o) if !blockers.contains(&o) => blockers.push(o),
                    Some(_) => {}
                }
            }
        }
    }
    blockers.sort_unstable();
    Some(Unreachable {
        radius: r,
        component_cells: count,
        names: p.world.names_of(blockers.iter().copied()),
        blockers,
    })
}
