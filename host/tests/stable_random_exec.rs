//! Random stable-pushing scenes executed: scenes of
//! `planner::stable::random_scene` planned with the nominal model (Lynch & Mason §4) and driven
//! closed loop on the perturbed in-process simulated robot, which starts at a free pose of any
//! heading and first drives to the plan's first edge. Judged by the simulator's true slider
//! pose. The full measurement (50 diff-drive scenes, 50 car scenes) is `pushbot eval stable
//! --random 50 [--pusher car] --perturb` (README).

use pushbot::experiments::stable_trials::{StableTask, run_trial};
use pushbot::planner::stable::angle_diff;
use pushbot::planner::stable::random_scene::RandomPusher;
use pushbot::planner::stable::robot::robot_in_slider;
use pushbot::sim::robot::SimCamera;

/// Run the random scene `seed` for `pusher` once, perturbed; the robot must start away from
/// the first edge, and the goal be reached.
fn reaches(seed: u64, pusher: RandomPusher) {
    let task = StableTask::random(seed, pusher)
        .unwrap()
        .unwrap_or_else(|| panic!("scene {seed}: no plan"));
    let start = task.robot_start.expect("a start away from the slider");
    let q = task.problem.start;
    let (axle, heading) = robot_in_slider(&task.problem, task.plan.steps[0].contact);
    let (c, h) = (q.apply(axle), q.rotate(heading));
    let turn = angle_diff(start[2], h.y.atan2(h.x)).to_degrees();
    eprintln!(
        "{}: robot starts {:.0} mm from the first edge's pose, turned {turn:.0}°",
        task.name,
        (c.x - start[0]).hypot(c.y - start[1]) * 1e3
    );
    assert!((c.x - start[0]).hypot(c.y - start[1]) > 0.1);
    let pert = task.perturbation(1, seed, true);
    let t = run_trial(&task, seed, 1, pert, true, SimCamera::Truth).unwrap();
    eprintln!(
        "{}: reached {} ({:.1} mm, {:.2}°, {} re-plans, {} contact losses)",
        task.name,
        t.reached,
        t.final_error_m * 1e3,
        t.final_error_deg,
        t.replans,
        t.contact_losses
    );
    assert!(t.reached, "{}: {:?}", task.name, t.failure);
}

#[test]
fn a_random_diff_drive_scene_is_reached_from_any_start() {
    reaches(5, RandomPusher::DiffDrive);
}

#[test]
fn a_random_car_scene_is_reached_from_any_start() {
    reaches(5, RandomPusher::Car);
}

#[test]
fn only_wheeled_pushers_run_on_the_simulated_robot() {
    let e = StableTask::random(1, RandomPusher::Arm).err().unwrap();
    assert!(format!("{e}").contains("diff-drive and car"), "{e}");
}
