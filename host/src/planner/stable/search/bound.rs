//! The A* lower bound ([`Heuristic`]) on the cost still to pay to the goal neighbourhood: it
//! turns the best-first search of Lynch & Mason (1996) §4.1 into A* without changing what it
//! minimises.

use super::grid::floor;
use crate::mechanics::V2;
use crate::planner::stable::{ContactModel, Pose, Problem, angle_diff, cor_of};

/// An admissible lower bound on the cost still to pay from a configuration to the goal
/// neighbourhood: `a` times a lower bound on the number of push steps, plus `b` when a control
/// change is surely due. It turns the paper's best-first search (§4.1) into A* without
/// changing what it minimises.
///
/// Why the step count is a lower bound: a step of length `step` moves no slider vertex farther
/// than `step` along its arc, so the centre of friction (inside the convex hull of the
/// vertices, hence no farther from the rotation centre than some vertex) moves at most `step`.
/// Every step of a control turns the slider by the same angle, so no step turns it more than
/// the largest of the controls' step rotations (the problem's own steps, precomputed; at most
/// `step / R` with `R` = half the slider length, as every point has a vertex at least that far
/// away). Steps that start within `fine_radius` of the goal are `fine_factor` times shorter
/// (§4.5): after the last step that starts outside that disk the centre is still at least
/// `fine_radius − step` from the goal, and the goal box lies within `goal_xy·√2` of it. Fine
/// steps turn by their own (smaller) largest rotation, so the turning still to do is bounded
/// with the same split into fine and coarse steps (see [`Heuristic::steps`]).
///
/// The control-change term: a configuration reached with control `k` of a contact reaches the
/// goal neighbourhood without another control change only along the curve that repeating `k`
/// traces (a circle about the control's fixed rotation centre, or a ray; refined steps near
/// the goal follow the same curve). If that curve never enters the neighbourhood, at least one
/// more control change, costing `b`, is due ([`Heuristic::turns`]). Steps and control changes
/// are separate terms of the cost, so the sum is still a bound; and it is consistent: a step
/// that keeps the control stays on the curve, one that changes it pays `b`.
#[derive(Debug, Clone)]
pub struct Heuristic {
    a: u32,
    b: u32,
    /// Per contact, per control: its curve in the slider frame.
    curves: Vec<Vec<Curve>>,
    step: f64,
    fine_step: f64,
    fine_radius: f64,
    /// Fine steps needed after the last coarse step.
    fine_tail: f64,
    /// Largest rotation of one (coarse) step.
    turn: f64,
    goal: Pose,
    goal_xy: f64,
    goal_theta: f64,
    /// Largest rotation of one fine step.
    turn_fine: f64,
    /// Reciprocals of `step`, `fine_step`, `turn` and `turn_fine` (see [`Heuristic::quick`]).
    inv: [f64; 4],
}

impl Heuristic {
    /// The bound for problem `p`.
    pub fn new(p: &Problem) -> Self {
        let pa = &p.params;
        let fine_on = pa.fine_factor > 1.0 && pa.fine_radius > 0.0;
        let fine_step = if fine_on {
            pa.step / pa.fine_factor
        } else {
            pa.step
        };
        let fine_radius = if fine_on { pa.fine_radius } else { 0.0 };
        let fine_tail = if fine_on {
            ((fine_radius - pa.step - pa.goal_xy * std::f64::consts::SQRT_2) / fine_step).max(0.0)
        } else {
            0.0
        };
        let half_len = p.slider.length() / 2.0;
        let turn_any = if half_len > 0.0 {
            pa.step / half_len
        } else {
            f64::INFINITY
        };
        // The largest rotation of one step of any control (each bounded by `turn_any`);
        // kept above 0 so that "cannot turn" reads as an unreachable heading, not a NaN.
        let max_turn = |deltas: fn(&ContactModel) -> &[Pose], cap: f64| {
            p.contacts
                .iter()
                .flat_map(|cm| deltas(cm).iter())
                .map(|d| d.theta.abs())
                .fold(0.0f64, f64::max)
                .min(cap)
                .max(1e-12)
        };
        let turn = max_turn(|cm| &cm.deltas, turn_any);
        let turn_fine = if fine_on {
            max_turn(|cm| &cm.fine_deltas, turn_any * fine_step / pa.step)
        } else {
            turn
        };
        let (sg, cg) = p.goal.theta.sin_cos();
        let curves = p
            .contacts
            .iter()
            .map(|cm| {
                cm.steps
                    .iter()
                    .map(|xi| match cor_of(xi) {
                        Some(c) => Curve::Turn {
                            cor: c,
                            cor_at_goal: V2::new(cg * c.x - sg * c.y, sg * c.x + cg * c.y),
                            radius: c.norm(),
                        },
                        None => Curve::Line {
                            dir: V2::new(xi.x, xi.y),
                        },
                    })
                    .collect()
            })
            .collect();
        Heuristic {
            a: pa.a,
            b: pa.b,
            curves,
            step: pa.step,
            fine_step,
            fine_radius,
            fine_tail,
            turn,
            goal: p.goal,
            goal_xy: pa.goal_xy,
            goal_theta: pa.goal_theta,
            turn_fine,
            inv: [pa.step, fine_step, turn, turn_fine].map(|v| 1.0 / v),
        }
    }

    /// A lower bound on the number of push steps from `q` to the goal neighbourhood.
    ///
    /// Distance and turning are bounded together per case: inside the refined disk either
    /// every remaining step is fine (`fine_factor` times shorter, turning that much less), or
    /// the path leaves the disk and comes back, which takes at least `A` fine steps (out and
    /// the tail in) and the rest of the turning at the coarse rate; outside the disk the
    /// path ends with at least the fine tail.
    pub fn steps(&self, q: &Pose) -> u32 {
        ceil_bound(self.raw::<true>(q))
    }

    /// [`Heuristic::steps`], bit for bit, multiplying by reciprocals instead of dividing; the
    /// few configurations whose bound lands within `1e-7` of an integer (where the two
    /// roundings could differ) are recomputed with the divisions.
    pub(super) fn quick(&self, q: &Pose) -> u32 {
        let v = shrink(self.raw::<false>(q));
        let t = floor(v);
        let fr = v - t as f64;
        if v.abs() < 1e6 && fr > 1e-7 && fr < 1.0 - 1e-7 {
            // Not an integer: its ceiling is `t + 1`, and it is positive unless `t < 0`.
            (t + 1).clamp(0, i64::from(u32::MAX)) as u32
        } else {
            self.steps(q)
        }
    }

    /// The bound before rounding; `EXACT`: divide, else multiply by the reciprocals (the same
    /// to a few units in the last place).
    #[inline(always)]
    fn raw<const EXACT: bool>(&self, q: &Pose) -> f64 {
        // `x / d`, `d` being `step`, `fine_step`, `turn` or `turn_fine` (index `i`).
        let div = |x: f64, d: f64, i: usize| if EXACT { x / d } else { x * self.inv[i] };
        let (dx, dy) = ((q.x - self.goal.x).abs(), (q.y - self.goal.y).abs());
        let (bx, by) = ((dx - self.goal_xy).max(0.0), (dy - self.goal_xy).max(0.0));
        let d_box = (bx * bx + by * by).sqrt();
        let d_centre = (dx * dx + dy * dy).sqrt();
        let turn = (angle_diff(q.theta, self.goal.theta).abs() - self.goal_theta).max(0.0);
        let turn_fine = self.turn_fine;
        // Steps when `n_f` of them are fine and the rest of the turning is coarse.
        let mixed = |n_f: f64| n_f + div(turn - n_f * turn_fine, self.turn, 2).max(0.0);
        if self.fine_radius <= 0.0 {
            div(d_box, self.step, 0).max(div(turn, self.turn, 2))
        } else if d_centre > self.fine_radius {
            let tail = self.fine_tail;
            (tail + div(d_box - tail * self.fine_step, self.step, 0).max(0.0)).max(mixed(tail))
        } else {
            let all_fine = div(d_box, self.fine_step, 1).max(div(turn, turn_fine, 3));
            let out_and_back = div(self.fine_radius - d_centre, self.fine_step, 1) + self.fine_tail;
            all_fine.min(out_and_back.max(mixed(out_and_back)))
        }
    }

    /// The lower bound on the remaining cost: `a · steps`.
    pub fn cost(&self, steps: u32) -> u32 {
        self.a.saturating_mul(steps)
    }

    /// Whether a configuration `q` (with `(sin θ, cos θ)` = `sc`) reached with control
    /// `control` of contact `contact` needs at least one more control change: repeating the
    /// control traces a curve that never enters the goal neighbourhood (tested with a margin,
    /// so it errs towards `false`).
    pub fn turns(&self, q: &Pose, (s, c): (f64, f64), contact: usize, control: usize) -> bool {
        const EPS: f64 = 1e-9;
        let Some(curve) = self.curves.get(contact).and_then(|v| v.get(control)) else {
            return false;
        };
        let (gx, gy, r) = (self.goal.x, self.goal.y, self.goal_xy);
        match *curve {
            Curve::Turn {
                cor,
                cor_at_goal,
                radius,
            } => {
                // On the circle about the world rotation centre `q.apply(cor)`, the pose with
                // the goal's heading is `m = q + R(θ)·cor − R(θ_goal)·cor`; poses with a
                // heading within `goal_theta` of it lie within `radius·goal_theta` of `m`.
                let mx = q.x + c * cor.x - s * cor.y - cor_at_goal.x;
                let my = q.y + s * cor.x + c * cor.y - cor_at_goal.y;
                let dx = ((mx - gx).abs() - r).max(0.0);
                let dy = ((my - gy).abs() - r).max(0.0);
                let tol = radius * self.goal_theta + EPS;
                dx * dx + dy * dy > tol * tol
            }
            Curve::Line { dir } => {
                if angle_diff(q.theta, self.goal.theta).abs() > self.goal_theta + EPS {
                    return true;
                }
                // Slab test of the ray `q + t·d`, t ≥ 0, against the goal box.
                let d = V2::new(c * dir.x - s * dir.y, s * dir.x + c * dir.y);
                let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
                for (o, d, g) in [(q.x, d.x, gx), (q.y, d.y, gy)] {
                    let (lo, hi) = (g - r - EPS, g + r + EPS);
                    if d.abs() < 1e-15 {
                        if o < lo || o > hi {
                            return true;
                        }
                    } else {
                        let (a, b) = ((lo - o) / d, (hi - o) / d);
                        t0 = t0.max(a.min(b));
                        t1 = t1.min(a.max(b));
                    }
                }
                t0 > t1
            }
        }
    }

    /// The control-change term of the bound: `b` if [`Heuristic::turns`], else 0.
    pub(super) fn turn_cost(
        &self,
        q: &Pose,
        sc: (f64, f64),
        contact: usize,
        control: usize,
    ) -> u32 {
        if self.b > 0 && self.turns(q, sc, contact, control) {
            self.b
        } else {
            0
        }
    }
}

/// The curve a control traces when repeated.
#[derive(Debug, Clone, Copy)]
enum Curve {
    /// A rotation about `cor` (slider frame); `cor_at_goal` is `cor` rotated by the goal's
    /// heading; `radius = |cor|`.
    Turn {
        cor: V2,
        cor_at_goal: V2,
        radius: f64,
    },
    /// A translation along `dir` (slider frame).
    Line { dir: V2 },
}

/// A bound `n` less a little for rounding errors: rounded up, it is a bound, never more.
fn shrink(n: f64) -> f64 {
    n * (1.0 - 1e-9) - 1e-9
}

/// `shrink(n).ceil()` as a step count (at least 0), without the libm call: truncate, then
/// round up.
fn ceil_bound(n: f64) -> u32 {
    let v = shrink(n);
    let t = v as i64;
    let t = if (t as f64) < v {
        t.saturating_add(1)
    } else {
        t
    };
    t.clamp(0, i64::from(u32::MAX)) as u32
}
