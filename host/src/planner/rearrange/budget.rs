//! Sizing the exact cost map before it is built (Ben-Shahar & Rivlin §IV-E, "the complexity of
//! the algorithm"): the packed space holds (robot memory) × (robot placements) × Π (movable
//! placements) configurations, two bytes of cost each plus the wave front, so the memory the
//! map needs is known from the bodies' free placements alone — also for problems the exact
//! planner cannot take, which are then left to the practical mode.

use super::costmap::map_bytes_estimate;
use super::problem::{MAX_MOVABLES, Model, Problem};

/// What the exact cost map of a problem would take.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ExactBudget {
    /// Packed configurations (saturates at `u64::MAX`). Indices are `u32` below 2³², `u64`
    /// above: any map that fits in memory can be built.
    pub configurations: u64,
    /// The same as a float (does not saturate).
    pub configurations_f64: f64,
    /// Bytes the map and its wave front need at their peak (estimate; saturates).
    pub bytes: u64,
    /// Bytes the system has available (`MemAvailable`), if it tells.
    pub available: Option<u64>,
    /// Movables in the problem.
    pub movables: usize,
}

/// Why the exact planner cannot take a problem.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TooLarge {
    /// More movables than the packed state holds.
    #[error(
        "{movables} movables: the exact planner takes at most {MAX_MOVABLES}; use --mode practical"
    )]
    Movables {
        /// How many.
        movables: usize,
    },
    /// More configurations than this machine can number (a 64-bit index, its address space).
    #[error(
        "{configurations} configurations or more: more than this machine can number, the exact cost map would need {need}; use --mode practical"
    )]
    Index {
        /// How many.
        configurations: u64,
        /// The memory, human-readable.
        need: String,
    },
    /// Not enough memory.
    #[error(
        "the exact cost map of {configurations} configurations needs {need}, {avail} are available; use --mode practical"
    )]
    Memory {
        /// How many.
        configurations: u64,
        /// The memory needed, human-readable.
        need: String,
        /// The memory available, human-readable.
        avail: String,
    },
}

impl ExactBudget {
    /// Size the exact map of `p` (`max_edge` from its model when it has one, else a bound).
    pub fn of(p: &Problem) -> ExactBudget {
        let configurations = Model::configurations(p);
        let configurations_f64 = Model::configurations_f64(p);
        let max_edge = Model::new(p).map(|m| m.max_edge).unwrap_or(u32::MAX - 1);
        ExactBudget {
            configurations,
            configurations_f64,
            bytes: map_bytes_estimate(configurations, max_edge),
            available: available_bytes(),
            movables: p.movables.len(),
        }
    }

    /// Can the exact planner build this map here? `Err` says why not.
    pub fn check(&self) -> Result<(), TooLarge> {
        if self.movables > MAX_MOVABLES {
            return Err(TooLarge::Movables {
                movables: self.movables,
            });
        }
        if self.configurations == u64::MAX || usize::try_from(self.configurations).is_err() {
            return Err(TooLarge::Index {
                configurations: self.configurations,
                need: human(self.bytes),
            });
        }
        if let Some(avail) = self.available
            && self.bytes > avail / 10 * 9
        {
            return Err(TooLarge::Memory {
                configurations: self.configurations,
                need: human(self.bytes),
                avail: human(avail),
            });
        }
        Ok(())
    }
}

/// Bytes as MiB or GiB.
pub fn human(bytes: u64) -> String {
    if bytes >= 1 << 40 {
        format!("{:.2e} GiB", bytes as f64 / (1u64 << 30) as f64)
    } else if bytes >= 1 << 30 {
        format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
    } else {
        format!("{:.0} MiB", (bytes as f64 / (1u64 << 20) as f64).ceil())
    }
}

/// `MemAvailable` from `/proc/meminfo`, if the system tells.
pub fn available_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

impl Model {
    /// Packed configurations of a problem's exact map, from its bodies' free placements
    /// (saturating; no tables are built).
    pub fn configurations(p: &Problem) -> u64 {
        Model::placements(p)
            .into_iter()
            .fold(1u64, |n, k| n.saturating_mul(k))
    }

    /// The same as a float, for sizes past `u64`.
    pub fn configurations_f64(p: &Problem) -> f64 {
        Model::placements(p).into_iter().map(|k| k as f64).product()
    }

    /// The digits of the packed index: robot memory, robot placements, each movable's.
    fn placements(p: &Problem) -> Vec<u64> {
        let g = &p.grid;
        let count = |cells: &[(i32, i32)], orients: u8| -> u64 {
            let mut n = 0u64;
            for o in 0..orients {
                let sh: Vec<(i32, i32)> = cells.iter().map(|&c| super::grid::rot(c, o)).collect();
                for y in 0..g.h {
                    for x in 0..g.w {
                        n += sh.iter().all(|&(cx, cy)| g.free(x + cx, y + cy)) as u64;
                    }
                }
            }
            n
        };
        let aux = if p.metric.needs_memory() { 8 } else { 1 };
        let mut digits = vec![aux, count(&p.robot.cells(), 1)];
        for m in &p.movables {
            digits.push(count(&m.cells, if m.rotates { 4 } else { 1 }));
        }
        digits
    }
}
