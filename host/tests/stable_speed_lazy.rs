//! The planner's speed-ups keep its answers: lazy collision checks (a step checked when its node
//! is taken from OPEN, `Checks::Lazy`) against the paper's eager order (checked before the node
//! enters OPEN, `Checks::Eager`), on the five presets with random starts, goals, costs and node
//! limits. Both must expand the same number of configurations and return the same plan, step
//! for step.

use pushbot::planner::stable::presets::{CostOverride, PRESETS, load_scene};
use pushbot::planner::stable::{Checks, Pose, Queue, plan_checked};
use rand::{Rng, SeedableRng};

#[test]
fn lazy_collision_checks_give_the_eager_plan() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(17);
    let (mut found, mut runs) = (0, 0);
    for name in PRESETS {
        let scene = load_scene(name).unwrap();
        for trial in 0..6 {
            let costs = if trial == 0 {
                CostOverride::default()
            } else {
                CostOverride {
                    a: Some(rng.random_range(0..3)),
                    b: Some(rng.random_range(0..6)),
                    c: Some(Some(rng.random_range(0..12))),
                }
            };
            let Ok(mut p) = scene.problem(costs) else {
                continue;
            };
            let (w, h) = p.world.table;
            let free = |p: &pushbot::planner::stable::Problem, q: &Pose| {
                p.contacts.iter().any(|cm| cm.body.free_at(&p.world, q))
            };
            if trial > 0 {
                // A random free start and goal.
                let pick = |rng: &mut rand::rngs::StdRng| loop {
                    let q = Pose::new(
                        rng.random_range(0.0..w),
                        rng.random_range(0.0..h),
                        rng.random_range(-3.2..3.2),
                    );
                    if free(&p, &q) {
                        return q;
                    }
                };
                let (s, g) = (pick(&mut rng), pick(&mut rng));
                p.start = s;
                p.goal = g;
            }
            p.params.max_nodes = rng.random_range(200..4000);
            for queue in [Queue::Buckets, Queue::Heap] {
                let e = plan_checked(&p, queue, Checks::Eager);
                let l = plan_checked(&p, queue, Checks::Lazy);
                let what = format!("{name} trial {trial} {queue:?}");
                assert_eq!(e.found, l.found, "{what}");
                assert_eq!(e.cost, l.cost, "{what}");
                assert_eq!(e.nodes_expanded, l.nodes_expanded, "{what}");
                assert_eq!(e.steps, l.steps, "{what}");
                assert_eq!(e.transits, l.transits, "{what}");
                runs += 1;
                found += usize::from(e.found);
            }
        }
    }
    // Both outcomes must occur for the comparison to mean something.
    assert!(
        runs >= 40 && found >= 5 && found < runs,
        "{found} of {runs}"
    );
}
