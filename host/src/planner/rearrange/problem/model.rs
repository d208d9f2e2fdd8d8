//! Compiling a [`Problem`] into a [`Model`]: the checks on the description, the bodies'
//! domains, overlap and contact tables, costs under the metric (§IV-C), and the mixed-radix
//! packing of composite configurations (§II-A).

use super::super::grid::rot;
use super::super::metric::Metric;
use super::spec::{ContactMode, Problem, ProblemError, invalid};
use super::tables::{
    Bits, ContactTable, Domain, FastDiv, MAX_MOVABLES, NONE, RotInstance, build_domain,
    overlap_table, touch_table,
};

/// A problem compiled to dense tables; the packed composite configuration space.
#[derive(Debug, Clone)]
pub struct Model {
    /// The problem it was built from.
    pub problem: Problem,
    /// Robot memory states per robot placement: 1, or 8 (last direction × last move was a
    /// translational push) when the metric charges turns or contact-mode changes.
    pub n_aux: u32,
    /// The robot's placements.
    pub robot: Domain,
    /// Each movable's placements.
    pub movables: Vec<Domain>,
    /// `radix[0] = n_aux`, `radix[1]` = robot placements, then each movable's.
    pub radix: Vec<u32>,
    /// Number of packed configurations.
    pub n_states: u64,
    /// Index stride of each digit: `stride[k] = radix[0] × … × radix[k−1]`.
    pub stride: Vec<u64>,
    /// Robot/movable overlap: `rm[i].get(m * n_robot + r)` (movable-major, so the robot's
    /// neighbouring placements share cache lines).
    pub rm: Vec<Bits>,
    /// Robot/movable contact (a robot cell and a movable cell side by side): `touch[i]`, same
    /// layout as `rm`. No push can have led to a configuration where the robot touches nothing.
    pub touch: Vec<Bits>,
    /// Some movable has rotational pushes.
    pub any_rotation: bool,
    /// Movable/movable overlap for i < j: `mm[i * MAX + j].get(mi * n_j + mj)`.
    pub mm: Vec<Option<Bits>>,
    /// Cost of the robot arriving at a placement (mass × passability).
    pub robot_cost: Vec<u32>,
    /// Cost of pushing movable i into a placement (mass × passability + safety).
    pub push_cost: Vec<Vec<u32>>,
    /// May movable i be left at this placement?
    pub leave_ok: Vec<Vec<bool>>,
    /// Translational contact tables.
    pub contact: Vec<ContactTable>,
    /// Rotational pushes by pre-push orientation: `rot_pre[i][o]`.
    pub rot_pre: Vec<[Vec<RotInstance>; 4]>,
    /// Rotational pushes by post-push orientation: `rot_post[i][o]`.
    pub rot_post: Vec<[Vec<RotInstance>; 4]>,
    /// Largest cost of one move.
    pub max_edge: u32,
    /// Division by each radix without a divide instruction (decoding is in the hot loop).
    pub div: Vec<FastDiv>,
}

impl Model {
    /// Compile a problem; checks sizes, shapes, start and goals.
    pub fn new(problem: &Problem) -> Result<Model, ProblemError> {
        let p = problem;
        let g = &p.grid;
        if g.w < 1 || g.h < 1 || g.w > 256 || g.h > 256 || g.cells.len() != (g.w * g.h) as usize {
            return invalid(format!("grid {}×{}: each side must be 1..=256", g.w, g.h));
        }
        if p.movables.len() > MAX_MOVABLES {
            return invalid(format!(
                "{} movables: at most {MAX_MOVABLES}",
                p.movables.len()
            ));
        }
        if p.robot.size < 1 || p.robot.size > 8 {
            return invalid(format!("robot size {}: must be 1..=8", p.robot.size));
        }
        if p.robot.mass < 1 || p.robot.mass > 1000 {
            return invalid("robot mass must be 1..=1000");
        }
        for m in &p.movables {
            if m.cells.is_empty() || m.cells.len() > 64 {
                return invalid(format!("movable `{}`: needs 1..=64 cells", m.name));
            }
            if m.cells.iter().any(|&(x, y)| x.abs() > 16 || y.abs() > 16) {
                return invalid(format!(
                    "movable `{}`: cells must lie within 16 of the anchor",
                    m.name
                ));
            }
            if m.mass > 1000 {
                return invalid(format!("movable `{}`: mass must be 0..=1000", m.name));
            }
            for mode in &m.modes {
                let (pt, d) = match mode {
                    ContactMode::Translate { point, dir } => (*point, *dir),
                    ContactMode::Rotate {
                        point,
                        dir,
                        turn,
                        shift,
                    } => {
                        if *turn != 1 && *turn != -1 {
                            return invalid(format!(
                                "movable `{}`: rotation turn must be +1 or -1",
                                m.name
                            ));
                        }
                        if shift.0.abs() > 16 || shift.1.abs() > 16 {
                            return invalid(format!(
                                "movable `{}`: rotation shift too large",
                                m.name
                            ));
                        }
                        if !m.rotates {
                            return invalid(format!(
                                "movable `{}`: has a rotational contact mode but does not rotate",
                                m.name
                            ));
                        }
                        (*point, *dir)
                    }
                };
                let (dx, dy) = d.delta();
                if m.cells.contains(&pt) || !m.cells.contains(&(pt.0 + dx, pt.1 + dy)) {
                    return invalid(format!(
                        "movable `{}`: contact point ({}, {}) pushing {} must be outside the shape, next to it",
                        m.name,
                        pt.0,
                        pt.1,
                        d.letter()
                    ));
                }
            }
        }
        if p.start.movables.len() != p.movables.len() || p.goal_movables.len() != p.movables.len() {
            return invalid("start and goal must place every movable");
        }
        let metric = &p.metric;
        metric.check().map_err(ProblemError::Invalid)?;
        let n_aux = if metric.needs_memory() { 8 } else { 1 };
        let ncells = (g.w * g.h) as usize;
        let robot = build_domain(g, &p.robot.cells(), 1);
        let movables: Vec<Domain> = p
            .movables
            .iter()
            .map(|m| build_domain(g, &m.cells, if m.rotates { 4 } else { 1 }))
            .collect();
        let mut radix = vec![n_aux, robot.len()];
        radix.extend(movables.iter().map(|d| d.len()));
        let n_states = radix
            .iter()
            .try_fold(1u64, |n, &r| n.checked_mul(r as u64))
            .filter(|&n| usize::try_from(n).is_ok());
        let Some(n_states) = n_states else {
            return invalid(
                "more composite configurations than this machine can address; use --mode practical",
            );
        };
        if radix.contains(&0) {
            return invalid("some body has no free placement on this grid");
        }
        let rm = movables
            .iter()
            .map(|d| overlap_table(d, &robot, ncells))
            .collect();
        let touch = movables.iter().map(|d| touch_table(d, &robot, g)).collect();
        let mut mm = vec![None; MAX_MOVABLES * MAX_MOVABLES];
        for i in 0..movables.len() {
            for j in i + 1..movables.len() {
                mm[i * MAX_MOVABLES + j] = Some(overlap_table(&movables[i], &movables[j], ncells));
            }
        }
        let robot_cost: Vec<u32> = robot
            .cells
            .iter()
            .map(|cs| metric.move_cost(p.robot.mass, cs, g))
            .collect();
        let push_cost: Vec<Vec<u32>> = movables
            .iter()
            .zip(&p.movables)
            .map(|(d, spec)| {
                d.cells
                    .iter()
                    .map(|cs| metric.push_cost(spec.mass, cs, g))
                    .collect()
            })
            .collect();
        let leave_ok = movables
            .iter()
            .map(|d| {
                d.cells
                    .iter()
                    .map(|cs| cs.iter().all(|&c| !g.cells[c as usize].no_leave))
                    .collect()
            })
            .collect();
        let mut contact = Vec::new();
        let mut rot_pre = Vec::new();
        let mut rot_post = Vec::new();
        let k = p.robot.size;
        for (i, spec) in p.movables.iter().enumerate() {
            let lo = -(16 + k + 1);
            let side = 2 * (16 + k + 1) + 1;
            let s2 = (side * side) as usize;
            let orients = movables[i].orients;
            let mut ok = vec![false; 16 * s2];
            let mut pre: [Vec<RotInstance>; 4] = Default::default();
            let mut post: [Vec<RotInstance>; 4] = Default::default();
            for o in 0..orients {
                for mode in &spec.modes {
                    match *mode {
                        ContactMode::Translate { point, dir } => {
                            let (pt, d) = (rot(point, o), dir.rotated(o));
                            for a in p.robot.anchors_touching(pt, d) {
                                let (x, y) = (a.0 - lo, a.1 - lo);
                                ok[(o as usize * 4 + d as usize) * s2 + (y * side + x) as usize] =
                                    true;
                            }
                        }
                        ContactMode::Rotate {
                            point,
                            dir,
                            turn,
                            shift,
                        } => {
                            let (pt, d) = (rot(point, o), dir.rotated(o));
                            let post_o = ((o as i32 + turn as i32).rem_euclid(4)) as u8;
                            let sh = rot(shift, o);
                            let mut all: Vec<(i32, i32)> = spec.cells_at(o);
                            all.extend(
                                spec.cells_at(post_o)
                                    .iter()
                                    .map(|&(x, y)| (x + sh.0, y + sh.1)),
                            );
                            let (x0, x1) = (
                                all.iter().map(|c| c.0).min().unwrap_or(0),
                                all.iter().map(|c| c.0).max().unwrap_or(0),
                            );
                            let (y0, y1) = (
                                all.iter().map(|c| c.1).min().unwrap_or(0),
                                all.iter().map(|c| c.1).max().unwrap_or(0),
                            );
                            let sweep: Vec<(i32, i32)> = (y0..=y1)
                                .flat_map(|y| (x0..=x1).map(move |x| (x, y)))
                                .collect();
                            for a in p.robot.anchors_touching(pt, d) {
                                let inst = RotInstance {
                                    pre_o: o,
                                    robot_off: a,
                                    dir: d,
                                    shift: sh,
                                    post_o,
                                    sweep: sweep.clone(),
                                };
                                pre[o as usize].push(inst.clone());
                                post[post_o as usize].push(inst);
                            }
                        }
                    }
                }
            }
            if !p.rules.rotations {
                pre = Default::default();
                post = Default::default();
            }
            contact.push(ContactTable { lo, side, ok });
            rot_pre.push(pre);
            rot_post.push(post);
        }
        let any_rotation = rot_post.iter().any(|r| r.iter().any(|v| !v.is_empty()));
        let max_edge = metric.max_edge(p, &robot_cost, &push_cost);
        if max_edge > 4000 {
            return invalid(format!(
                "one move may cost {max_edge}: the metric weights are too large (limit 4000)"
            ));
        }
        let mut model = Model {
            problem: p.clone(),
            n_aux,
            robot,
            movables,
            stride: radix
                .iter()
                .scan(1u64, |acc, &r| {
                    let s = *acc;
                    *acc = acc.wrapping_mul(r as u64);
                    Some(s)
                })
                .collect(),
            radix,
            n_states,
            rm,
            touch,
            any_rotation,
            mm,
            robot_cost,
            push_cost,
            leave_ok,
            contact,
            rot_pre,
            rot_post,
            max_edge,
            div: Vec::new(),
        };
        model.div = model.radix.iter().map(|&r| FastDiv::new(r)).collect();
        if model.pack(&p.start).is_none() {
            return invalid(
                "the start configuration overlaps an obstacle, the grid border or another body",
            );
        }
        for (i, g) in p.goal_movables.iter().enumerate() {
            if let Some(pl) = g
                && model.movables[i].lookup(model.w(), model.h(), *pl) == NONE
            {
                return invalid(format!(
                    "movable `{}`: its goal overlaps an obstacle",
                    p.movables[i].name
                ));
            }
        }
        Ok(model)
    }
}

impl Metric {
    /// An upper bound on one move's cost (sizes the bucket queue).
    pub fn max_edge(&self, p: &Problem, robot_cost: &[u32], push_cost: &[Vec<u32>]) -> u32 {
        let r = robot_cost.iter().copied().max().unwrap_or(1);
        let mut pushes: Vec<u32> = push_cost
            .iter()
            .map(|v| v.iter().copied().max().unwrap_or(0))
            .collect();
        pushes.sort_unstable_by(|a, b| b.cmp(a));
        let n = if p.rules.max_pushed == 0 {
            pushes.len()
        } else {
            p.rules.max_pushed as usize
        };
        let m: u32 = pushes.iter().take(n.max(1)).sum();
        r + m + 2 * self.turn + self.mode_change
    }
}
