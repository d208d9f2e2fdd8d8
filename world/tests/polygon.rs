//! The O(n log n) simple-polygon check: big circles accepted, crossings named, and the same
//! verdict as the O(n²) reference on random small polygons (float and grid coordinates, the
//! latter full of touching and collinear edges).

use proptest::prelude::*;
use pushbot_world::geometry::{Outline, ShapeError};
use pushbot_world::polygon::{check_simple, check_simple_quadratic, normalise_ccw};

fn circle(n: usize, r: f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [0.6 + r * a.cos(), 0.45 + r * a.sin()]
        })
        .collect()
}

#[test]
fn a_100000_vertex_circle_is_simple() {
    let c = circle(100_000, 0.4);
    assert_eq!(check_simple(&c), Ok(()));
    // And it makes an outline (one convex part): a point inside, one outside.
    let o = Outline::polygon(&c).expect("an outline");
    let at = pushbot_world::Pose::default();
    assert!(o.contains(&at, [0.6, 0.45]) && !o.contains(&at, [1.01, 0.45]));
    let mut cw = c.clone();
    cw.reverse();
    assert_eq!(check_simple(&cw), Ok(()));
}

#[test]
fn a_big_self_crossing_outline_names_its_edges() {
    let mut c = circle(20_000, 0.4);
    // Swap two far-apart vertices: edges 4999/5000 and 14999/15000 now cross the circle.
    c.swap(5_000, 15_000);
    let e = check_simple(&c).unwrap_err();
    let ShapeError::SelfIntersecting(i, j) = e else {
        panic!("{e:?}")
    };
    assert!(i < j);
    let touched = [4_999, 5_000, 14_999, 15_000];
    assert!(
        touched.contains(&i) || touched.contains(&j),
        "edges {i} and {j}"
    );
    assert!(e.to_string().contains(&format!("edges {i} and {j} cross")));
}

#[test]
fn a_star_of_many_spikes_is_simple_and_fast_to_check() {
    // Every edge's bounding box holds the centre: bad for box-based culling, fine for a sweep.
    let n = 20_000;
    let star: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = if i % 2 == 0 { 0.4 } else { 0.001 };
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    assert_eq!(check_simple(&star), Ok(()));
}

#[test]
fn the_old_errors_stay() {
    assert_eq!(
        check_simple(&[[0.0, 0.0], [1.0, 0.0]]),
        Err(ShapeError::TooFew)
    );
    assert_eq!(
        check_simple(&[[0.0, 0.0], [1.0, 0.0], [f64::NAN, 1.0]]),
        Err(ShapeError::TooFew)
    );
    assert_eq!(
        check_simple(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]),
        Err(ShapeError::Degenerate)
    );
    assert_eq!(
        check_simple(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        Err(ShapeError::Degenerate)
    );
    // A vertex on another edge (T-junction) and collinear overlap both count as crossing.
    let t = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
    assert!(matches!(
        check_simple(&t),
        Err(ShapeError::SelfIntersecting(..))
    ));
}

#[test]
fn a_u_shaped_obstacle_keeps_its_inside_free() {
    // A U open upwards: its notch (0.4..0.6 × 0.3..1.0) is free, its walls are not.
    let u = [
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.6, 1.0],
        [0.6, 0.3],
        [0.4, 0.3],
        [0.4, 1.0],
        [0.0, 1.0],
    ];
    let o = Outline::polygon(&u).unwrap();
    assert!(o.parts() >= 2, "kept as convex parts, not hulled");
    let at = pushbot_world::Pose::default();
    assert!(!o.contains(&at, [0.5, 0.6]), "the notch is free");
    assert!(o.contains(&at, [0.2, 0.6]) && o.contains(&at, [0.5, 0.1]));
    // A disc in the notch does not overlap it; one on a wall does.
    let disc = Outline::disc(0.05);
    assert!(!o.overlaps(&pushbot_world::Pose::new(0.5, 0.7, 0.0), &disc, &at, 1e-9));
    assert!(disc.overlaps(&pushbot_world::Pose::new(0.2, 0.7, 0.0), &o, &at, 1e-9));
    // Clockwise, the same shape.
    let mut cw: Vec<[f64; 2]> = u.iter().rev().copied().collect();
    assert!(normalise_ccw(&mut cw));
    let o = Outline::polygon(&cw).unwrap();
    assert!(!o.contains(&at, [0.5, 0.6]));
}

fn verdict(r: Result<(), ShapeError>) -> &'static str {
    match r {
        Ok(()) => "ok",
        Err(ShapeError::SelfIntersecting(..)) => "crossing",
        Err(_) => "other",
    }
}

/// Both checks agree; a crossing the sweep names is a real one.
fn agree(poly: &[[f64; 2]]) -> Result<(), TestCaseError> {
    let (fast, slow) = (check_simple(poly), check_simple_quadratic(poly));
    prop_assert_eq!(verdict(fast.clone()), verdict(slow.clone()), "{:?}", poly);
    if let Err(ShapeError::SelfIntersecting(i, j)) = fast {
        let n = poly.len();
        prop_assert!(i < j && j < n, "edges {} and {} of {}", i, j, n);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn the_sweep_agrees_with_every_pair_on_floats(
        poly in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 3..12)
    ) {
        let poly: Vec<[f64; 2]> = poly.into_iter().map(|(x, y)| [x, y]).collect();
        agree(&poly)?;
    }

    #[test]
    fn the_sweep_agrees_with_every_pair_on_a_grid(
        poly in prop::collection::vec((0i32..5, 0i32..5), 3..12)
    ) {
        let poly: Vec<[f64; 2]> = poly.into_iter().map(|(x, y)| [x as f64, y as f64]).collect();
        agree(&poly)?;
    }

    #[test]
    fn the_sweep_agrees_on_star_shaped_polygons(
        radii in prop::collection::vec(1i32..4, 3..16), jitter in 0usize..3
    ) {
        // Simple by construction (vertices at increasing angles), on a coarse grid of radii
        // with collinear runs; `jitter` swaps two vertices to make some of them not simple.
        let n = radii.len();
        let mut poly: Vec<[f64; 2]> = radii
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [(*r as f64 * a.cos() * 4.0).round(), (*r as f64 * a.sin() * 4.0).round()]
            })
            .collect();
        if jitter > 0 {
            poly.swap(0, jitter.min(n - 1));
        }
        agree(&poly)?;
    }
}
