//! The smallest circle enclosing a set of points: what an object's outline sweeps through as it
//! turns about the circle's centre, and the smallest such disc about any point. A delivery
//! among obstacles plans the object's way for this disc (Lau, Mitani & Igarashi §III-E plan a
//! path for the object as a whole; the disc is its outline swept through every rotation).
//!
//! Welzl's move-to-front idea in its iterative form ("Smallest enclosing disks (balls and
//! ellipsoids)", 1991; de Berg et al., *Computational Geometry*, §4.7): the points are visited
//! in a shuffled order, and a point outside the disc so far is on the boundary of the disc of
//! the points up to it, which is found the same way with one or two boundary points fixed.
//! Expected O(n); the shuffle is a fixed pseudo-random permutation, so the result does not
//! depend on a random source.

/// A circle of the plane.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Circle {
    /// Centre.
    pub centre: [f64; 2],
    /// Radius.
    pub radius: f64,
}

/// Relative slack for "inside": a point is counted inside a circle it is outside of by no
/// more than this share of the radius (the circles are built from the points themselves).
const SLACK: f64 = 1e-9;

impl Circle {
    /// A circle of `radius` about the origin.
    pub fn at_origin(radius: f64) -> Circle {
        Circle {
            centre: [0.0, 0.0],
            radius,
        }
    }

    /// Whether `p` lies inside or on the circle.
    pub fn contains(&self, p: [f64; 2]) -> bool {
        dist(self.centre, p) <= self.radius * (1.0 + SLACK) + SLACK
    }

    fn of_two(a: [f64; 2], b: [f64; 2]) -> Circle {
        let centre = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        Circle {
            centre,
            radius: dist(centre, a).max(dist(centre, b)),
        }
    }

    /// The circle through `a`, `b`, `c`; for (nearly) collinear points the circle on the two
    /// furthest apart.
    fn of_three(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Circle {
        let (bx, by) = (b[0] - a[0], b[1] - a[1]);
        let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
        let d = 2.0 * (bx * cy - by * cx);
        let scale = (bx * bx + by * by).max(cx * cx + cy * cy);
        if d.abs() <= 1e-12 * scale {
            return [
                Circle::of_two(a, b),
                Circle::of_two(a, c),
                Circle::of_two(b, c),
            ]
            .into_iter()
            .max_by(|x, y| x.radius.total_cmp(&y.radius))
            .unwrap_or(Circle::of_two(a, b));
        }
        let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
        let ux = (cy * b2 - by * c2) / d;
        let uy = (bx * c2 - cx * b2) / d;
        let centre = [a[0] + ux, a[1] + uy];
        Circle {
            centre,
            radius: dist(centre, a).max(dist(centre, b)).max(dist(centre, c)),
        }
    }
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The smallest circle enclosing `points`; `None` when there are none or one is not finite.
pub fn enclosing_circle(points: &[[f64; 2]]) -> Option<Circle> {
    if points.is_empty() || points.iter().flatten().any(|v| !v.is_finite()) {
        return None;
    }
    let mut p = points.to_vec();
    shuffle(&mut p);
    let mut c = Circle {
        centre: p[0],
        radius: 0.0,
    };
    for i in 1..p.len() {
        if c.contains(p[i]) {
            continue;
        }
        // p[i] is on the boundary of the disc of p[..=i].
        c = Circle {
            centre: p[i],
            radius: 0.0,
        };
        for j in 0..i {
            if c.contains(p[j]) {
                continue;
            }
            // p[i] and p[j] are on the boundary of the disc of p[..=j] ∪ {p[i]}.
            c = Circle::of_two(p[i], p[j]);
            for k in 0..j {
                if !c.contains(p[k]) {
                    c = Circle::of_three(p[i], p[j], p[k]);
                }
            }
        }
    }
    Some(c)
}

/// A fixed pseudo-random permutation (Fisher–Yates on a 64-bit xorshift): the expected-linear
/// bound needs an order unrelated to the input's, not a random one.
fn shuffle(p: &mut [[f64; 2]]) {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in (1..p.len()).rev() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        p.swap(i, (s % (i as u64 + 1)) as usize);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The least, over a fine grid of centres (refined twice round the best), of the furthest
    /// point's distance: the optimum by brute force.
    fn brute_force(points: &[[f64; 2]]) -> f64 {
        let far = |c: [f64; 2]| points.iter().map(|&p| dist(c, p)).fold(0.0, f64::max);
        let (mut lo, mut hi) = ([-1.0, -1.0], [1.0, 1.0]);
        let mut best = [0.0, 0.0];
        for _ in 0..6 {
            let n = 60;
            let mut b = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    let c = [
                        lo[0] + (hi[0] - lo[0]) * i as f64 / n as f64,
                        lo[1] + (hi[1] - lo[1]) * j as f64 / n as f64,
                    ];
                    if far(c) < b {
                        b = far(c);
                        best = c;
                    }
                }
            }
            let w = (hi[0] - lo[0]) / n as f64 * 2.0;
            lo = [best[0] - w, best[1] - w];
            hi = [best[0] + w, best[1] + w];
        }
        far(best)
    }

    #[test]
    fn matches_brute_force_on_pseudo_random_point_sets() {
        let mut s: u64 = 12345;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 1.6 - 0.8
        };
        for n in [1, 2, 3, 4, 7, 12, 40] {
            for _ in 0..20 {
                let pts: Vec<[f64; 2]> = (0..n).map(|_| [next(), 0.5 * next()]).collect();
                let c = enclosing_circle(&pts).expect("a circle");
                assert!(pts.iter().all(|&p| c.contains(p)), "{pts:?} {c:?}");
                let best = brute_force(&pts);
                assert!(c.radius <= best + 1e-6, "{} > {best} for {pts:?}", c.radius);
            }
        }
    }

    #[test]
    fn collinear_and_repeated_points_and_bad_input() {
        let c = enclosing_circle(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 0.0]]).unwrap();
        assert!((c.radius - 1.0).abs() < 1e-12 && (c.centre[0] - 1.0).abs() < 1e-12);
        assert_eq!(enclosing_circle(&[]), None);
        assert_eq!(enclosing_circle(&[[f64::NAN, 0.0]]), None);
    }
}
