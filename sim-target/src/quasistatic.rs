//! One quasi-static step with several contacts at once: the robot (driven, kinematic) pushes
//! objects, which push each other and rest against walls and obstacles (static).
//!
//! Each object's support friction is the ellipsoidal limit surface (Lee & Cutkosky 1991; Lynch,
//! Maekawa & Tanie 1992; Lynch & Mason §3): at its centre of friction (COF), in the table frame
//! (the ellipsoid is isotropic in force), the small displacement it makes under a wrench
//! `(fx, fy, m)` is `s·(fx, fy, m/c²)` with `c` the limit surface's characteristic length and
//! `s = 1/(μ_s·m·g)`, so that objects moving together share the push in proportion to their
//! friction, as on the true limit surface. Contacts are Coulomb: the normal force is ≥ 0 and
//! only acts when the gap closes, the friction force stays within `μ` times the normal force,
//! and the contact sticks (no relative sliding) when it can. These complementarity conditions
//! (a linear complementarity problem) are solved by projected Gauss–Seidel on the contact
//! forces, on position-level constraints linearised about the step's start: the gap plus the
//! relative normal displacement stays ≥ 0 ("speculative" contacts closer than a prediction
//! distance take part too, so nothing tunnels).
//!
//! With one point contact this reproduces [`crate::pushing::point_push`] exactly (the force on
//! a cone edge when sliding, the sticking closed form otherwise). If no motion of the objects
//! can make room for the robot's commanded motion (an object wedged against a wall), the
//! robot's motion is scaled back to the largest feasible fraction: the robot stalls.

/// Which body a contact row acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyRef {
    /// The driven robot (moves as commanded, scaled by the step's feasible fraction).
    Robot,
    /// Object `k` (moves as the solve says).
    Object(usize),
    /// A wall or obstacle (never moves).
    Static,
}

/// A pushable body's state for the solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mobile {
    /// COF, table frame.
    pub cof: [f64; 2],
    /// Limit surface characteristic length, m.
    pub c: f64,
    /// Compliance `1/(μ_s·m·g)`, m/N (any positive scale; only ratios matter).
    pub s: f64,
}

/// A contact between two bodies (table frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// First body.
    pub a: BodyRef,
    /// Second body.
    pub b: BodyRef,
    /// Contact point on `a`.
    pub pa: [f64; 2],
    /// Contact point on `b`.
    pub pb: [f64; 2],
    /// Unit normal from `a` to `b`.
    pub n: [f64; 2],
    /// Gap along `n` at the step's start (negative: penetrating).
    pub gap: f64,
    /// Coulomb coefficient.
    pub mu: f64,
}

/// The robot's commanded small displacement: `(dx, dy)` of its centre `centre` and `dth`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Drive {
    /// Robot centre at the step's start.
    pub centre: [f64; 2],
    /// Displacement of the centre, m.
    pub d: [f64; 2],
    /// Rotation, rad.
    pub dth: f64,
}

impl Drive {
    fn at(&self, p: [f64; 2], scale: f64) -> [f64; 2] {
        let r = [p[0] - self.centre[0], p[1] - self.centre[1]];
        [
            scale * (self.d[0] - self.dth * r[1]),
            scale * (self.d[1] + self.dth * r[0]),
        ]
    }
}

/// The solve's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Fraction of the robot's commanded motion that happens (1: free; 0: fully blocked).
    pub scale: f64,
    /// Each object's COF displacement and rotation `(dx, dy, dth)`.
    pub moves: Vec<[f64; 3]>,
    /// Normal force (arbitrary units) of each row.
    pub normal: Vec<f64>,
    /// Friction force of each row (same units, along the normal turned +90°).
    pub tangent: Vec<f64>,
    /// Largest remaining violation of a linearised constraint, m.
    pub residual: f64,
}

const MAX_ITERS: usize = 300;
/// Iterations of a bisection probe (warm-started).
const PROBE_ITERS: usize = 100;
/// Bisection steps for a jammed robot's feasible fraction (2⁻¹⁰ of a step's motion).
const BISECTIONS: usize = 10;
const TOL: f64 = 1e-10;
/// A step is feasible when every linearised gap is closed to within this, m.
pub const FEASIBLE: f64 = 1e-10;
/// The solve keeps contacts this far apart (m), so that rounding never makes them overlap.
pub const SKIN: f64 = 1e-9;

/// The gap a contact must keep: [`SKIN`], or what it has if less (a contact that started
/// closer is not pushed apart, one that started overlapping is pushed out to touching).
fn target(gap: f64) -> f64 {
    gap.clamp(0.0, SKIN)
}

fn jac(m: &Mobile, p: [f64; 2], d: [f64; 2]) -> [f64; 3] {
    let r = [p[0] - m.cof[0], p[1] - m.cof[1]];
    [d[0], d[1], r[0] * d[1] - r[1] * d[0]]
}

fn weight(m: &Mobile, j: [f64; 3]) -> f64 {
    m.s * (j[0] * j[0] + j[1] * j[1] + j[2] * j[2] / (m.c * m.c))
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Solve with the robot's motion scaled by `scale`.
fn solve_at(
    mobiles: &[Mobile],
    rows: &[Row],
    drive: &Drive,
    scale: f64,
    warm: Option<&Solution>,
    max_iters: usize,
) -> Solution {
    let mut moves = vec![[0.0; 3]; mobiles.len()];
    let (mut ln, mut lt) = match warm {
        Some(w) => (w.normal.clone(), w.tangent.clone()),
        None => (vec![0.0; rows.len()], vec![0.0; rows.len()]),
    };
    // Per-row constants: each moving side's body, Jacobians and compliances, and the weights.
    // A side's relative motion along the normal (tangent) is the dot product of its Jacobian
    // with the body's displacement: `jac(m, p, d) · q` is `d` dotted with the displacement of the
    // body's point `p`.
    #[derive(Clone, Copy)]
    struct Side {
        k: usize,
        jn: [f64; 3],
        jt: [f64; 3],
        s: f64,
        s_c2: f64,
    }
    struct Pre {
        sides: [Option<Side>; 2],
        wn: f64,
        wt: f64,
        kin_n: f64,
        kin_t: f64,
    }
    let pre: Vec<Pre> = rows
        .iter()
        .map(|r| {
            let t = [-r.n[1], r.n[0]];
            let mut sides = [None, None];
            let (mut wn, mut wt, mut kin_n, mut kin_t) = (0.0, 0.0, 0.0, 0.0);
            for (side, (body, p, sign)) in [(r.a, r.pa, -1.0), (r.b, r.pb, 1.0)]
                .into_iter()
                .enumerate()
            {
                match body {
                    BodyRef::Object(k) => {
                        let m = &mobiles[k];
                        let jn = jac(m, p, r.n);
                        let jt = jac(m, p, t);
                        wn += weight(m, jn);
                        wt += weight(m, jt);
                        sides[side] = Some(Side {
                            k,
                            jn,
                            jt,
                            s: m.s,
                            s_c2: m.s / (m.c * m.c),
                        });
                    }
                    BodyRef::Robot => {
                        let u = drive.at(p, scale);
                        kin_n += sign * dot(r.n, u);
                        kin_t += sign * dot(t, u);
                    }
                    BodyRef::Static => {}
                }
            }
            Pre {
                sides,
                wn,
                wt,
                kin_n,
                kin_t,
            }
        })
        .collect();
    const SIGN: [f64; 2] = [-1.0, 1.0];
    let apply = |moves: &mut [[f64; 3]], p: &Pre, normal: bool, dl: f64| {
        for (side, sign) in p.sides.iter().zip(SIGN) {
            if let Some(b) = side {
                let j = if normal { b.jn } else { b.jt };
                let f = sign * dl;
                let q = &mut moves[b.k];
                q[0] += f * b.s * j[0];
                q[1] += f * b.s * j[1];
                q[2] += f * b.s_c2 * j[2];
            }
        }
    };
    let rel = |moves: &[[f64; 3]], p: &Pre, normal: bool| -> f64 {
        let mut g = 0.0;
        for (side, sign) in p.sides.iter().zip(SIGN) {
            if let Some(b) = side {
                let j = if normal { b.jn } else { b.jt };
                let q = &moves[b.k];
                g += sign * (j[0] * q[0] + j[1] * q[1] + j[2] * q[2]);
            }
        }
        g
    };
    if warm.is_some() {
        for (i, p) in pre.iter().enumerate() {
            apply(&mut moves, p, true, ln[i]);
            apply(&mut moves, p, false, lt[i]);
        }
    }
    let violation = |moves: &[[f64; 3]]| {
        rows.iter()
            .zip(&pre)
            .filter(|(_, p)| p.wn > 0.0)
            .map(|(r, p)| r.gap - target(r.gap) + p.kin_n + rel(moves, p, true))
            .fold(0.0f64, |m, g| m.max(-g))
    };
    let mut last_violation = f64::INFINITY;
    for it in 0..max_iters {
        let mut change = 0.0f64;
        for (i, r) in rows.iter().enumerate() {
            let p = &pre[i];
            if p.wn <= 0.0 {
                continue;
            }
            let g = r.gap - target(r.gap) + p.kin_n + rel(&moves, p, true);
            let new = (ln[i] - g / p.wn).max(0.0);
            let dl = new - ln[i];
            if dl != 0.0 {
                apply(&mut moves, p, true, dl);
                ln[i] = new;
                change = change.max((dl * p.wn).abs());
            }
            if r.mu > 0.0 && p.wt > 0.0 {
                let gt = p.kin_t + rel(&moves, p, false);
                let lim = r.mu * ln[i];
                let new = (lt[i] - gt / p.wt).clamp(-lim, lim);
                let dl = new - lt[i];
                if dl != 0.0 {
                    apply(&mut moves, p, false, dl);
                    lt[i] = new;
                    change = change.max((dl * p.wt).abs());
                }
            }
        }
        if change < TOL {
            break;
        }
        // A jam (no feasible motion) shows as a violation that stops shrinking: give up early
        // and let the caller cut the robot's motion back.
        if it % 16 == 15 {
            let v = violation(&moves);
            if v > FEASIBLE && v > 0.9 * last_violation {
                break;
            }
            last_violation = v;
        }
    }
    // Rows between the robot and a static body cannot be corrected by the solve: they only
    // must not get worse than they started.
    let mut residual = 0.0f64;
    for (i, r) in rows.iter().enumerate() {
        let g = r.gap + pre[i].kin_n + rel(&moves, &pre[i], true);
        let floor = if pre[i].wn > 0.0 {
            target(r.gap)
        } else {
            r.gap.min(0.0) - SKIN
        };
        residual = residual.max(floor - g);
    }
    Solution {
        scale,
        moves,
        normal: ln,
        tangent: lt,
        residual,
    }
}

/// Solve one step: the largest fraction (≤ 1) of the robot's commanded motion that the
/// objects can make room for, and the objects' displacements. `warm`: the forces of a
/// previous solve with the same rows (in the same order), to start from.
pub fn solve(mobiles: &[Mobile], rows: &[Row], drive: &Drive, warm: Option<&Solution>) -> Solution {
    let warm = warm.filter(|w| w.normal.len() == rows.len() && w.tangent.len() == rows.len());
    // The robot against static bodies: the largest fraction that keeps every gap open.
    let mut hi = 1.0f64;
    for r in rows {
        let (p, sign) = match (r.a, r.b) {
            (BodyRef::Robot, BodyRef::Static) => (r.pa, 1.0),
            (BodyRef::Static, BodyRef::Robot) => (r.pb, -1.0),
            _ => continue,
        };
        let approach = sign * dot(r.n, drive.at(p, 1.0));
        if approach > 0.0 {
            hi = hi.min((r.gap.max(0.0) / approach).max(0.0));
        }
    }
    let first = solve_at(mobiles, rows, drive, hi, warm, MAX_ITERS);
    if first.residual <= FEASIBLE || hi == 0.0 {
        return first;
    }
    // Jammed. A robot held against the same contacts as in the last step (`warm`, whose
    // rows are these) can mostly go as far as it could then: when that fraction is feasible
    // and one bisection step more is not, it is the answer bisection would narrow to.
    let step = hi / f64::from(1u32 << BISECTIONS);
    if let Some(w) = warm.filter(|w| w.scale < hi) {
        let at = solve_at(mobiles, rows, drive, w.scale, Some(w), PROBE_ITERS);
        if at.residual <= FEASIBLE {
            let above = solve_at(mobiles, rows, drive, w.scale + step, Some(&at), PROBE_ITERS);
            if above.residual > FEASIBLE {
                return at;
            }
        }
    }
    // Otherwise bisect for the largest feasible fraction (each probe warm-started from the
    // last feasible one). Standing still is feasible when nothing overlaps to begin with.
    let mut lo = 0.0;
    let mut best = solve_at(mobiles, rows, drive, 0.0, None, MAX_ITERS);
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        let s = solve_at(mobiles, rows, drive, mid, Some(&best), PROBE_ITERS);
        if s.residual <= FEASIBLE {
            lo = mid;
            best = s;
        } else {
            hi = mid;
        }
    }
    best
}
