//! Fewer samples to learn than the paper: the active collection (uncertain initial pushes, a short
//! initial collection, only informative supplemental samples) reaches Lau et al.'s 10-streak
//! (§III-D) within 300 samples, and the data-need curve (`eval delivery --figure 7`) has its
//! shape.

use pushbot::exec::collect::{COVERED, CollectParams, uncovered};
use pushbot::exec::deliver::DeliveryParams;
use pushbot::experiments::data_need::{
    DataNeedSetup, VARIANTS, checkpoints, collect_clear, data_need, variant_params,
};
use pushbot::sim::robot::SimRobotOptions;
use pushbot::strategy::active::Selection;
use pushbot::strategy::regression::KernelParams;
use pushbot_sim::Scene;

fn setup() -> DataNeedSetup {
    DataNeedSetup {
        every: 50,
        tests: 2,
        max_samples: 1000,
        streak: 10,
        seed: 1,
        sim: SimRobotOptions::default(),
        delivery: DeliveryParams::default(),
        kernel: KernelParams::default(),
        starts: vec!["E".into(), "F".into()],
    }
}

#[test]
fn the_default_collection_is_the_active_one() {
    let p = CollectParams::default();
    assert_eq!(p.selection, Selection::Explore);
    assert!(p.admission.is_some());
    assert!(p.initial < 300);
    let explore = VARIANTS.iter().find(|v| v.name == "explore").unwrap();
    assert_eq!(variant_params(explore, &setup()).initial, p.initial);
    assert_eq!(variant_params(explore, &setup()).selection, p.selection);
}

#[test]
fn the_data_need_curve_of_the_active_collection_reaches_the_streak_within_300_samples() {
    let scene = Scene::preset("lau-irregular").unwrap();
    let s = setup();
    let explore = *VARIANTS.iter().find(|v| v.name == "explore").unwrap();
    let curves = data_need(std::slice::from_ref(&scene), &[explore], &s).unwrap();
    let [c] = curves.as_slice() else {
        panic!("one scene × one variant: {} curves", curves.len())
    };
    let rep = &c.collection;
    let n = c.streak_at.expect("10 straight successes");
    assert!(n <= 300, "{n} samples: {rep:?}");
    assert_eq!(
        n,
        rep.initial_samples + rep.coverage_samples + rep.supplemental_samples
    );
    // Informative pushes only: the evaluation pushed more than it kept.
    assert!(rep.evaluation_pushes > rep.supplemental_samples, "{rep:?}");
    // A point every 50 samples and one at the end, each with its test deliveries.
    let at: Vec<usize> = c.points.iter().map(|p| p.samples).collect();
    assert_eq!(at, checkpoints(n, 50, 1000));
    assert!(c.points.iter().all(|p| p.tests == 2 && p.successes <= 2));
    // The strategy that reached the streak delivers from the scene's starts.
    assert!(c.points.last().unwrap().successes >= 1, "{:?}", c.points);

    // Reproducible from the seed: the same collection again.
    let (samples, again) = collect_clear(&scene, &variant_params(&explore, &s), &s).unwrap();
    assert_eq!(samples.len(), n);
    assert_eq!(again.evaluation_pushes, rep.evaluation_pushes);
}

#[test]
fn the_exploring_collection_chooses_its_own_pushes() {
    // `--selection explore` is wired to the initial collection: 40 pushes of the L-shape, each
    // a sample, reproducible from the seed, and not the pushes the uncertain selection makes;
    // then a push for each way of moving the object they missed.
    let scene = Scene::preset("lau-l-shape").unwrap();
    let s = setup();
    let params = |selection| CollectParams {
        initial: 40,
        streak: 0,
        selection,
        ..CollectParams::default()
    };
    let (explore, rep) = collect_clear(&scene, &params(Selection::Explore), &s).unwrap();
    assert_eq!(rep.initial_samples, 40, "{rep:?}");
    // After the 40 pushes, one coverage push for each way (every 45°) they did not move the
    // object by 1 cm; each that moved it is a sample, and covers its way or another.
    let before = uncovered(&explore[..40], COVERED);
    let after = uncovered(&explore, COVERED);
    assert_eq!(rep.coverage_pushes, before.len(), "{rep:?}");
    assert_eq!(explore.len(), 40 + rep.coverage_samples);
    assert!(
        after.iter().all(|a| before.contains(a)),
        "{before:?} → {after:?}"
    );
    assert!(after.len() < before.len(), "{before:?} → {after:?}");
    let (again, _) = collect_clear(&scene, &params(Selection::Explore), &s).unwrap();
    assert_eq!(again, explore);
    let (uncertain, rep) = collect_clear(&scene, &params(Selection::Uncertain), &s).unwrap();
    assert_eq!(uncertain.len(), 40);
    assert_eq!(rep.coverage_pushes, 0);
    // The first push is the same (no samples yet: every candidate is unknown alike); after it
    // the two selections part.
    assert_eq!(uncertain[0], explore[0]);
    assert_ne!(uncertain[..], explore[..40]);
}
