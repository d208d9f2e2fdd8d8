//! Practical plans replayed step by step against the exact planner's metric (Ben-Shahar &
//! Rivlin §IV-C, the costs D(Q̂, Q) of the moves of §IV-B): on random instances of 2–4 movables
//! with every term of the metric switched on at random (mass, passability, safety, turns,
//! contact-mode changes) and random admissibility rules, each move of a practical plan must be
//! an admissible move of the full problem whose cost there equals the plan's step cost, and the
//! plan's cost must be their sum. Where the exact map is small enough to build, a practical
//! "no plan" on a solvable instance must say why the search gave up, and that reason is checked.

use std::time::Instant;

use pushbot::planner::rearrange::admissibility::MoveKind;
use pushbot::planner::rearrange::practical::{
    Action, GaveUp, Options, PracticalError, PracticalPlan, plan_practical,
};
use pushbot::planner::rearrange::problem::face_modes;
use pushbot::planner::rearrange::{
    Config, ContactMode, Dir, Grid, Metric, Model, MovableSpec, Placement, Problem, RobotSpec,
    Rules, cost_map,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Cells of `spec` at `pl` on the grid.
fn cells(spec: &MovableSpec, pl: Placement) -> Vec<(i32, i32)> {
    spec.cells_at(pl.o)
        .into_iter()
        .map(|(x, y)| (pl.x + x, pl.y + y))
        .collect()
}

/// A random placement of `spec` on free cells not in `taken`, or `None` after some tries.
fn place(
    rng: &mut ChaCha8Rng,
    g: &Grid,
    spec: &MovableSpec,
    taken: &[(i32, i32)],
) -> Option<Placement> {
    for _ in 0..50 {
        let pl = Placement {
            x: rng.random_range(0..g.w),
            y: rng.random_range(0..g.h),
            o: if spec.rotates {
                rng.random_range(0..4)
            } else {
                0
            },
        };
        let cs = cells(spec, pl);
        if cs
            .iter()
            .all(|&(x, y)| g.free(x, y) && !taken.contains(&(x, y)))
        {
            return Some(pl);
        }
    }
    None
}

/// A random instance with `n` movables: a room of 5–7 cells a side with obstacles, rough and
/// no-leave cells; one-cell boxes and dominoes (some turning, with rotational contact modes);
/// random masses, metric weights and admissibility rules.
fn random_instance(rng: &mut ChaCha8Rng, n: usize) -> Option<Problem> {
    let side = rng.random_range(5..=if n == 4 { 6 } else { 7 });
    let mut grid = Grid::new(side, side);
    for c in grid.cells.iter_mut() {
        c.obstacle = rng.random_bool(0.08);
        if rng.random_bool(0.15) {
            c.rough = rng.random_range(1..=2);
        }
        c.no_leave = rng.random_bool(0.04);
    }
    let robot = RobotSpec {
        size: if n == 2 && rng.random_bool(0.15) {
            2
        } else {
            1
        },
        mass: rng.random_range(1..=2),
    };
    let rules = Rules {
        push_dirs: if rng.random_bool(0.85) {
            0b1111
        } else {
            rng.random_range(1..16)
        },
        max_pushed: [1, 1, 1, 0, 2][rng.random_range(0..5)],
        distance_limit: rng
            .random_bool(0.1)
            .then(|| rng.random_range(4..=side as u32 + 2)),
        strict_contact: rng.random_bool(0.7),
        rotations: rng.random_bool(0.8),
    };
    let memory = rng.random_bool(0.4);
    let metric = Metric {
        rough: [rng.random_range(1..=3), rng.random_range(1..=5)],
        safety: if rng.random_bool(0.6) {
            rng.random_range(1..=3)
        } else {
            0
        },
        turn: if memory { rng.random_range(0..=2) } else { 0 },
        mode_change: if memory { rng.random_range(1..=3) } else { 0 },
    };
    let mut movables = Vec::new();
    for i in 0..n {
        let domino = rng.random_bool(0.25);
        let shape = if domino {
            vec![(0, 0), (1, 0)]
        } else {
            vec![(0, 0)]
        };
        let mut spec = MovableSpec::with_faces(&format!("m{i}"), shape.clone(), 0);
        spec.mass = rng.random_range(0..=3);
        if domino && rng.random_bool(0.5) {
            spec.rotates = true;
            let faces = face_modes(&shape);
            for _ in 0..rng.random_range(1..=2) {
                if let ContactMode::Translate { point, dir } =
                    faces[rng.random_range(0..faces.len())]
                {
                    spec.modes.push(ContactMode::Rotate {
                        point,
                        dir,
                        turn: if rng.random_bool(0.5) { 1 } else { -1 },
                        shift: (rng.random_range(0..=1), rng.random_range(-1..=0)),
                    });
                }
            }
        }
        movables.push(spec);
    }
    // Start: the movables on free cells, then the robot; goals: free of each other.
    let mut taken = Vec::new();
    let mut starts = Vec::new();
    for spec in &movables {
        let pl = place(rng, &grid, spec, &taken)?;
        taken.extend(cells(spec, pl));
        starts.push(pl);
    }
    let rspec = MovableSpec::with_faces("robot", robot.cells(), 1);
    let rp = place(rng, &grid, &rspec, &taken)?;
    let mut p = Problem {
        name: String::new(),
        grid,
        robot,
        movables,
        rules,
        metric,
        start: Config {
            robot: (rp.x, rp.y),
            heading: Dir::from_index(rng.random_range(0..4)),
            pushing: false,
            movables: starts,
        },
        goal_robot: None,
        goal_movables: vec![None; n],
    };
    // Goals where a random walk of admissible moves of the full problem ends (pushes preferred),
    // so a plan exists.
    let model = Model::new(&p).ok()?;
    let mut cur = model.pack(&p.start)?;
    let mut nb = Vec::new();
    for _ in 0..rng.random_range(20..=150) {
        model.neighbours(cur, &mut nb);
        let pushes: Vec<u64> = nb
            .iter()
            .filter(|s| s.kind != MoveKind::Transit)
            .map(|s| s.to)
            .collect();
        cur = if !pushes.is_empty() && rng.random_bool(0.5) {
            pushes[rng.random_range(0..pushes.len())]
        } else if nb.is_empty() {
            break;
        } else {
            nb[rng.random_range(0..nb.len())].to
        };
    }
    let end = model.unpack(cur);
    if end.movables == p.start.movables {
        return None;
    }
    p.goal_movables = end
        .movables
        .iter()
        .map(|&pl| (!rng.random_bool(0.1)).then_some(pl))
        .collect();
    p.goal_robot = rng.random_bool(0.1).then_some(end.robot);
    Model::new(&p).is_ok().then_some(p)
}

/// One step whose cost differs between the plan and the metric.
#[derive(Debug)]
struct Mismatch {
    step: usize,
    action: Action,
    plan: u32,
    metric: u32,
}

/// Replay `plan` under the full problem's model: every move must be an admissible move there
/// (the same kind, direction and arrival); returns the steps whose cost differs from the
/// metric's, or why the plan is not a legal pushing path.
fn replay(p: &Problem, model: &Model, plan: &PracticalPlan) -> Result<Vec<Mismatch>, String> {
    let mut cur = model
        .pack(&plan.start)
        .ok_or("the plan's start is not the problem's")?;
    let mut out = Vec::new();
    let mut nb = Vec::new();
    for (k, m) in plan.moves.iter().enumerate() {
        model.neighbours(cur, &mut nb);
        let same_kind = |kind: MoveKind| match (m.action, kind) {
            (Action::Transit, MoveKind::Transit) => true,
            (Action::Push(i), MoveKind::Push { pushed }) => pushed == 1 << i,
            (Action::Rotate(i, t), MoveKind::Rotate { movable, turn }) => {
                movable as usize == i && turn == t
            }
            _ => false,
        };
        let arrives = |to: u64| {
            let c = model.unpack(to);
            c.robot == m.config.robot
                && c.movables == m.config.movables
                && (model.n_aux == 1
                    || (c.heading, c.pushing) == (m.config.heading, m.config.pushing))
        };
        let step = nb
            .iter()
            .find(|s| s.dir == m.dir && same_kind(s.kind) && arrives(s.to))
            .ok_or_else(|| {
                format!(
                    "step {k} ({:?} {:?} to {:?}) is not an admissible move of the problem \
                     under {:?}",
                    m.action, m.dir, m.config, p.rules
                )
            })?;
        if step.cost != m.cost {
            out.push(Mismatch {
                step: k,
                action: m.action,
                plan: m.cost,
                metric: step.cost,
            });
        }
        cur = step.to;
    }
    let end = model.unpack(cur);
    for (i, g) in p.goal_movables.iter().enumerate() {
        if g.is_some_and(|g| g != end.movables[i]) {
            return Err(format!("movable {i} ends off its goal"));
        }
    }
    if p.goal_robot.is_some_and(|g| g != end.robot) {
        return Err("the robot ends off its goal".into());
    }
    let sum: u32 = plan.moves.iter().map(|m| m.cost).sum();
    if plan.cost != sum {
        return Err(format!(
            "plan cost {} but its steps sum to {sum}",
            plan.cost
        ));
    }
    Ok(out)
}

/// The exact map is built (to check that no plan is cheaper than the optimum) up to this many
/// packed configurations.
const EXACT_UP_TO: u64 = 300_000;

/// The exact map that checks a "several at once" reason is built up to this many configurations.
const ONE_AT_A_TIME_UP_TO: u64 = 40_000_000;

#[test]
fn every_practical_step_costs_what_the_metric_charges() {
    let t0 = Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let (mut plans, mut instances, mut steps, mut exact) = (0, 0, 0, 0);
    let mut by_movables = [0usize; 5];
    let mut bad: Vec<String> = Vec::new();
    let (mut mismatched_plans, mut mismatched_steps, mut missed) = (0, 0, 0);
    let (mut budget, mut several, mut several_confirmed) = (0, 0, 0);
    while plans < 500 {
        instances += 1;
        assert!(instances < 5_000, "too few instances were generated");
        let n = 2 + instances % 3;
        let Some(mut p) = random_instance(&mut rng, n) else {
            continue;
        };
        p.name = format!("instance {instances} ({n} movables)");
        let model = Model::new(&p).expect("the generator checks the problem");
        let result = plan_practical(&p, &Options::for_problem(&p));
        match result {
            Ok(plan) => {
                plans += 1;
                by_movables[n] += 1;
                steps += plan.moves.len();
                match replay(&p, &model, &plan) {
                    Err(e) => bad.push(format!("{}: {e}", p.name)),
                    Ok(mm) if !mm.is_empty() => {
                        mismatched_plans += 1;
                        mismatched_steps += mm.len();
                        let steps: Vec<String> = mm
                            .iter()
                            .map(|m| {
                                format!(
                                    "step {} {:?} costs {} in the plan, {} under the metric",
                                    m.step, m.action, m.plan, m.metric
                                )
                            })
                            .collect();
                        bad.push(format!("{}: {} ({:?})", p.name, steps.join("; "), p.metric));
                    }
                    Ok(_) => {}
                }
                if model.n_states <= EXACT_UP_TO {
                    exact += 1;
                    let map = cost_map(&model).expect("small maps do not overflow");
                    let opt = map.get(model.pack(&p.start).expect("start is free"));
                    if opt.is_none_or(|o| plan.cost < o) {
                        bad.push(format!(
                            "{}: cost {} but the optimum is {opt:?}",
                            p.name, plan.cost
                        ));
                    }
                }
            }
            // The goals are where a walk of admissible moves ended: a plan exists, so the
            // search must say why it gave up, and the reason must hold.
            Err(PracticalError::NoPlanFound { expansions, why }) => {
                missed += 1;
                match why {
                    GaveUp::Budget { limit } => {
                        budget += 1;
                        if limit != Options::for_problem(&p).max_expansions || expansions < limit {
                            bad.push(format!(
                                "{}: 'budget spent' after {expansions} nodes of {limit}",
                                p.name
                            ));
                        }
                    }
                    GaveUp::Exhausted {
                        several_at_once, ..
                    } => {
                        several += 1;
                        if !several_at_once || p.rules.max_pushed == 1 {
                            bad.push(format!(
                                "{}: a plan pushing one movable at a time exists, none found: \
                                 {why}",
                                p.name
                            ));
                        } else {
                            match one_at_a_time_impossible(&p) {
                                Some(false) => bad.push(format!(
                                    "{}: blames pushes of several movables at once, but the \
                                     exact planner finds a plan pushing one at a time",
                                    p.name
                                )),
                                Some(true) => several_confirmed += 1,
                                None => {}
                            }
                        }
                    }
                }
            }
            Err(e) => bad.push(format!("{}: a plan exists, but: {e}", p.name)),
        }
    }
    let secs = t0.elapsed().as_secs_f64();
    eprintln!(
        "{plans} plans ({} with 2, {} with 3, {} with 4 movables; {steps} steps) from {instances} \
         instances; {mismatched_steps} steps in {mismatched_plans} plans cost other than the \
         metric says; {missed} solvable instances without a plan ({budget} budget spent, \
         {several} needing pushes of several movables at once, {several_confirmed} of them \
         confirmed by the exact planner); {exact} plans checked against the optimum; {secs:.1} s",
        by_movables[2], by_movables[3], by_movables[4]
    );
    assert!(
        bad.is_empty(),
        "{} failures:\n{}",
        bad.len(),
        bad.join("\n")
    );
    assert!(
        by_movables[2..].iter().all(|&c| c >= 100),
        "{by_movables:?}"
    );
}

/// Has the problem no plan when one move may push only one movable? `None` when its exact map
/// has more than [`ONE_AT_A_TIME_UP_TO`] configurations.
fn one_at_a_time_impossible(p: &Problem) -> Option<bool> {
    let mut one = p.clone();
    one.rules.max_pushed = 1;
    let model = Model::new(&one).expect("the same problem");
    (model.n_states <= ONE_AT_A_TIME_UP_TO).then(|| {
        let map = cost_map(&model).expect("small maps do not overflow");
        map.get(model.pack(&one.start).expect("start is free"))
            .is_none()
    })
}
