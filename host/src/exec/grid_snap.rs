//! Snapping what the camera sees to the grid of Ben-Shahar & Rivlin's configuration space
//! (§III, the free space CCF), for executing a plan ([`crate::exec::rearrange`]): when the
//! snapped configuration overlaps (a body seen across a cell border), the nearest free one.

use anyhow::{Result, bail};
use nalgebra::Vector2;

use crate::exec::plan_source::PlanSource;
use crate::planner::rearrange::frame::GridFrame;
use crate::planner::rearrange::problem::Config;

/// Where the camera saw the robot's centre and each movable's reference point (table frame,
/// m), before snapping to the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Sighting {
    /// The robot's centre.
    pub robot: Vector2<f64>,
    /// Each movable's reference point, in the problem's order.
    pub movables: Vec<Vector2<f64>>,
}

/// The free configuration nearest to what was seen, when the snapped one overlaps: a body seen
/// across a cell border from where it stands clear (the robot beside a box it just left, a box
/// put down by hand between two cells). Up to two bodies move to a neighbouring cell each; of
/// the free configurations so found, the one whose cells' centres lie least far (in sum) from
/// where the bodies were seen. Fails, naming every body's place, when none is free: then
/// something really overlaps (a box on a wall, off the grid).
pub fn snap_free(
    src: &dyn PlanSource,
    frame: &GridFrame,
    seen: &Sighting,
    q: Config,
) -> Result<Config> {
    if src.free(&q) {
        return Ok(q);
    }
    let k = src.problem().robot.size;
    // Body 0 is the robot, body i + 1 the movable i: (its anchor cell's centre, where seen).
    let centre = |b: usize, a: (i32, i32)| match b {
        0 => frame.robot_centre(a, k),
        _ => frame.centre(a.0, a.1),
    };
    let anchor = |c: &Config, b: usize| match b {
        0 => c.robot,
        _ => (c.movables[b - 1].x, c.movables[b - 1].y),
    };
    let at = |b: usize| {
        if b == 0 {
            seen.robot
        } else {
            seen.movables[b - 1]
        }
    };
    let place = |c: &mut Config, b: usize, a: (i32, i32)| match b {
        0 => c.robot = a,
        _ => (c.movables[b - 1].x, c.movables[b - 1].y) = a,
    };
    // Each body's other cells: its 8 neighbours, with how much farther their centre lies.
    let alternatives: Vec<Vec<(f64, (i32, i32))>> = (0..=q.movables.len())
        .map(|b| {
            let (x, y) = anchor(&q, b);
            let here = (centre(b, (x, y)) - at(b)).norm();
            let mut v = Vec::with_capacity(8);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if (dx, dy) != (0, 0) {
                        let a = (x + dx, y + dy);
                        v.push(((centre(b, a) - at(b)).norm() - here, a));
                    }
                }
            }
            v
        })
        .collect();
    let mut best: Option<(f64, Config)> = None;
    let mut consider = |extra: f64, c: Config| {
        if best.as_ref().is_none_or(|(e, _)| extra < *e) && src.free(&c) {
            best = Some((extra, c));
        }
    };
    for (b, alts) in alternatives.iter().enumerate() {
        for &(e, a) in alts {
            let mut c = q.clone();
            place(&mut c, b, a);
            consider(e, c.clone());
            for (b2, alts2) in alternatives.iter().enumerate().skip(b + 1) {
                for &(e2, a2) in alts2 {
                    let mut c2 = c.clone();
                    place(&mut c2, b2, a2);
                    consider(e + e2, c2);
                }
            }
        }
    }
    if let Some((extra, c)) = best {
        tracing::info!(
            "seen overlapping (robot {:?}, movables {:?}); nearest free: robot {:?}, movables \
             {:?} ({:.3} m farther from what was seen)",
            q.robot,
            q.movables,
            c.robot,
            c.movables,
            extra
        );
        return Ok(c);
    }
    let mut bodies = vec![format!(
        "robot at ({:.3}, {:.3}) m, cell {:?}",
        seen.robot.x, seen.robot.y, q.robot
    )];
    for ((m, s), pl) in src
        .problem()
        .movables
        .iter()
        .zip(&seen.movables)
        .zip(&q.movables)
    {
        bodies.push(format!(
            "`{}` at ({:.3}, {:.3}) m, cell ({}, {})",
            m.name, s.x, s.y, pl.x, pl.y
        ));
    }
    bail!(
        "what the camera sees fits no free grid configuration (a body on an obstacle or off \
         the grid, or two bodies in one cell): {}",
        bodies.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::plan_source::PracticalSource;
    use crate::planner::rearrange::cases::load_scene;
    use crate::planner::rearrange::practical::Options;
    use crate::planner::rearrange::problem::Placement;
    use proptest::prelude::*;

    /// Case A1 (an 18 × 7 room of 0.1 m cells, boxes `a` and `b`) and its grid frame.
    fn a1() -> (PracticalSource, GridFrame) {
        let p = load_scene("A1").expect("preset");
        let frame = GridFrame {
            cell: 0.1,
            h: p.grid.h,
        };
        (PracticalSource::new(&p, Options::for_problem(&p)), frame)
    }

    /// A placement's cell.
    fn cell(p: &Placement) -> (i32, i32) {
        (p.x, p.y)
    }

    /// Snap what was seen the way the executor does.
    fn snapped(src: &PracticalSource, frame: &GridFrame, seen: &Sighting) -> Config {
        let p = src.problem();
        let k = p.robot.size;
        let half = (k - 1) as f64 / 2.0 * frame.cell;
        let robot = frame.cell_of(seen.robot - Vector2::new(half, -half));
        let movables = seen
            .movables
            .iter()
            .map(|s| {
                let (x, y) = frame.cell_of(*s);
                Placement { x, y, o: 0 }
            })
            .collect();
        Config {
            robot,
            heading: p.start.heading,
            pushing: false,
            movables,
        }
    }

    /// Sum over the bodies of how far their cells' centres lie from where they were seen.
    fn spread(src: &PracticalSource, frame: &GridFrame, seen: &Sighting, c: &Config) -> f64 {
        let k = src.problem().robot.size;
        (frame.robot_centre(c.robot, k) - seen.robot).norm()
            + c.movables
                .iter()
                .zip(&seen.movables)
                .map(|(m, s)| (frame.centre(m.x, m.y) - s).norm())
                .sum::<f64>()
    }

    #[test]
    fn a_robot_seen_in_a_box_cell_steps_to_the_nearer_free_side() {
        let (src, frame) = a1();
        // Box `b` in the middle of cell (4, 3); the robot's centre 1 cm past it, east.
        let seen = Sighting {
            robot: Vector2::new(0.46, 0.35),
            movables: vec![Vector2::new(0.25, 0.35), Vector2::new(0.45, 0.35)],
        };
        let q = snapped(&src, &frame, &seen);
        assert_eq!(
            q.robot,
            cell(&q.movables[1]),
            "the test's premise: one cell"
        );
        let c = snap_free(&src, &frame, &seen, q.clone()).expect("a free configuration");
        assert_eq!(
            c.robot,
            (5, 3),
            "east of the box, where the robot really is"
        );
        assert_eq!(
            c.movables, q.movables,
            "the boxes stay where they were seen"
        );
    }

    #[test]
    fn a_box_put_down_on_a_cell_corner_goes_to_a_free_cell_beside_it() {
        let (src, frame) = a1();
        // The robot in the middle of (3, 3); box `b` put down on the corner it shares with
        // (2, 3) (box `a`), (2, 2) and (3, 2).
        let seen = Sighting {
            robot: Vector2::new(0.35, 0.35),
            movables: vec![Vector2::new(0.25, 0.35), Vector2::new(0.30, 0.40)],
        };
        let q = snapped(&src, &frame, &seen);
        let c = snap_free(&src, &frame, &seen, q.clone()).expect("a free configuration");
        assert!(src.free(&c));
        assert_eq!(
            c.robot, q.robot,
            "the robot stands in the middle of its cell"
        );
        assert!(
            [(2, 2), (3, 2)].contains(&cell(&c.movables[1])),
            "box b went to {:?}",
            c.movables[1]
        );
    }

    #[test]
    fn a_box_seen_off_the_grid_is_a_clear_error_naming_it() {
        let (src, frame) = a1();
        let seen = Sighting {
            robot: Vector2::new(0.05, 0.35),
            movables: vec![Vector2::new(0.25, 0.35), Vector2::new(-0.31, 0.35)],
        };
        let q = snapped(&src, &frame, &seen);
        let e = snap_free(&src, &frame, &seen, q).expect_err("no free configuration");
        let msg = e.to_string();
        assert!(msg.contains("`b` at (-0.310, 0.350) m"), "{msg}");
        assert!(msg.contains("fits no free grid configuration"), "{msg}");
    }

    std::thread_local! {
        /// Overlapping sightings met by the property below (it must meet some).
        static OVERLAPS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    #[test]
    fn the_property_meets_overlapping_sightings() {
        OVERLAPS.with(|n| n.set(0));
        the_snap_is_the_nearest_free_configuration();
        let n = OVERLAPS.with(|n| n.get());
        assert!(n >= 20, "only {n} of the property's cases overlapped");
    }

    proptest! {
        /// Against brute force over every body's 3 × 3 cells: the snap is free and as near to
        /// what was seen as the nearest free configuration that moves at most two bodies.
        #[test]
        fn the_snap_is_the_nearest_free_configuration(
            a in (0.0..1.8f64, 0.0..0.7f64),
            r in (-0.15..0.15f64, -0.15..0.15f64),
            b in (-0.15..0.15f64, -0.15..0.15f64),
        ) {
            // The robot and box `b` near box `a`, so that they often share a cell.
            let (src, frame) = a1();
            let a = Vector2::new(a.0, a.1);
            let seen = Sighting {
                robot: a + Vector2::new(r.0, r.1),
                movables: vec![a, a + Vector2::new(b.0, b.1)],
            };
            let q = snapped(&src, &frame, &seen);
            let mut best: Option<(f64, Config)> = None;
            let around = |(x, y): (i32, i32)| {
                (-1..=1).flat_map(move |dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            };
            for ra in around(q.robot) {
                for aa in around(cell(&q.movables[0])) {
                    for ba in around(cell(&q.movables[1])) {
                        let mut c = q.clone();
                        c.robot = ra;
                        (c.movables[0].x, c.movables[0].y) = aa;
                        (c.movables[1].x, c.movables[1].y) = ba;
                        let moved = usize::from(ra != q.robot)
                            + usize::from(aa != cell(&q.movables[0]))
                            + usize::from(ba != cell(&q.movables[1]));
                        let d = spread(&src, &frame, &seen, &c);
                        if moved <= 2 && src.free(&c) && best.as_ref().is_none_or(|(e, _)| d < *e) {
                            best = Some((d, c));
                        }
                    }
                }
            }
            let was_free = src.free(&q);
            match (snap_free(&src, &frame, &seen, q), best) {
                (Ok(c), Some((d, _))) => {
                    prop_assert!(src.free(&c));
                    prop_assert!((spread(&src, &frame, &seen, &c) - d).abs() < 1e-9);
                }
                (Err(_), None) => {}
                (got, want) => prop_assert!(false, "snap {got:?}, brute force {want:?}"),
            }
            OVERLAPS.with(|n| n.set(n.get() + usize::from(!was_free)));
        }
    }
}
