//! Property test of the rearrangement planner (Ben-Shahar & Rivlin §IV-D, optimality and
//! completeness): random small problems, checked against an independent, naive model of the
//! same moves that works on sets of cells.
//!
//! For every configuration the map's cost must equal the optimum over the naive forward move
//! graph; for sampled starts a forward Dijkstra search must agree, and the restored plan must be
//! a legal pushing path (each step a naive forward move) of exactly that cost.

use std::collections::{BinaryHeap, HashMap, HashSet};

use pushbot::planner::rearrange::problem::{Cell, rot};
use pushbot::planner::rearrange::{
    Config, ContactMode, Dir, Grid, Metric, Model, MovableSpec, Placement, Problem, RobotSpec,
    Rules, cost_map, restore,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

type Pos = (i32, i32);

/// A naive configuration: robot anchor, memory (dir, pushing) or none, movables.
#[derive(Clone, PartialEq, Eq, Hash, Debug)]
struct N {
    robot: Pos,
    mem: Option<(u8, bool)>,
    m: Vec<Placement>,
}

struct Naive<'a> {
    p: &'a Problem,
}

impl Naive<'_> {
    fn free(&self, c: Pos) -> bool {
        let g = &self.p.grid;
        c.0 >= 0
            && c.1 >= 0
            && c.0 < g.w
            && c.1 < g.h
            && !g.cells[(c.1 * g.w + c.0) as usize].obstacle
    }
    fn cell(&self, c: Pos) -> Cell {
        self.p.grid.cells[(c.1 * self.p.grid.w + c.0) as usize]
    }
    fn robot_cells(&self, a: Pos) -> HashSet<Pos> {
        let k = self.p.robot.size;
        (0..k)
            .flat_map(|y| (0..k).map(move |x| (a.0 + x, a.1 + y)))
            .collect()
    }
    fn mov_cells(&self, i: usize, pl: Placement) -> HashSet<Pos> {
        self.p.movables[i]
            .cells
            .iter()
            .map(|&c| rot(c, pl.o))
            .map(|(x, y)| (x + pl.x, y + pl.y))
            .collect()
    }
    fn valid(&self, s: &N) -> bool {
        let mut seen = HashSet::new();
        let mut all: Vec<Pos> = self.robot_cells(s.robot).into_iter().collect();
        for (i, &pl) in s.m.iter().enumerate() {
            if pl.o != 0 && !self.p.movables[i].rotates {
                return false;
            }
            all.extend(self.mov_cells(i, pl));
        }
        all.into_iter().all(|c| self.free(c) && seen.insert(c))
    }
    fn pass(&self, cells: &HashSet<Pos>) -> u32 {
        let f = self.p.metric.rough;
        cells
            .iter()
            .map(|&c| [1, f[0], f[1]][self.cell(c).rough.min(2) as usize])
            .max()
            .unwrap_or(1)
    }
    fn near(&self, cells: &HashSet<Pos>) -> bool {
        cells
            .iter()
            .any(|&(x, y)| (-1..=1).any(|dy| (-1..=1).any(|dx| !self.free((x + dx, y + dy)))))
    }
    fn push_cost(&self, i: usize, cells: &HashSet<Pos>) -> u32 {
        let m = &self.p.metric;
        self.p.movables[i].mass * self.pass(cells)
            + if m.safety > 0 && self.near(cells) {
                m.safety
            } else {
                0
            }
    }
    fn mem_cost(&self, prev: Option<(u8, bool)>, d: u8, kind: u8) -> u32 {
        // kind: 0 transit, 1 translate, 2 rotate
        let Some((pd, pp)) = prev else { return 0 };
        let a = (d + 4 - pd) % 4;
        let turns = a.min(4 - a) as u32;
        let change = match kind {
            0 => false,
            1 => !(pp && pd == d),
            _ => true,
        };
        self.p.metric.turn * turns + if change { self.p.metric.mode_change } else { 0 }
    }
    fn arrival_ok(&self, robot: Pos, m: &[Placement], pushed: &HashSet<usize>) -> bool {
        m.iter().enumerate().all(|(j, &pl)| {
            pushed.contains(&j)
                || (self
                    .mov_cells(j, pl)
                    .iter()
                    .all(|&c| !self.cell(c).no_leave)
                    && self.p.rules.distance_limit.is_none_or(|l| {
                        ((robot.0 - pl.x).abs() + (robot.1 - pl.y).abs()) as u32 <= l
                    }))
        })
    }
    /// Leading edge of the robot moving d: its cells whose next cell in d is not the robot's.
    fn leading(&self, robot: Pos, d: Dir) -> HashSet<Pos> {
        let cells = self.robot_cells(robot);
        let (dx, dy) = d.delta();
        cells
            .iter()
            .copied()
            .filter(|&(x, y)| !cells.contains(&(x + dx, y + dy)))
            .collect()
    }
    fn successors(&self, s: &N) -> Vec<(N, u32)> {
        let mut out = Vec::new();
        let memory = s.mem.is_some();
        for d in Dir::ALL {
            let (dx, dy) = d.delta();
            let nr = (s.robot.0 + dx, s.robot.1 + dy);
            let rc = self.robot_cells(nr);
            if !rc.iter().all(|&c| self.free(c)) {
                continue;
            }
            let hit: HashSet<usize> = (0..s.m.len())
                .filter(|&i| !self.mov_cells(i, s.m[i]).is_disjoint(&rc))
                .collect();
            if hit.is_empty() {
                if self.arrival_ok(nr, &s.m, &HashSet::new()) {
                    let c = self.p.robot.mass * self.pass(&rc) + self.mem_cost(s.mem, d as u8, 0);
                    out.push((
                        N {
                            robot: nr,
                            mem: memory.then_some((d as u8, false)),
                            m: s.m.clone(),
                        },
                        c,
                    ));
                }
            } else if self.p.rules.push_dirs & (1 << d as u8) != 0 {
                let lead = self.leading(s.robot, d);
                let contact_ok = !self.p.rules.strict_contact
                    || hit.iter().all(|&i| {
                        let pl = s.m[i];
                        self.p.movables[i].modes.iter().any(|mode| match *mode {
                            ContactMode::Translate { point, dir } => {
                                let (px, py) = rot(point, pl.o);
                                dir.rotated(pl.o) == d && lead.contains(&(pl.x + px, pl.y + py))
                            }
                            _ => false,
                        })
                    });
                if !contact_ok {
                    continue;
                }
                let mut set = hit.clone();
                let mut blocked = false;
                loop {
                    let moved: HashSet<Pos> = set
                        .iter()
                        .flat_map(|&i| {
                            self.mov_cells(
                                i,
                                Placement {
                                    x: s.m[i].x + dx,
                                    y: s.m[i].y + dy,
                                    o: s.m[i].o,
                                },
                            )
                        })
                        .collect();
                    if !moved.iter().all(|&c| self.free(c)) {
                        blocked = true;
                        break;
                    }
                    let more: Vec<usize> = (0..s.m.len())
                        .filter(|j| {
                            !set.contains(j) && !self.mov_cells(*j, s.m[*j]).is_disjoint(&moved)
                        })
                        .collect();
                    if more.is_empty() {
                        break;
                    }
                    set.extend(more);
                }
                let limit = self.p.rules.max_pushed as usize;
                if blocked || (limit != 0 && set.len() > limit) {
                    continue;
                }
                let mut m2 = s.m.clone();
                let mut c = self.p.robot.mass * self.pass(&rc) + self.mem_cost(s.mem, d as u8, 1);
                for &i in &set {
                    m2[i] = Placement {
                        x: s.m[i].x + dx,
                        y: s.m[i].y + dy,
                        o: s.m[i].o,
                    };
                    c += self.push_cost(i, &self.mov_cells(i, m2[i]));
                }
                if self.arrival_ok(nr, &m2, &set) {
                    out.push((
                        N {
                            robot: nr,
                            mem: memory.then_some((d as u8, true)),
                            m: m2,
                        },
                        c,
                    ));
                }
            }
        }
        if !self.p.rules.rotations {
            return out;
        }
        for (i, spec) in self.p.movables.iter().enumerate() {
            if !spec.rotates {
                continue;
            }
            let pl = s.m[i];
            for mode in &spec.modes {
                let ContactMode::Rotate {
                    point,
                    dir,
                    turn,
                    shift,
                } = *mode
                else {
                    continue;
                };
                let d = dir.rotated(pl.o);
                let (px, py) = rot(point, pl.o);
                if !self.leading(s.robot, d).contains(&(pl.x + px, pl.y + py)) {
                    continue;
                }
                let (dx, dy) = d.delta();
                let nr = (s.robot.0 + dx, s.robot.1 + dy);
                let rc = self.robot_cells(nr);
                let (sx, sy) = rot(shift, pl.o);
                let np = Placement {
                    x: pl.x + sx,
                    y: pl.y + sy,
                    o: ((pl.o as i8 + turn).rem_euclid(4)) as u8,
                };
                let old = self.mov_cells(i, pl);
                let new = self.mov_cells(i, np);
                let others: HashSet<Pos> = (0..s.m.len())
                    .filter(|&j| j != i)
                    .flat_map(|j| self.mov_cells(j, s.m[j]))
                    .collect();
                let xs = old.iter().chain(&new).map(|c| c.0);
                let ys = old.iter().chain(&new).map(|c| c.1);
                let (x0, x1) = (xs.clone().min().unwrap(), xs.max().unwrap());
                let (y0, y1) = (ys.clone().min().unwrap(), ys.max().unwrap());
                let sweep_ok = (y0..=y1)
                    .all(|y| (x0..=x1).all(|x| self.free((x, y)) && !others.contains(&(x, y))));
                if !sweep_ok
                    || !rc
                        .iter()
                        .all(|&c| self.free(c) && !others.contains(&c) && !new.contains(&c))
                    || !new.iter().all(|&c| self.free(c) && !others.contains(&c))
                {
                    continue;
                }
                let mut m2 = s.m.clone();
                m2[i] = np;
                if !self.arrival_ok(nr, &m2, &HashSet::from([i])) {
                    continue;
                }
                let c = self.p.robot.mass * self.pass(&rc)
                    + self.push_cost(i, &new)
                    + self.mem_cost(s.mem, d as u8, 2);
                out.push((
                    N {
                        robot: nr,
                        mem: memory.then_some((d as u8, false)),
                        m: m2,
                    },
                    c,
                ));
            }
        }
        out
    }
    fn is_goal(&self, s: &N) -> bool {
        self.p.goal_robot.is_none_or(|g| g == s.robot)
            && s.m
                .iter()
                .zip(&self.p.goal_movables)
                .all(|(pl, g)| g.is_none_or(|g| g == *pl))
    }
    fn all_states(&self) -> Vec<N> {
        let g = &self.p.grid;
        let memory = self.p.metric.turn > 0 || self.p.metric.mode_change > 0;
        let mems: Vec<Option<(u8, bool)>> = if memory {
            (0..8).map(|a| Some((a / 2, a % 2 == 1))).collect()
        } else {
            vec![None]
        };
        let mut bodies: Vec<Vec<Placement>> = Vec::new();
        for spec in &self.p.movables {
            let mut v = Vec::new();
            for o in 0..if spec.rotates { 4 } else { 1 } {
                for y in 0..g.h {
                    for x in 0..g.w {
                        v.push(Placement { x, y, o });
                    }
                }
            }
            bodies.push(v);
        }
        let mut out = Vec::new();
        let mut combos: Vec<Vec<Placement>> = vec![vec![]];
        for b in &bodies {
            combos = combos
                .iter()
                .flat_map(|c| b.iter().map(move |&p| [c.clone(), vec![p]].concat()))
                .collect();
        }
        for m in combos {
            for y in 0..g.h {
                for x in 0..g.w {
                    for &mem in &mems {
                        let s = N {
                            robot: (x, y),
                            mem,
                            m: m.clone(),
                        };
                        if self.valid(&s) {
                            out.push(s);
                        }
                    }
                }
            }
        }
        out
    }
}

fn to_config(s: &N) -> Config {
    let (heading, pushing) = s
        .mem
        .map(|(d, p)| (Dir::from_index(d as usize), p))
        .unwrap_or((Dir::E, false));
    Config {
        robot: s.robot,
        heading,
        pushing,
        movables: s.m.clone(),
    }
}

fn random_problem(rng: &mut ChaCha8Rng) -> Option<Problem> {
    let (w, h) = (rng.random_range(3..=5), rng.random_range(3..=5));
    let mut grid = Grid::new(w, h);
    for c in grid.cells.iter_mut() {
        c.obstacle = rng.random_bool(0.12);
        if rng.random_bool(0.2) {
            c.rough = rng.random_range(1..=2);
        }
        c.no_leave = rng.random_bool(0.08);
    }
    let robot = RobotSpec {
        size: if rng.random_bool(0.2) { 2 } else { 1 },
        mass: rng.random_range(1..=2),
    };
    let nm = rng.random_range(1..=2);
    let shapes: [Vec<(i32, i32)>; 3] = [
        vec![(0, 0)],
        vec![(0, 0), (1, 0)],
        vec![(0, 0), (1, 0), (0, 1)],
    ];
    let mut movables = Vec::new();
    for i in 0..nm {
        let cells = shapes[[0, 0, 0, 1, 1, 2][rng.random_range(0..6)]].clone();
        let mut spec =
            MovableSpec::with_faces(&format!("m{i}"), cells.clone(), rng.random_range(0..=3));
        if rng.random_bool(0.4) {
            spec.modes.retain(|_| rng.random_bool(0.5));
        }
        if cells.len() > 1 && rng.random_bool(0.5) {
            spec.rotates = true;
            // random rotational modes: a contact point next to the shape, a turn and a shift
            let faces: Vec<ContactMode> = pushbot::planner::rearrange::problem::face_modes(&cells);
            for _ in 0..rng.random_range(1..=3) {
                if let ContactMode::Translate { point, dir } =
                    faces[rng.random_range(0..faces.len())]
                {
                    spec.modes.push(ContactMode::Rotate {
                        point,
                        dir,
                        turn: if rng.random_bool(0.5) { 1 } else { -1 },
                        shift: (rng.random_range(-1..=1), rng.random_range(-1..=1)),
                    });
                }
            }
        }
        movables.push(spec);
    }
    let rules = Rules {
        push_dirs: if rng.random_bool(0.7) {
            0b1111
        } else {
            rng.random_range(1..16)
        },
        max_pushed: rng.random_range(0..=2),
        distance_limit: if rng.random_bool(0.3) {
            Some(rng.random_range(2..=5))
        } else {
            None
        },
        strict_contact: rng.random_bool(0.7),
        rotations: rng.random_bool(0.8),
    };
    let memory = rng.random_bool(0.3);
    let metric = Metric {
        rough: [rng.random_range(1..=3), rng.random_range(1..=5)],
        safety: rng.random_range(0..=2),
        turn: if memory { rng.random_range(0..=2) } else { 0 },
        mode_change: if memory { rng.random_range(1..=3) } else { 0 },
    };
    // size guard for the naive enumeration
    let orients: i64 = movables
        .iter()
        .map(|m| if m.rotates { 4 } else { 1 })
        .product();
    let n = (w * h) as i64;
    let total = n.pow(1 + nm as u32) * orients * if memory { 8 } else { 1 };
    if total > 120_000 {
        return None;
    }
    let mut p = Problem {
        name: "random".into(),
        grid,
        robot,
        movables,
        rules,
        metric,
        start: Config {
            robot: (0, 0),
            heading: Dir::E,
            pushing: false,
            movables: vec![],
        },
        goal_robot: None,
        goal_movables: vec![],
    };
    // start and goals: random free placements
    let naive = Naive { p: &p };
    let states = naive.all_states();
    if states.is_empty() {
        return None;
    }
    let s = states[rng.random_range(0..states.len())].clone();
    let g = states[rng.random_range(0..states.len())].clone();
    p.start = to_config(&N { mem: None, ..s });
    p.goal_movables =
        g.m.iter()
            .map(|&pl| {
                if rng.random_bool(0.85) {
                    Some(pl)
                } else {
                    None
                }
            })
            .collect();
    if rng.random_bool(0.15) {
        p.goal_robot = Some(g.robot);
    }
    Some(p)
}

#[derive(PartialEq, Eq, PartialOrd, Ord)]
struct Entry(std::cmp::Reverse<u32>, usize);

#[test]
fn cost_map_equals_naive_optimum_and_restored_plans_are_legal() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let mut checked = 0;
    let mut with_finite_start = 0;
    let mut plans_with_pushes = 0;
    while checked < 60 {
        let Some(p) = random_problem(&mut rng) else {
            continue;
        };
        let model = Model::new(&p).expect("random problems are well formed");
        let map = cost_map(&model).expect("small maps do not overflow");
        let naive = Naive { p: &p };
        let states = naive.all_states();
        let index: HashMap<N, usize> = states
            .iter()
            .cloned()
            .enumerate()
            .map(|(i, s)| (s, i))
            .collect();
        let succ: Vec<Vec<(usize, u32)>> = states
            .iter()
            .map(|s| {
                naive
                    .successors(s)
                    .into_iter()
                    .map(|(t, c)| (index[&t], c))
                    .collect()
            })
            .collect();
        // optimum to the goal set over the naive graph (Dijkstra on reversed naive edges)
        let mut pred: Vec<Vec<(usize, u32)>> = vec![Vec::new(); states.len()];
        for (u, es) in succ.iter().enumerate() {
            for &(v, c) in es {
                pred[v].push((u, c));
            }
        }
        let mut dist = vec![u32::MAX; states.len()];
        let mut heap = BinaryHeap::new();
        for (i, s) in states.iter().enumerate() {
            if naive.is_goal(s) {
                dist[i] = 0;
                heap.push(Entry(std::cmp::Reverse(0), i));
            }
        }
        while let Some(Entry(std::cmp::Reverse(d), u)) = heap.pop() {
            if d > dist[u] {
                continue;
            }
            for &(v, c) in &pred[u] {
                if d + c < dist[v] {
                    dist[v] = d + c;
                    heap.push(Entry(std::cmp::Reverse(d + c), v));
                }
            }
        }
        let mut finite = 0u64;
        for (i, s) in states.iter().enumerate() {
            let idx = model
                .pack(&to_config(s))
                .unwrap_or_else(|| panic!("naive state {s:?} not packable"));
            let want = (dist[i] != u32::MAX).then_some(dist[i]);
            assert_eq!(map.get(idx), want, "cost of {s:?} in problem {p:#?}");
            finite += want.is_some() as u64;
        }
        assert_eq!(
            map.stats.states_mapped, finite,
            "map has finite costs outside the naive free space"
        );
        // forward Dijkstra and restoration from sampled starts
        for _ in 0..6 {
            let s0 = rng.random_range(0..states.len());
            let mut fd: HashMap<usize, u32> = HashMap::from([(s0, 0)]);
            let mut heap = BinaryHeap::from([Entry(std::cmp::Reverse(0), s0)]);
            let mut best = None;
            while let Some(Entry(std::cmp::Reverse(d), u)) = heap.pop() {
                if d > fd[&u] {
                    continue;
                }
                if naive.is_goal(&states[u]) {
                    best = Some(d);
                    break;
                }
                for &(v, c) in &succ[u] {
                    if fd.get(&v).is_none_or(|&old| d + c < old) {
                        fd.insert(v, d + c);
                        heap.push(Entry(std::cmp::Reverse(d + c), v));
                    }
                }
            }
            let idx = model.pack(&to_config(&states[s0])).unwrap();
            assert_eq!(map.get(idx), best, "forward search from {:?}", states[s0]);
            match restore(&model, &map, idx) {
                Ok(plan) => {
                    with_finite_start += 1;
                    assert_eq!(Some(plan.cost), best);
                    let mut cur = s0;
                    let mut total = 0;
                    for st in &plan.steps {
                        let next = index.get(&N {
                            robot: st.config.robot,
                            mem: states[cur]
                                .mem
                                .map(|_| (st.config.heading as u8, st.config.pushing)),
                            m: st.config.movables.clone(),
                        });
                        let next = *next.expect("restored configuration is free");
                        let legal = succ[cur]
                            .iter()
                            .any(|&(v, c)| v == next && c == st.step.cost);
                        assert!(
                            legal,
                            "restored step {:?} is not a naive move of that cost",
                            st.step
                        );
                        total += st.step.cost;
                        cur = next;
                    }
                    assert!(naive.is_goal(&states[cur]));
                    assert_eq!(total, plan.cost);
                    plans_with_pushes += (plan.pushes() > 0) as u32;
                }
                Err(e) => assert_eq!(best, None, "restore failed: {e}"),
            }
        }
        checked += 1;
    }
    assert!(
        with_finite_start > 20,
        "too few solvable starts sampled: {with_finite_start}"
    );
    assert!(
        plans_with_pushes > 10,
        "too few plans with pushes: {plans_with_pushes}"
    );
}
