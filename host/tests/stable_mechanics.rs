//! STABLE (Lynch & Mason 1996 §3.3.1) against hand-computed cases, and the controllability
//! verdicts against the paper's statements (§2.3, §3.2.2, §3.3.2).

use std::f64::consts::PI;

use pushbot::mechanics::controllability::{
    PushBoundary, controllable, positively_spans_space, small_time_locally_controllable,
    theorem2_edge, theorem2_vertex, theorem3, theorem5, theorem6, theorem7,
};
use pushbot::mechanics::limit_surface::EllipsoidLimitSurface;
use pushbot::mechanics::stable::{StableSet, stable};
use pushbot::mechanics::{LineContact, Slider, V2, V3, cor};

fn square() -> Slider {
    let o = [
        V2::new(-1.0, -1.0),
        V2::new(1.0, -1.0),
        V2::new(1.0, 1.0),
        V2::new(-1.0, 1.0),
    ];
    Slider::new(&o, V2::zeros()).unwrap()
}

fn regular(n: usize, r: f64) -> Slider {
    let o: Vec<V2> = (0..n)
        .map(|k| {
            let a = 2.0 * PI * (k as f64 + 0.5) / n as f64 - PI / 2.0;
            V2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    Slider::new(&o, V2::zeros()).unwrap()
}

fn rect(w: f64, h: f64, cof: V2) -> Slider {
    let o = [
        V2::new(0.0, 0.0),
        V2::new(w, 0.0),
        V2::new(w, h),
        V2::new(0.0, h),
    ];
    Slider::new(&o, cof).unwrap()
}

fn same_set(got: &[V3], want: &[V3]) {
    assert_eq!(got.len(), want.len(), "got {got:?}, want {want:?}");
    for w in want {
        let w = w.normalize();
        assert!(
            got.iter().any(|g| (g - w).norm() < 1e-9),
            "missing {w:?} in {got:?}"
        );
    }
}

/// Square of side 2, centre of friction at its centre, bottom edge pushed, μ = 0.5.
///
/// α = atan 0.5, e_L = (−1, 2)/√5, e_R = (1, 2)/√5. Over the vertices (±1, ±1):
/// M_L = max e_L·x = 3/√5, m_R = min e_R·x = −3/√5. Counter-clockwise centres of step 1 lie in
/// the wedge e_L·c ≥ 3/√5 (−c_x + 2c_y ≥ 3) and e_R·c ≤ −3/√5 (c_x + 2c_y ≤ −3): apex (−3, 0),
/// opening to the left along (−2, ∓1). Step 2, end points P₁ = (−1, −1), P₂ = (1, −1),
/// p = √2, r = √2: bisector of P₁: c_x + c_y ≤ −1; tip line of P₂ (r²/p = √2): c_x − c_y ≤ −2.
/// At c_x ≤ −3 the wedge is inside both (checked at the apex and the slopes), so the region is
/// the wedge. Its vertices on the velocity sphere: rotation about (−3, 0) counter-clockwise,
/// v = (ω c_y, −ω c_x, ω) = (0, 3, 1)/√10, and the translations along the wedge's edges, the
/// friction-cone edges (∓1, 2)/√5. By symmetry the clockwise apex is (3, 0): (0, 3, −1)/√10.
#[test]
fn stable_square_mu_half_hand_computed() {
    let s = square();
    let set = stable(&s, &LineContact::full_edge(&s, 0).unwrap(), 0.5).unwrap();
    same_set(
        &set.extremal,
        &[
            V3::new(0.0, 3.0, 1.0),
            V3::new(0.0, 3.0, -1.0),
            V3::new(-1.0, 2.0, 0.0),
            V3::new(1.0, 2.0, 0.0),
        ],
    );
    let cors: Vec<V2> = set.extremal_cors().into_iter().flatten().collect();
    assert!(cors.iter().any(|c| (c - V2::new(-3.0, 0.0)).norm() < 1e-9));
    // "Two rotations and two translations" (§4.4).
    assert_eq!(set.translations().len(), 2);
}

/// Same square, μ = 10: the friction cone is wide and the end-point bands bind.
///
/// s = sin α = 10/√101, c = cos α = 1/√101. Step 1 (ccw): c_y ≥ 11 + 10c_x and
/// c_y ≤ −11 − 10c_x. Step 2: c_y ≤ −1 − c_x (bisector of P₁), c_y ≥ c_x + 2 (tip line of P₂).
/// For c_x < −1 the tip line is above step 1's lower line, and the bisector below step 1's
/// upper line once c_x < −10/9; they meet where c_x + 2 = −1 − c_x: apex (−1.5, 0.5), opening
/// to the left along (−1, −1) and (−1, 1): translations towards the contact's end points,
/// (±1, 1)/√2. Rotation about (−1.5, 0.5) ccw: v = (0.5, 1.5, 1); mirrored: (−0.5, 1.5, −1).
#[test]
fn stable_square_mu_ten_end_point_bands_bind() {
    let s = square();
    let set = stable(&s, &LineContact::full_edge(&s, 0).unwrap(), 10.0).unwrap();
    same_set(
        &set.extremal,
        &[
            V3::new(0.5, 1.5, 1.0),
            V3::new(-0.5, 1.5, -1.0),
            V3::new(1.0, 1.0, 0.0),
            V3::new(-1.0, 1.0, 0.0),
        ],
    );
}

/// The same contact on a rotated, shifted edge gives the same set, rotated: STABLE does not
/// depend on which edge is "horizontal on the page".
#[test]
fn stable_is_frame_independent() {
    let s = square();
    let top = stable(&s, &LineContact::full_edge(&s, 2).unwrap(), 0.5).unwrap();
    // Edge 2 runs from (1,1) to (−1,1), normal −y: the bottom-edge set rotated by π.
    let want: Vec<V3> = [
        V3::new(0.0, 3.0, 1.0),
        V3::new(0.0, 3.0, -1.0),
        V3::new(-1.0, 2.0, 0.0),
        V3::new(1.0, 2.0, 0.0),
    ]
    .iter()
    .map(|v| V3::new(-v.x, -v.y, v.z))
    .collect();
    same_set(&top.extremal, &want);
}

/// Theorem 4's lines are implied by steps 1–2 (the paper's "therefore"): dropping them does not
/// change the extremal set on these cases, and every rotation centre found lies outside them.
#[test]
fn theorem4_lines_are_redundant_on_polygons() {
    for (s, mu) in [
        (square(), 0.5),
        (square(), 10.0),
        (rect(3.0, 1.0, V2::new(1.2, 0.4)), 0.3),
        (regular(6, 1.0), 0.8),
    ] {
        for e in 0..s.n_edges() {
            let c = LineContact::full_edge(&s, e).unwrap();
            let set = stable(&s, &c, mu).unwrap();
            let without = StableSet {
                contact: c,
                constraints: set.constraints[..8].to_vec(),
                extremal: pushbot::mechanics::stable::extreme_rays(&set.constraints[..8]),
            };
            same_set(&without.extremal, &set.extremal);
            let xs: Vec<f64> = s
                .vertices
                .iter()
                .map(|v| c.to_contact_frame(*v).x)
                .collect();
            let (xmin, xmax) = (
                xs.iter().copied().fold(f64::INFINITY, f64::min),
                xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            );
            for v in &set.extremal {
                if let Some(k) = cor(v) {
                    let kx = c.to_contact_frame(k).x;
                    if v.z > 0.0 {
                        assert!(kx <= xmin + 1e-9)
                    } else {
                        assert!(kx >= xmax - 1e-9)
                    }
                }
            }
        }
    }
}

/// STABLE is conservative: for a concrete bounded support distribution (ellipsoidal limit
/// surfaces with characteristic lengths up to r), the force that produces any direction STABLE
/// returns lies in the composite friction cone of the line contact (§3.3.1, Fig. 9).
#[test]
fn stable_directions_need_forces_inside_the_composite_cone() {
    for (s, mu) in [
        (square(), 0.5),
        (rect(3.0, 1.0, V2::new(1.2, 0.4)), 0.3),
        (regular(8, 1.0), 1.0),
    ] {
        let r = s.radius();
        for e in 0..s.n_edges() {
            let c = LineContact::full_edge(&s, e).unwrap();
            let set = stable(&s, &c, mu).unwrap();
            let (t, n) = (c.tangent(), c.normal());
            let a = mu.atan();
            let edges = [n * a.cos() - t * a.sin(), n * a.cos() + t * a.sin()];
            let gens: Vec<V3> = [c.a, c.b]
                .iter()
                .flat_map(|p| {
                    edges
                        .iter()
                        .map(move |d| V3::new(d.x, d.y, p.x * d.y - p.y * d.x))
                })
                .collect();
            // Facets of the composite cone (pointed): planes through two generators with all
            // generators on one side.
            let mut facets = Vec::new();
            for i in 0..gens.len() {
                for j in i + 1..gens.len() {
                    let f = gens[i].cross(&gens[j]);
                    if f.norm() < 1e-12 {
                        continue;
                    }
                    for sg in [1.0, -1.0] {
                        let f = f * sg;
                        if gens.iter().all(|g| f.dot(g) >= -1e-9) {
                            facets.push(f.normalize());
                        }
                    }
                }
            }
            for frac in [0.3, 0.5, 0.7, 1.0] {
                let ls = EllipsoidLimitSurface {
                    c: frac * r / 2f64.sqrt(),
                };
                let k = set.extremal.len();
                for i in 0..k {
                    for w in [0.0, 0.3, 0.7] {
                        let v = set.extremal[i] * (1.0 - w) + set.extremal[(i + 1) % k] * w;
                        let f = ls.force(&v);
                        for fa in &facets {
                            assert!(
                                fa.dot(&f) >= -1e-7,
                                "edge {e}, c={frac}: force {f:?} outside F"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Proposition 6: a contact that cannot apply a force through the centre of friction gives no
/// stable direction (and Theorem 5 does not hold).
#[test]
fn no_pure_force_no_stable_push() {
    let s = square();
    let c = LineContact {
        edge: 0,
        a: V2::new(0.5, -1.0),
        b: V2::new(1.0, -1.0),
    };
    let set = stable(&s, &c, 0.1).unwrap();
    assert!(set.is_empty(), "{:?}", set.extremal);
    assert!(!theorem5(&c, 0.1));
    // With enough friction a pure force through the centre is inside F again.
    assert!(theorem5(&c, 1.0));
    assert!(!stable(&s, &c, 1.0).unwrap().is_empty());
}

/// §3.3.2: any rectangle or regular 2k-gon pushed from two opposite edges is small-time locally
/// controllable by STABLE pushes (centre of friction inside, nonzero friction) — by Theorem 7
/// and, independently, by Proposition 4 on the extremal directions STABLE finds.
#[test]
fn rectangles_and_regular_2k_gons_are_stlc_from_two_opposite_edges() {
    let mut cases: Vec<(Slider, usize, usize)> = vec![
        (rect(2.0, 1.0, V2::new(1.0, 0.5)), 0, 2),
        (rect(1.0, 3.0, V2::new(0.5, 1.5)), 1, 3),
        (rect(3.0, 1.0, V2::new(0.8, 0.3)), 0, 2),
    ];
    for k in 2..=6 {
        cases.push((regular(2 * k, 1.0), 0, k));
    }
    for (s, e1, e2) in &cases {
        for mu in [0.1, 0.5, 2.0] {
            let c1 = LineContact::full_edge(s, *e1).unwrap();
            let c2 = LineContact::full_edge(s, *e2).unwrap();
            assert!(theorem7(&[c1, c2], mu), "Theorem 7 on {:?}", s.vertices);
            let mut dirs = stable(s, &c1, mu).unwrap().extremal;
            dirs.extend(stable(s, &c2, mu).unwrap().extremal);
            assert!(
                small_time_locally_controllable(&dirs),
                "Prop 4 on {:?} mu {mu}",
                s.vertices
            );
            // One edge alone: controllable (Theorem 5, Proposition 2) but not STLC (it cannot pull).
            let one = stable(s, &c1, mu).unwrap().extremal;
            assert!(theorem5(&c1, mu) && controllable(&one));
            assert!(!small_time_locally_controllable(&one));
            assert!(!theorem7(&[c1], mu));
        }
        // Frictionless line contacts: F has no interior, Theorem 7 does not apply.
        let c1 = LineContact::full_edge(s, *e1).unwrap();
        let c2 = LineContact::full_edge(s, *e2).unwrap();
        assert!(!theorem7(&[c1, c2], 0.0));
    }
}

/// Two adjacent edges of a square: pure forces span only a quarter plane, not STLC.
#[test]
fn adjacent_edges_are_not_stlc() {
    let s = square();
    let cs = [
        LineContact::full_edge(&s, 0).unwrap(),
        LineContact::full_edge(&s, 1).unwrap(),
    ];
    assert!(!theorem7(&cs, 0.5));
    let mut dirs = stable(&s, &cs[0], 0.5).unwrap().extremal;
    dirs.extend(stable(&s, &cs[1], 0.5).unwrap().extremal);
    assert!(!small_time_locally_controllable(&dirs));
    // All four edges: STLC.
    let all: Vec<LineContact> = (0..4)
        .map(|e| LineContact::full_edge(&s, e).unwrap())
        .collect();
    assert!(theorem7(&all, 0.5));
}

/// Theorem 3: point-contact pushing is STLC for any Γ except a frictionless disk centred at the
/// centre of friction.
#[test]
fn theorem3_frictionless_centred_disk_is_the_only_exception() {
    let disk = PushBoundary::Disk {
        centre: V2::zeros(),
        radius: 1.0,
    };
    assert!(!theorem3(&disk, 0.0));
    assert!(theorem3(&disk, 0.2));
    assert!(theorem3(
        &PushBoundary::Disk {
            centre: V2::new(0.3, 0.0),
            radius: 1.0
        },
        0.0
    ));
    assert!(theorem3(&PushBoundary::Polygon(square().vertices), 0.0));
    assert!(theorem3(
        &PushBoundary::Polygon(regular(6, 1.0).vertices),
        0.0
    ));
    assert!(theorem3(
        &PushBoundary::Polygon(rect(3.0, 1.0, V2::new(0.4, 0.2)).vertices.clone()),
        0.5
    ));
}

/// Theorem 2 (through Proposition 5): any edge, frictionless or not; any vertex with friction
/// not at the centre of friction. Theorem 6: some edge is controllable by STABLE pushes.
#[test]
fn theorem2_and_theorem6_on_polygons() {
    for s in [square(), regular(5, 1.0), rect(3.0, 1.0, V2::new(0.4, 0.2))] {
        for e in 0..s.n_edges() {
            assert!(theorem2_edge(&s, e, 0.0).unwrap());
            assert!(theorem2_edge(&s, e, 0.5).unwrap());
            assert!(theorem2_vertex(&s, e, 0.3).unwrap());
        }
        assert!(theorem6(&s, 0.3).unwrap());
        assert!(!theorem6(&s, 0.0).unwrap(), "no interior without friction");
    }
    // Proposition 5's "only if": a single force direction, or forces all through the centre.
    assert!(!pushbot::mechanics::controllability::proposition5(&[
        V3::new(0.0, 1.0, 0.5)
    ]));
    assert!(!pushbot::mechanics::controllability::proposition5(&[
        V3::new(0.0, 1.0, 0.0),
        V3::new(1.0, 0.0, 0.0)
    ]));
}

/// Positive spanning on a known set: the six ± axes span, five do not.
#[test]
fn positive_span_of_axes() {
    let mut d = vec![V3::x(), -V3::x(), V3::y(), -V3::y(), V3::z(), -V3::z()];
    assert!(positively_spans_space(&d));
    d.pop();
    assert!(!positively_spans_space(&d));
}
