//! The cost metric D(Q̂, Q) of Ben-Shahar & Rivlin §IV-C, with the metrics of §V-A and §V-B.
//!
//! One move costs, in integers:
//! - **mass metric**: `robot mass × passability` of the robot's arrival cells, plus for every
//!   pushed movable `its mass × passability` of its arrival cells (the more is pushed, the more
//!   the move costs);
//! - **passability metric**: the passability factor of a placement is the factor of its roughest
//!   cell: 1 for normal cells, `rough[0]` for rough, `rough[1]` for very rough (three levels);
//! - **safety metric**: `safety` more for every pushed movable that arrives next to an obstacle
//!   or the table's border (8-neighbourhood);
//! - **contact-mode changes**: `mode_change` for every push that does not continue a
//!   translational push in the same direction (each time the robot takes up a contact anew);
//! - **turn cost** (the NOMAD-200 lesson of §V-B): `turn` per quarter turn between the direction
//!   of the previous move and this one.
//!
//! The last two need the robot to remember its last move; then every robot placement carries
//! 8 memory states (direction × "was a translational push"), see [`Model::n_aux`].
//!
//! [`Model::n_aux`]: super::problem::Model::n_aux
//!
//! Below the problem: it takes only the grid; the bound on one move's cost, which needs the
//! whole problem, is [`Metric::max_edge`] in `problem/model.rs`.

use super::grid::{Dir, Grid};

/// Metric weights. All costs are integers; every move costs at least 1.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Metric {
    /// Passability factors of rough (level 1) and very rough (level 2) cells; normal is 1.
    pub rough: [u32; 2],
    /// Extra cost of pushing a movable next to an obstacle (0 = off).
    pub safety: u32,
    /// Cost per quarter turn of the robot (0 = off).
    pub turn: u32,
    /// Cost per contact-mode change (0 = off).
    pub mode_change: u32,
}

impl Default for Metric {
    fn default() -> Self {
        Metric {
            rough: [1, 1],
            safety: 0,
            turn: 0,
            mode_change: 0,
        }
    }
}

/// What kind of move a step is, for the metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepKind {
    /// The robot moves alone.
    Transit,
    /// The robot translates one or more movables.
    Translate,
    /// The robot turns a movable by 90°.
    Rotate,
}

impl Metric {
    /// Check the weights are sane.
    pub fn check(&self) -> Result<(), String> {
        if self.rough.iter().any(|&f| !(1..=100).contains(&f)) {
            return Err("metric.rough factors must be 1..=100".into());
        }
        if self.safety > 1000 || self.turn > 1000 || self.mode_change > 1000 {
            return Err(
                "metric.safety, metric.turn and metric.mode_change must be 0..=1000".into(),
            );
        }
        Ok(())
    }

    /// The robot must remember its last move (turn or contact-change costs are on).
    pub fn needs_memory(&self) -> bool {
        self.turn > 0 || self.mode_change > 0
    }

    /// Passability factor of a placement (its roughest cell).
    pub fn pass_factor(&self, cells: &[u32], g: &Grid) -> u32 {
        cells
            .iter()
            .map(|&c| match g.cells[c as usize].rough {
                0 => 1,
                1 => self.rough[0],
                _ => self.rough[1],
            })
            .max()
            .unwrap_or(1)
    }

    /// Cost of the robot arriving at a placement.
    pub fn move_cost(&self, mass: u32, cells: &[u32], g: &Grid) -> u32 {
        mass * self.pass_factor(cells, g)
    }

    /// Cost of pushing a movable into a placement.
    pub fn push_cost(&self, mass: u32, cells: &[u32], g: &Grid) -> u32 {
        let mut c = mass * self.pass_factor(cells, g);
        if self.safety > 0 && near_obstacle(cells, g) {
            c += self.safety;
        }
        c
    }

    /// Extra cost from the robot's memory: turns and contact-mode changes. `prev` is the last
    /// move's (direction, was a translational push), `None` when the robot keeps no memory.
    #[inline]
    pub fn memory_cost(&self, prev: Option<(Dir, bool)>, dir: Dir, kind: StepKind) -> u32 {
        let Some((pd, ppush)) = prev else { return 0 };
        let q = (dir as i32 - pd as i32).rem_euclid(4);
        let turns = if q == 3 { 1 } else { q as u32 };
        let change = match kind {
            StepKind::Transit => false,
            StepKind::Translate => !(ppush && pd == dir),
            StepKind::Rotate => true,
        };
        self.turn * turns + if change { self.mode_change } else { 0 }
    }
}

/// Does any cell of the placement touch an obstacle or the border (8-neighbourhood)?
pub fn near_obstacle(cells: &[u32], g: &Grid) -> bool {
    cells.iter().any(|&c| {
        let (x, y) = (c as i32 % g.w, c as i32 / g.w);
        (-1..=1).any(|dy| (-1..=1).any(|dx| !g.free(x + dx, y + dy)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turn_cost_counts_quarter_turns_and_mode_changes() {
        let m = Metric {
            turn: 3,
            mode_change: 10,
            ..Metric::default()
        };
        assert_eq!(
            m.memory_cost(Some((Dir::E, false)), Dir::E, StepKind::Transit),
            0
        );
        assert_eq!(
            m.memory_cost(Some((Dir::E, false)), Dir::N, StepKind::Transit),
            3
        );
        assert_eq!(
            m.memory_cost(Some((Dir::E, false)), Dir::W, StepKind::Transit),
            6
        );
        assert_eq!(
            m.memory_cost(Some((Dir::E, true)), Dir::E, StepKind::Translate),
            0
        );
        assert_eq!(
            m.memory_cost(Some((Dir::E, false)), Dir::E, StepKind::Translate),
            10
        );
        assert_eq!(
            m.memory_cost(Some((Dir::S, true)), Dir::E, StepKind::Translate),
            13
        );
        assert_eq!(m.memory_cost(None, Dir::E, StepKind::Rotate), 0);
    }

    #[test]
    fn passability_takes_the_roughest_cell() {
        let mut g = Grid::new(3, 1);
        g.at_mut(1, 0).rough = 1;
        g.at_mut(2, 0).rough = 2;
        let m = Metric {
            rough: [3, 7],
            ..Metric::default()
        };
        assert_eq!(m.move_cost(2, &[0], &g), 2);
        assert_eq!(m.move_cost(2, &[0, 1], &g), 6);
        assert_eq!(m.move_cost(2, &[1, 2], &g), 14);
    }
}
