//! One leg of the practical mode: a single movable pushed among the others, which are held
//! where they are as static obstacles 𝓘 (Ben-Shahar & Rivlin §II-A with r = 1). The leg is
//! exact for that sub-problem: a Dijkstra search forward from the current configuration over
//! the packed space of the robot and one movable, with the admissible neighbours N_A(Q) of
//! §IV-B and the costs D of §IV-C — the cost-to-come counterpart of the §IV-A1 cost map, which
//! gives in one search both the cheapest way to the movable's goal and the cheapest places to
//! park it out of the way.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::super::admissibility::MoveKind;
use super::super::problem::{Config, Dir, Model, NONE, Placement, Problem, ProblemError};

/// What one move of a practical plan does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// The robot moves alone.
    Transit,
    /// The robot translates this movable one cell.
    Push(usize),
    /// The robot turns this movable a quarter turn (+1 clockwise, −1 counter-clockwise).
    Rotate(usize, i8),
}

/// One move of a practical plan, with the full configuration it reaches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Move {
    /// The robot's direction of motion.
    pub dir: Dir,
    /// Its cost D under the problem's metric.
    pub cost: u32,
    /// What it does.
    pub action: Action,
    /// The configuration after it (every movable).
    pub config: Config,
}

/// A leg: the moves and where they end.
#[derive(Debug, Clone)]
pub struct Leg {
    /// Its cost.
    pub cost: u32,
    /// Its moves.
    pub moves: Vec<Move>,
    /// The configuration it ends in.
    pub end: Config,
}

/// The legs found for one movable from one configuration.
#[derive(Debug, Default)]
pub struct Legs {
    /// To its goal placement, if there is one and it can be reached.
    pub direct: Option<Leg>,
    /// To the cheapest parking placements (off `avoid`, not where it is).
    pub parkings: Vec<Leg>,
    /// Configurations the search settled.
    pub settled: u64,
}

/// The sub-problem of movable `i` (or of the robot alone, `None`) with every other movable of
/// `cur` turned into obstacles; `bare` drops the others instead.
pub fn sub_problem(p: &Problem, cur: &Config, i: Option<usize>, bare: bool) -> Problem {
    let mut grid = p.grid.clone();
    if !bare {
        for (j, (spec, pl)) in p.movables.iter().zip(&cur.movables).enumerate() {
            if Some(j) == i {
                continue;
            }
            for (cx, cy) in spec.cells_at(pl.o) {
                if grid.get(pl.x + cx, pl.y + cy).is_some() {
                    grid.at_mut(pl.x + cx, pl.y + cy).obstacle = true;
                }
            }
        }
    }
    let only: Vec<usize> = i.into_iter().collect();
    Problem {
        name: p.name.clone(),
        grid,
        robot: p.robot.clone(),
        movables: only.iter().map(|&j| p.movables[j].clone()).collect(),
        rules: p.rules.clone(),
        metric: p.metric.clone(),
        start: Config {
            robot: cur.robot,
            heading: cur.heading,
            pushing: cur.pushing,
            movables: only.iter().map(|&j| cur.movables[j]).collect(),
        },
        goal_robot: None,
        goal_movables: only.iter().map(|_| None).collect(),
    }
}

/// The model of a leg's sub-problem with the costs D of the full problem. The movables held
/// fixed are obstacles of the sub-problem for admissibility (§IV-B) only: the metric (§IV-C)
/// takes its passability and its safety term from the table's own cells, where the safety term
/// counts static obstacles and the border, never a movable — the same costs the exact planner
/// gives the same moves.
pub fn leg_model(p: &Problem, sub: &Problem) -> Result<Model, ProblemError> {
    let mut model = Model::new(sub)?;
    let (metric, table) = (&p.metric, &p.grid);
    model.robot_cost = model
        .robot
        .cells
        .iter()
        .map(|cs| metric.move_cost(p.robot.mass, cs, table))
        .collect();
    model.push_cost = model
        .movables
        .iter()
        .zip(&sub.movables)
        .map(|(d, spec)| {
            d.cells
                .iter()
                .map(|cs| metric.push_cost(spec.mass, cs, table))
                .collect()
        })
        .collect();
    model.max_edge = metric.max_edge(sub, &model.robot_cost, &model.push_cost);
    Ok(model)
}

/// What a leg search looks for.
pub struct Wanted<'a> {
    /// The movable's goal (`None`: no direct leg wanted).
    pub target: Option<Placement>,
    /// The robot's goal, for a robot-alone leg.
    pub robot_target: Option<(i32, i32)>,
    /// Grid cells a parked movable must not cover.
    pub avoid: &'a [bool],
    /// How many parking placements to return.
    pub parkings: usize,
}

/// Search the legs of movable `i` (or of the robot alone) from `cur` among the others.
pub fn legs(
    p: &Problem,
    cur: &Config,
    i: Option<usize>,
    bare: bool,
    want: &Wanted,
) -> Result<Legs, ProblemError> {
    let sub = sub_problem(p, cur, i, bare);
    let model = leg_model(p, &sub)?;
    let start = model
        .pack(&sub.start)
        .ok_or_else(|| ProblemError::Invalid("leg start not free".into()))?;
    // One movable among fixed others: far fewer than 2³² configurations, so `u32` indices.
    let start = u32::try_from(start)
        .map_err(|_| ProblemError::Invalid("a leg's space needs more than u32 indices".into()))?;
    let n = model.n_states as usize;
    let mut dist = vec![u32::MAX; n];
    let mut parent = vec![NONE; n];
    let mut heap = BinaryHeap::new();
    let mut out = Legs::default();
    let mut parked: Vec<u32> = Vec::new();
    let start_place = i.map(|_| sub.start.movables[0]);
    let mut need_direct = want.target.is_some() || want.robot_target.is_some();
    // The others are obstacles here, but a distance limit (§IV-B) still binds the robot to them.
    let others: Vec<(i32, i32)> = (0..cur.movables.len())
        .filter(|&j| Some(j) != i)
        .map(|j| (cur.movables[j].x, cur.movables[j].y))
        .collect();
    let limit = p.rules.distance_limit;
    dist[start as usize] = 0;
    heap.push(Reverse((0u32, start)));
    let mut nb = Vec::new();
    while let Some(Reverse((c, s))) = heap.pop() {
        if c != dist[s as usize] {
            continue;
        }
        out.settled += 1;
        let st = model.decode(s);
        let place = i.map(|_| model.movables[0].place[st.m[0] as usize]);
        let rp = model.robot.place[st.r as usize];
        if need_direct
            && (place.is_some() && place == want.target
                || want.robot_target.is_some_and(|r| r == (rp.x, rp.y)))
        {
            out.direct = Some(leg_to(&model, cur, i, &parent, s, c));
            need_direct = false;
        } else if let Some(pl) = place
            && out.parkings.len() < want.parkings
            && Some(pl) != start_place
            && c > 0
            && !parked.contains(&st.m[0])
            && model.leave_ok[0][st.m[0] as usize]
            && !model.movables[0].cells[st.m[0] as usize]
                .iter()
                .any(|&cell| want.avoid[cell as usize])
        {
            parked.push(st.m[0]);
            out.parkings.push(leg_to(&model, cur, i, &parent, s, c));
        }
        if !need_direct && out.parkings.len() >= want.parkings {
            break;
        }
        model.neighbours(s, &mut nb);
        for step in &nb {
            if let Some(l) = limit {
                let rp = model.robot.place[model.decode(step.to).r as usize];
                let far = |&(x, y): &(i32, i32)| {
                    (rp.x - x).unsigned_abs() + (rp.y - y).unsigned_abs() > l
                };
                if others.iter().any(far) {
                    continue;
                }
            }
            let nc = c + step.cost;
            if nc < dist[step.to as usize] {
                dist[step.to as usize] = nc;
                parent[step.to as usize] = s;
                heap.push(Reverse((nc, step.to)));
            }
        }
    }
    Ok(out)
}

/// The leg ending at `s` (cost `c`), from the parents, in full configurations.
fn leg_to(model: &Model, cur: &Config, i: Option<usize>, parent: &[u32], s: u32, c: u32) -> Leg {
    let mut chain = vec![s];
    while parent[*chain.last().unwrap_or(&s) as usize] != NONE {
        chain.push(parent[chain[chain.len() - 1] as usize]);
    }
    chain.reverse();
    let mut moves = Vec::with_capacity(chain.len());
    let mut nb = Vec::new();
    for pair in chain.windows(2) {
        model.neighbours(pair[0], &mut nb);
        let Some(step) = nb
            .iter()
            .filter(|st| st.to == pair[1])
            .min_by_key(|st| st.cost)
        else {
            continue;
        };
        let j = i.unwrap_or(0);
        let action = match step.kind {
            MoveKind::Transit => Action::Transit,
            MoveKind::Push { .. } => Action::Push(j),
            MoveKind::Rotate { turn, .. } => Action::Rotate(j, turn),
        };
        let sub = model.unpack(step.to as u64);
        let mut config = cur.clone();
        config.robot = sub.robot;
        if model.n_aux > 1 {
            config.heading = sub.heading;
            config.pushing = sub.pushing;
        }
        if let Some(i) = i {
            config.movables[i] = sub.movables[0];
        }
        moves.push(Move {
            dir: step.dir,
            cost: step.cost,
            action,
            config,
        });
    }
    let end = moves
        .last()
        .map_or_else(|| cur.clone(), |m| m.config.clone());
    Leg {
        cost: c,
        moves,
        end,
    }
}
