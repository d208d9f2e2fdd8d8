//! Executing a rearrangement plan on the robot, Ben-Shahar & Rivlin §V-B (the NOMAD-200
//! experiment): the grid plan becomes motion primitives on the real table, and the camera
//! closes the loop. The grid lies on the table as [`GridFrame`] says; the scene for a grid
//! problem is [`crate::planner::rearrange::to_scene::scene_for`].
//!
//! [`execute`] repeats: observe → snap to the grid → restore the plan from the map (§IV-A2) →
//! carry out its first *segment*, the longest run of moves in one direction of one kind (a
//! transit drive, or a push run that ends by backing off the movable to the cell centre). The
//! map is never recomputed: when a movable ends off its expected cell, the snapped configuration
//! is simply a new start for restoration, which costs no re-propagation. With many movables
//! ([`execute_practical`]) the moves come from the practical mode's plan instead, planned again
//! from the observation when it leaves the plan ([`crate::exec::plan_source`]).

use std::f64::consts::FRAC_PI_2;

use std::collections::HashMap;

use anyhow::{Result, anyhow, bail};
use nalgebra::Vector2;

use crate::exec::grid_snap::{Sighting, snap_free};
use crate::exec::io::RobotIo;
use crate::exec::maneuver::{self, Drive, Turn};
use crate::exec::plan_source::{ExactSource, PlanSource, PracticalSource};
use crate::planner::rearrange::admissibility::MoveKind;
use crate::planner::rearrange::costmap::CostMap;
use crate::planner::rearrange::frame::GridFrame;
use crate::planner::rearrange::practical::Options;
use crate::planner::rearrange::problem::{Config, Dir, Model, Placement, Problem};
#[cfg(doc)]
use crate::planner::rearrange::to_scene::SceneOptions;

/// Settings of the executor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExecOptions {
    /// Side of a cell, m.
    pub cell: f64,
    /// Fraction of its cells a movable's body fills (as in [`SceneOptions::fill`]).
    pub fill: f64,
    /// Most segments before giving up.
    pub max_segments: usize,
    /// Longest push run between two observations, cells (a point pusher lets a box turn
    /// slowly; short runs re-align it).
    pub max_push_cells: usize,
    /// Give up when the same configuration is observed this many times.
    pub max_repeats: usize,
}

impl Default for ExecOptions {
    fn default() -> Self {
        ExecOptions {
            cell: 0.1,
            fill: 0.8,
            max_segments: 400,
            max_push_cells: 2,
            max_repeats: 6,
        }
    }
}

/// How an execution went.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ExecReport {
    /// The goal set was reached (the observed configuration has cost 0).
    pub reached: bool,
    /// The planner: "exact" (the cost map) or "practical".
    pub mode: String,
    /// Plans made: always 1 with the exact map (re-plans are lookups in it); with the practical
    /// mode, the first plan and one for each observation that left it.
    pub plans: usize,
    /// Segments carried out (transit drives and push runs).
    pub segments: usize,
    /// Grid moves carried out.
    pub moves: usize,
    /// Pushing moves among them.
    pub pushes: usize,
    /// Times the observed configuration differed from the expected one (and restoration
    /// started from the observed one instead).
    pub deviations: usize,
    /// Re-plans: observations with a movable off the cell the plan had put it in (pushed
    /// off-grid, moved by hand), each continued from where the movables really were.
    pub replans: Vec<Replan>,
    /// Cost of the plan from the first observation.
    pub planned_cost: u32,
    /// Cost of the moves actually carried out.
    pub executed_cost: u32,
    /// Robot time spent, s.
    pub time_s: f64,
    /// The last observed configuration: robot anchor and movables' (x, y, o).
    pub final_robot: (i32, i32),
    /// The movables' last observed placements.
    pub final_movables: Vec<(i32, i32, u8)>,
}

/// A movable found off the cell the plan had put it in.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MovedBox {
    /// Its name.
    pub name: String,
    /// The cell the plan had put it in (x, y).
    pub expected: (i32, i32),
    /// The cell it was seen in.
    pub observed: (i32, i32),
}

/// A re-plan: the movables were not where the plan had put them.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Replan {
    /// Segments carried out before it.
    pub after_segment: usize,
    /// Each movable found off its expected cell.
    pub moved: Vec<MovedBox>,
    /// Cost of the rest of the plan as expected, and from where the movables were.
    pub cost_expected: u32,
    /// Cost from the observed configuration (an instant lookup in the cost map).
    pub cost_observed: u32,
}

/// Observe the robot and every movable and snap them to the grid. `memory` is the robot's last
/// move (direction, was a push), which the camera cannot see. Returns the snapped configuration
/// and what was seen.
pub fn observe(
    p: &Problem,
    frame: &GridFrame,
    io: &mut dyn RobotIo,
    memory: (Dir, bool),
) -> Result<(Config, Sighting)> {
    let k = p.robot.size;
    let rp = io.robot_pose();
    let half = (k - 1) as f64 / 2.0 * frame.cell;
    let anchor = frame.cell_of(rp.position() - Vector2::new(half, -half));
    let mut movables = Vec::with_capacity(p.movables.len());
    let mut seen = Vec::with_capacity(p.movables.len());
    for (i, m) in p.movables.iter().enumerate() {
        let bp = io
            .body_pose(&m.name)
            .ok_or_else(|| anyhow!("the camera does not see movable `{}`", m.name))?;
        let (x, y) = frame.cell_of(bp.position());
        let o = if m.rotates {
            ((-bp.theta / FRAC_PI_2).round() as i32).rem_euclid(4) as u8
        } else {
            p.start.movables[i].o
        };
        movables.push(Placement { x, y, o });
        seen.push(bp.position());
    }
    let q = Config {
        robot: anchor,
        heading: memory.0,
        pushing: memory.1,
        movables,
    };
    let sighting = Sighting {
        robot: rp.position(),
        movables: seen,
    };
    Ok((q, sighting))
}

/// Turn to `heading` (rad) from the observed pose: one spin.
fn face(io: &mut dyn RobotIo, heading: f64) -> Result<()> {
    maneuver::face(io, heading, &Turn::ONCE)
}

/// Drive the robot's centre to `target`: turn, then straight by the distance measured after
/// the turn (spinning in place may have shifted the centre a little).
fn drive_to(io: &mut dyn RobotIo, target: Vector2<f64>) -> Result<()> {
    maneuver::go_to(io, target, &Drive::one_leg(0.003))
}

/// Carry out the plan from the map until the goal set is reached, re-observing after every
/// segment and restoring from the observed configuration (never recomputing the map).
pub fn execute(
    model: &Model,
    map: &CostMap,
    io: &mut dyn RobotIo,
    opts: &ExecOptions,
) -> Result<ExecReport> {
    execute_from(&mut ExactSource { model, map }, io, opts)
}

/// Carry out a practical-mode plan (many movables) until the goal set is reached, re-observing
/// after every segment and planning again from the observation when it is not where the plan
/// had put things.
pub fn execute_practical(
    problem: &Problem,
    plan_opts: Options,
    io: &mut dyn RobotIo,
    opts: &ExecOptions,
) -> Result<ExecReport> {
    execute_from(&mut PracticalSource::new(problem, plan_opts), io, opts)
}

/// Carry out the plans of `src` until the goal set is reached, re-observing after every segment.
pub fn execute_from(
    src: &mut dyn PlanSource,
    io: &mut dyn RobotIo,
    opts: &ExecOptions,
) -> Result<ExecReport> {
    let p = &src.problem().clone();
    let frame = GridFrame {
        cell: opts.cell,
        h: p.grid.h,
    };
    let k = p.robot.size;
    let r = io.workspace().robot_radius;
    let margin = (1.0 - opts.fill) / 2.0 * opts.cell;
    // Robot centre ahead of its cell(s) centre when its bumper touches a movable's face.
    let contact_ahead = k as f64 * opts.cell / 2.0 + margin - r;
    let t0 = io.time();
    let mut memory = (p.start.heading, p.start.pushing);
    let mut expected: Option<Config> = None;
    let mut seen: HashMap<((i32, i32), Vec<Placement>), usize> = HashMap::new();
    let mut expected_cost = 0u32;
    let mut report = ExecReport {
        reached: false,
        mode: src.mode().to_string(),
        plans: 1,
        segments: 0,
        moves: 0,
        pushes: 0,
        deviations: 0,
        replans: Vec::new(),
        planned_cost: 0,
        executed_cost: 0,
        time_s: 0.0,
        final_robot: (0, 0),
        final_movables: Vec::new(),
    };
    loop {
        let (q, sighting) = observe(p, &frame, io, memory)?;
        report.final_robot = q.robot;
        report.final_movables = q.movables.iter().map(|m| (m.x, m.y, m.o)).collect();
        if let Some(e) = &expected
            && (e.robot != q.robot || e.movables != q.movables)
        {
            report.deviations += 1;
            tracing::info!(
                "observed {:?} {:?}, expected {:?} {:?}: restoring from the observation",
                q.robot,
                q.movables,
                e.robot,
                e.movables
            );
        }
        let q = snap_free(&*src, &frame, &sighting, q)?;
        let moved: Vec<MovedBox> = match &expected {
            Some(e) => p
                .movables
                .iter()
                .zip(e.movables.iter().zip(&q.movables))
                .filter(|(_, (a, b))| (a.x, a.y) != (b.x, b.y))
                .map(|(m, (a, b))| MovedBox {
                    name: m.name.clone(),
                    expected: (a.x, a.y),
                    observed: (b.x, b.y),
                })
                .collect(),
            None => Vec::new(),
        };
        let rest = src.rest_from(&q)?;
        let cost = rest.cost;
        if report.segments == 0 {
            report.planned_cost = cost;
        }
        if !moved.is_empty() {
            let cost_expected = expected_cost;
            tracing::info!(
                "re-plan ({}) after segment {}: {}; cost {cost_expected} → {cost}",
                src.mode(),
                report.segments,
                moved
                    .iter()
                    .map(|m| format!(
                        "`{}` at cell {:?}, not {:?}",
                        m.name, m.observed, m.expected
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            report.replans.push(Replan {
                after_segment: report.segments,
                moved,
                cost_expected,
                cost_observed: cost,
            });
        }
        if cost == 0 {
            report.reached = true;
            break;
        }
        let repeats = seen.entry((q.robot, q.movables.clone())).or_insert(0);
        *repeats += 1;
        if *repeats > opts.max_repeats {
            let n = *repeats;
            let seen_at: Vec<String> = std::iter::once(("robot", Some(io.robot_pose())))
                .chain(
                    p.movables
                        .iter()
                        .map(|m| (m.name.as_str(), io.body_pose(&m.name))),
                )
                .map(|(name, pose)| match pose {
                    Some(b) => format!("{name} at ({:.3}, {:.3}, {:.2} rad)", b.x, b.y, b.theta),
                    None => format!("{name} not seen"),
                })
                .collect();
            bail!(
                "no progress: configuration (robot {:?}, movables {:?}) observed {n} times; {}",
                q.robot,
                q.movables,
                seen_at.join(", ")
            );
        }
        if report.segments >= opts.max_segments {
            break;
        }
        let Some(first) = rest.moves.first() else {
            bail!(
                "the {} planner gave no move from a configuration of cost {cost}",
                src.mode()
            );
        };
        let mut n = rest
            .moves
            .iter()
            .take_while(|s| s.dir == first.dir && s.kind == first.kind)
            .count();
        if let MoveKind::Push { .. } = first.kind {
            n = n.min(opts.max_push_cells.max(1));
        }
        let seg = &rest.moves[..n];
        let last = &seg[n - 1].config;
        let end = frame.robot_centre(last.robot, k);
        tracing::debug!(
            "segment {:?} {:?} × {n}: robot {:?} → {:?}, movables {:?} → {:?}",
            first.kind,
            first.dir,
            q.robot,
            last.robot,
            q.movables,
            last.movables
        );
        match first.kind {
            MoveKind::Transit => drive_to(io, end)?,
            MoveKind::Push { pushed } => {
                let u = GridFrame::dir(first.dir);
                let perp = Vector2::new(-u.y, u.x);
                // Stand on the line of the nearest pushed movable as it really lies, so the
                // bumper meets its face where the grid says.
                let here = io.robot_pose().position();
                let mut lead = None;
                let mut nearest = f64::INFINITY;
                for (i, m) in p.movables.iter().enumerate() {
                    if pushed & (1 << i) == 0 {
                        continue;
                    }
                    if let Some(bp) = io.body_pose(&m.name) {
                        let d = (bp.position() - here).norm();
                        if d < nearest {
                            nearest = d;
                            lead = Some(i);
                        }
                    }
                }
                let lateral = match lead.and_then(|i| io.body_pose(&p.movables[i].name)) {
                    Some(bp) => {
                        let at = q.movables[lead.unwrap_or(0)];
                        (bp.position() - frame.centre(at.x, at.y)).dot(&perp)
                    }
                    None => 0.0,
                };
                let start = frame.robot_centre(q.robot, k) + perp * lateral;
                drive_to(io, start)?;
                face(io, GridFrame::heading(first.dir))?;
                let target = end + perp * lateral + u * contact_ahead;
                let along = (target - io.robot_pose().position()).dot(&u);
                io.forward(along)?;
                // Back off to the cell centre, or a cell's worth behind the lead movable if it
                // came up short, so the next move starts clear of it.
                let rp = io.robot_pose().position();
                let mut back = (end - rp).dot(&u);
                if let Some(i) = lead
                    && let Some(bp) = io.body_pose(&p.movables[i].name)
                {
                    let pe = last.movables[i];
                    let gap = (frame.centre(pe.x, pe.y) - end).dot(&u);
                    back = back.min((bp.position() - rp).dot(&u) - gap);
                }
                io.forward(back.min(0.0))?;
                report.pushes += n;
            }
            MoveKind::Rotate { .. } => {
                bail!("rotational pushes are not executed yet (only translational plans)")
            }
        }
        report.segments += 1;
        report.moves += n;
        let seg_cost = seg.iter().map(|s| s.cost).sum::<u32>();
        report.executed_cost += seg_cost;
        expected_cost = cost - seg_cost;
        memory = (first.dir, !matches!(first.kind, MoveKind::Transit));
        expected = Some(last.clone());
        src.advance(n);
    }
    report.time_s = io.time() - t0;
    report.plans = src.plans();
    Ok(report)
}
