//! The practical mode against the exact planner (Ben-Shahar & Rivlin §IV-A, whose optimality
//! `rearrange_property.rs` checks against brute force): on random instances small enough for
//! the exact map, every practical plan must be a legal pushing path under the full problem's
//! admissibility and metric, cost no less than the optimum, and almost always close to it.

use pushbot::planner::rearrange::practical::{Action, Options, PracticalError, plan_practical};
use pushbot::planner::rearrange::problem::Cell;
use pushbot::planner::rearrange::{
    Config, Dir, Grid, Metric, Model, MovableSpec, Placement, Problem, RobotSpec, Rules, cost_map,
    replay_cost,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A walled-in room of random size with random obstacles, 2–3 one-cell boxes with random
/// starts and goals (some with a turn cost, so the robot's memory matters).
fn random_problem(rng: &mut ChaCha8Rng, k: usize) -> Option<Problem> {
    let boxes = if k.is_multiple_of(2) { 2 } else { 3 };
    let side = if boxes == 2 {
        rng.random_range(5..=7)
    } else {
        rng.random_range(5..=6)
    };
    let mut grid = Grid::new(side, side);
    for _ in 0..rng.random_range(0..=side as usize / 2) {
        let (x, y) = (rng.random_range(0..side), rng.random_range(0..side));
        *grid.at_mut(x, y) = Cell {
            obstacle: true,
            ..Cell::default()
        };
    }
    for _ in 0..rng.random_range(0..=3) {
        let (x, y) = (rng.random_range(0..side), rng.random_range(0..side));
        if !grid.at_mut(x, y).obstacle {
            grid.at_mut(x, y).rough = 1;
        }
    }
    // Boxes start and end off the border (a box against the border stays against it).
    let mut free: Vec<(i32, i32)> = (1..side - 1)
        .flat_map(|y| (1..side - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| grid.free(x, y))
        .collect();
    if free.len() < 2 * boxes + 1 {
        return None;
    }
    let mut pick = |rng: &mut ChaCha8Rng| free.swap_remove(rng.random_range(0..free.len()));
    let robot = pick(rng);
    let starts: Vec<Placement> = (0..boxes)
        .map(|_| {
            let (x, y) = pick(rng);
            Placement { x, y, o: 0 }
        })
        .collect();
    // Goals may coincide with another box's start (exchanges), never with each other.
    let mut goal_cells: Vec<(i32, i32)> = starts.iter().map(|p| (p.x, p.y)).collect();
    goal_cells.push(robot);
    goal_cells.extend(free.iter().copied());
    let mut goals = Vec::new();
    for _ in 0..boxes {
        let (x, y) = goal_cells.swap_remove(rng.random_range(0..goal_cells.len()));
        goals.push(Some(Placement { x, y, o: 0 }));
    }
    let metric = Metric {
        rough: [2, 4],
        turn: if boxes == 2 && k.is_multiple_of(4) {
            1
        } else {
            0
        },
        ..Metric::default()
    };
    Some(Problem {
        name: format!("random-{k}"),
        grid,
        robot: RobotSpec { size: 1, mass: 1 },
        movables: (0..boxes)
            .map(|i| MovableSpec::with_faces(&format!("b{i}"), vec![(0, 0)], 1 + i as u32))
            .collect(),
        rules: Rules::default(),
        metric,
        start: Config {
            robot,
            heading: Dir::E,
            pushing: false,
            movables: starts,
        },
        goal_robot: None,
        goal_movables: goals,
    })
}

#[test]
fn practical_plans_are_legal_and_close_to_the_optimum() {
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let (mut solvable, mut found, mut close, mut unsolvable) = (0, 0, 0, 0);
    let mut worst = 1.0f64;
    let mut k = 0;
    while solvable < 110 {
        k += 1;
        let Some(p) = random_problem(&mut rng, k) else {
            continue;
        };
        let Ok(model) = Model::new(&p) else { continue };
        let map = cost_map(&model).unwrap();
        let optimum = map.get(model.pack(&p.start).unwrap());
        let practical = plan_practical(&p, &Options::for_problem(&p));
        match (optimum, practical) {
            (Some(opt), Ok(plan)) => {
                solvable += 1;
                found += 1;
                let configs: Vec<Config> = plan.moves.iter().map(|m| m.config.clone()).collect();
                assert_eq!(
                    replay_cost(&model, &p.start, &configs),
                    Some(plan.cost),
                    "{}: the practical plan must replay legally at its cost",
                    p.name
                );
                let end = &configs.last().unwrap_or(&p.start).movables;
                for (i, g) in p.goal_movables.iter().enumerate() {
                    assert_eq!(Some(end[i]), *g, "{}: ends at the goals", p.name);
                }
                assert!(plan.cost >= opt, "{}: cheaper than the optimum", p.name);
                assert!(!plan.optimal);
                worst = worst.max(plan.cost as f64 / opt.max(1) as f64);
                if plan.cost as f64 <= 1.2 * opt as f64 {
                    close += 1;
                }
            }
            (Some(opt), Err(e)) => {
                solvable += 1;
                eprintln!("{}: optimum {opt}, practical: {e}", p.name);
                assert!(
                    matches!(e, PracticalError::NoPlanFound { .. }),
                    "{}: a plan exists, but the practical mode says {e}",
                    p.name
                );
            }
            (None, Ok(_)) => panic!("{}: a plan where the exact planner has none", p.name),
            (None, Err(_)) => unsolvable += 1,
        }
    }
    eprintln!(
        "{solvable} solvable: {found} found, {close} within 1.2× (worst {worst:.2}); {unsolvable} unsolvable"
    );
    assert!(unsolvable < solvable, "{unsolvable} unsolvable instances");
    assert!(found * 100 >= solvable * 98, "found {found} of {solvable}");
    assert!(
        close * 100 >= solvable * 95,
        "{close} of {solvable} within 1.2×"
    );
}

#[test]
fn a_box_that_cannot_reach_its_goal_even_alone_proves_no_plan_exists() {
    // a box in a corner cannot be pushed out
    let mut p = random_problem(&mut ChaCha8Rng::seed_from_u64(1), 2).unwrap();
    p.grid = Grid::new(5, 5);
    p.start.robot = (2, 2);
    p.start.movables = vec![
        Placement { x: 0, y: 0, o: 0 },
        Placement { x: 4, y: 2, o: 0 },
    ];
    p.goal_movables = vec![
        Some(Placement { x: 1, y: 3, o: 0 }),
        Some(Placement { x: 2, y: 3, o: 0 }),
    ];
    let e = plan_practical(&p, &Options::for_problem(&p)).unwrap_err();
    assert!(
        matches!(&e, PracticalError::NoPlanExists(name) if name == "b0"),
        "{e}"
    );
    assert!(e.to_string().contains("no plan exists"));
    // a goal behind a box that cannot be moved out of the way: no plan found, not "none exists"
    let mut q = p.clone();
    q.grid = Grid::new(3, 1);
    q.start.robot = (0, 0);
    q.start.movables = vec![
        Placement { x: 1, y: 0, o: 0 },
        Placement { x: 2, y: 0, o: 0 },
    ];
    q.goal_movables = vec![Some(Placement { x: 2, y: 0, o: 0 }), None];
    let model = Model::new(&q).unwrap();
    assert_eq!(
        cost_map(&model).unwrap().get(model.pack(&q.start).unwrap()),
        None
    );
    let e = plan_practical(&q, &Options::for_problem(&q)).unwrap_err();
    assert!(
        matches!(e, PracticalError::NoPlanFound { .. }),
        "{e}: alone, b0 could reach its goal, so nothing is proven"
    );
    assert!(e.to_string().starts_with("no plan found"));
}

/// Two one-cell boxes in an open 7 × 5 room, the robot at (1, 2).
fn two_boxes(b0: (i32, i32), g0: (i32, i32), b1: (i32, i32), g1: (i32, i32)) -> Problem {
    let mut p = random_problem(&mut ChaCha8Rng::seed_from_u64(1), 2).unwrap();
    p.grid = Grid::new(7, 5);
    p.metric = Metric::default();
    p.movables = (0..2)
        .map(|i| MovableSpec::with_faces(&format!("b{i}"), vec![(0, 0)], 1))
        .collect();
    p.start.robot = (1, 2);
    let at = |(x, y): (i32, i32)| Placement { x, y, o: 0 };
    p.start.movables = vec![at(b0), at(b1)];
    p.goal_movables = vec![Some(at(g0)), Some(at(g1))];
    p
}

#[test]
fn a_push_beside_a_movable_held_still_costs_what_the_exact_planner_charges() {
    // b0 is pushed twice east past b1, which sits at its goal diagonally below: the safety term
    // counts walls and the border, not b1, so the plan costs 2 × (robot 1 + box 1).
    let mut p = two_boxes((2, 2), (4, 2), (3, 3), (3, 3));
    p.metric.safety = 5;
    let model = Model::new(&p).unwrap();
    let opt = cost_map(&model)
        .unwrap()
        .get(model.pack(&p.start).unwrap())
        .unwrap();
    assert_eq!(opt, 4);
    let plan = plan_practical(&p, &Options::for_problem(&p)).unwrap();
    let configs: Vec<Config> = plan.moves.iter().map(|m| m.config.clone()).collect();
    assert_eq!(replay_cost(&model, &p.start, &configs), Some(plan.cost));
    assert!(plan.moves.iter().all(|m| m.cost == 2), "{:?}", plan.moves);
    assert_eq!(plan.cost, opt);
}

#[test]
fn a_movable_left_where_none_may_be_left_is_pushed_last() {
    // b0's goal is a no-leave cell: the cheaper order (b0 first) would leave it there while b1
    // is pushed, which the rules forbid, so b1 goes first.
    let mut p = two_boxes((2, 1), (3, 1), (2, 3), (4, 3));
    p.grid.at_mut(3, 1).no_leave = true;
    let model = Model::new(&p).unwrap();
    let opt = cost_map(&model)
        .unwrap()
        .get(model.pack(&p.start).unwrap())
        .unwrap();
    let plan = plan_practical(&p, &Options::for_problem(&p)).unwrap();
    let configs: Vec<Config> = plan.moves.iter().map(|m| m.config.clone()).collect();
    assert_eq!(replay_cost(&model, &p.start, &configs), Some(plan.cost));
    assert!(plan.cost >= opt);
    let last_push = plan
        .moves
        .iter()
        .rev()
        .find(|m| m.action != Action::Transit);
    assert_eq!(last_push.map(|m| m.action), Some(Action::Push(0)));
}
