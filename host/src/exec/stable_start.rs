//! The transit to the first pushing contact from wherever the robot starts, at any
//! heading. Lynch & Mason §4.6 leave the transit between contacts open;
//! [`crate::planner::stable::transit`] plans it for the robot's turning disk, and this is the
//! same from a free start pose of any heading instead of from a contact: a shortest path of the
//! turning disk among the obstacles and the slider to the stand-off in front of the first
//! edge ([`disk_path`]), then the plate brought flush on the edge
//! ([`crate::exec::stable::approach`]).
//!
//! For a car the legs turn in place at the way points, as the planner's transit paths do: the
//! robot that drives them is a differential drive (a car's transits with its turning radius
//! are not planned).

use anyhow::{Context, Result};

use crate::exec::io::RobotIo;
use crate::exec::maneuver::{Drive, go_to};
use crate::exec::stable::{approach, flush_pose};
use crate::mechanics::{V2, V3, convex_hull};
use crate::planner::stable::collision::Body;
use crate::planner::stable::transit::{disk_path, point_segment_distance};
use crate::planner::stable::{Pose, Problem, angle_diff};

/// The robot counts as on the edge already when its axle is this close to flush on it, m …
const ON_EDGE_XY: f64 = 0.005;
/// … and its heading this close, rad.
const ON_EDGE_THETA: f64 = 3.0 * std::f64::consts::PI / 180.0;
/// Way points count as reached this close, m.
const WAYPOINT_TOL: f64 = 0.004;

/// Whether the robot at `r` is (nearly) flush on contact `ci` of the slider at `s`.
pub fn on_edge(p: &Problem, ci: usize, r: &Pose, s: &Pose) -> bool {
    let (c, h) = flush_pose(p, ci, s);
    (V2::new(r.x, r.y) - c).norm() <= ON_EDGE_XY
        && angle_diff(r.theta, h.y.atan2(h.x)).abs() <= ON_EDGE_THETA
}

/// The way points of the robot's axle centre from `robot` (any heading) to the stand-off in
/// front of contact `ci` of the slider at `s`, where the turning disk clears the slider; `None`
/// when the disk has no path there (or the straight leg onto the edge is blocked).
pub fn start_path(p: &Problem, robot: V2, s: &Pose, ci: usize) -> Option<Vec<V2>> {
    let r = p.pusher.turning_radius_disk();
    let pl = &p.contacts[ci].placement;
    let axle = pl.to_slider(V2::new(0.0, -p.pusher.axle_offset));
    let back = -pl.normal;
    let slider = &p.slider.vertices;
    let n = slider.len();
    // Clear of the slider grown as [`disk_path`] grows it (by the octagon circumscribing the
    // disk), so that the path may start there.
    let grown = r / (std::f64::consts::PI / 8.0).cos() + 1e-3;
    let clear =
        |c: V2| (0..n).all(|i| point_segment_distance(c, slider[i], slider[(i + 1) % n]) > grown);
    let mut b = 0.0;
    while !clear(axle + back * b) {
        b += 0.01;
        if b > 10.0 * (r + p.slider.radius()) {
            return None;
        }
    }
    // The footprint's straight leg in from the stand-off, checked exactly.
    let foot = Body::new(std::slice::from_ref(&p.contacts[ci].footprint));
    if !foot.step_free(&p.world, s, &V3::new(back.x * b, back.y * b, 0.0)) {
        return None;
    }

    let mut obstacles: Vec<Vec<V2>> = p.world.obstacles[p.world.n_walls..]
        .iter()
        .map(|o| o.vertices.clone())
        .collect();
    obstacles.push(convex_hull(
        &slider.iter().map(|v| s.apply(*v)).collect::<Vec<_>>(),
    ));
    disk_path(
        robot,
        s.apply(axle + back * b),
        r,
        p.world.table,
        &obstacles,
    )
}

/// Bring the robot from wherever it is onto contact `ci`: nothing when it is on the edge
/// already ([`on_edge`]), else along [`start_path`] and in ([`approach`]). `Ok(false)` when no
/// path exists.
pub fn go_to_first_contact(p: &Problem, ci: usize, io: &mut dyn RobotIo) -> Result<bool> {
    let (r, s) = crate::exec::stable::observe(io)?;
    if on_edge(p, ci, &r, &s) {
        return Ok(true);
    }
    let Some(path) = start_path(p, V2::new(r.x, r.y), &s, ci) else {
        return Ok(false);
    };
    for (k, w) in path.iter().enumerate().skip(1) {
        go_to(io, *w, &Drive::legs(WAYPOINT_TOL, 4))
            .with_context(|| format!("start transit, way point {k}"))?;
    }
    approach(p, ci, io).context("onto the first edge")?;
    Ok(true)
}
