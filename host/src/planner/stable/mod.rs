//! Planning stable pushing paths among obstacles: Lynch & Mason (1996) §4.
//!
//! A best-first search (§4.1) over slider configurations whose controls are the extremal stable
//! pushing directions of each pushing contact (STABLE, §3.3.1, intersected with what the pusher
//! can do, Fig. 14), integer costs `a·steps + b·control changes + c·contact changes` (§4.2.2)
//! kept in a bucketed OPEN list, pruning on a configuration grid per contact (§4.2.3), a goal
//! neighbourhood, MAXCOST and a node limit (§4.2.4). Beyond the paper: exact collision of
//! pusher + slider along every step ([`collision`]), transit paths for a mobile pusher between
//! contacts (§4.6's open problem, [`transit`]), and the exact-goal variant of §4.5, for wheeled
//! pushers too ([`exact`]).

pub mod collision;
pub mod exact;
pub mod no_plan;
pub mod presets;
pub mod pusher;
pub mod random_scene;
pub mod reach;
pub mod robot;
pub mod search;
pub mod svg;
pub mod transit;

use std::f64::consts::PI;

use crate::mechanics::stable::stable;
use crate::mechanics::{MechanicsError, Slider, V2, V3};
use collision::{Body, World};
use pusher::{Placement, Pusher, Usable};

pub use search::{Checks, Plan, Queue, plan, plan_checked, plan_with};

/// A slider configuration `(x, y, θ)` in the world frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Pose {
    /// x of the centre of friction (m).
    pub x: f64,
    /// y of the centre of friction (m).
    pub y: f64,
    /// Orientation (rad).
    pub theta: f64,
}

impl Pose {
    /// A pose.
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose { x, y, theta }
    }

    /// A slider-frame point in the world frame.
    pub fn apply(&self, p: V2) -> V2 {
        let (s, c) = self.theta.sin_cos();
        V2::new(self.x + c * p.x - s * p.y, self.y + s * p.x + c * p.y)
    }

    /// A slider-frame vector in the world frame.
    pub fn rotate(&self, v: V2) -> V2 {
        let (s, c) = self.theta.sin_cos();
        V2::new(c * v.x - s * v.y, s * v.x + c * v.y)
    }

    /// The pose reached by following the slider-frame twist `xi` for unit time
    /// (`q ∘ exp(ξ)`: a rotation about the fixed centre `COR(ξ)`, or a translation).
    pub fn integrate(&self, xi: &V3) -> Pose {
        match cor_of(xi) {
            Some(c) => {
                let phi = xi.z;
                let (s, co) = phi.sin_cos();
                let rc = V2::new(co * c.x - s * c.y, s * c.x + co * c.y);
                let d = self.rotate(c - rc);
                Pose::new(self.x + d.x, self.y + d.y, self.theta + phi)
            }
            None => {
                let d = self.rotate(V2::new(xi.x, xi.y));
                Pose::new(self.x + d.x, self.y + d.y, self.theta)
            }
        }
    }

    /// `self ∘ d`: the relative motion `d` (slider frame) applied at `self`, given
    /// `(sin θ, cos θ)` of `self`. Equals `self.integrate(ξ)` when `d = identity.integrate(ξ)`.
    pub fn compose(&self, d: &Pose, (s, c): (f64, f64)) -> Pose {
        Pose::new(
            self.x + c * d.x - s * d.y,
            self.y + s * d.x + c * d.y,
            self.theta + d.theta,
        )
    }

    /// The slider-frame twist `ξ` with `self.integrate(ξ) == other` and `|ω| ≤ π`: the single
    /// constant push between the two poses.
    pub fn twist_to(&self, other: &Pose) -> V3 {
        let (s, c) = self.theta.sin_cos();
        let (dx, dy) = (other.x - self.x, other.y - self.y);
        let d = V2::new(c * dx + s * dy, -s * dx + c * dy);
        let phi = angle_diff(other.theta, self.theta);
        if phi.abs() < 1e-12 {
            return V3::new(d.x, d.y, 0.0);
        }
        let (sp, cp) = phi.sin_cos();
        let det = 2.0 - 2.0 * cp;
        let cx = ((1.0 - cp) * d.x - sp * d.y) / det;
        let cy = (sp * d.x + (1.0 - cp) * d.y) / det;
        V3::new(phi * cy, -phi * cx, phi)
    }
}

/// The rotation centre of a twist (slider frame), `None` for a translation.
pub fn cor_of(xi: &V3) -> Option<V2> {
    crate::mechanics::cor(xi)
}

/// `a − b` wrapped into `(−π, π]`.
pub fn angle_diff(a: f64, b: f64) -> f64 {
    let d = wrap_2pi(a - b);
    if d > PI { d - 2.0 * PI } else { d }
}

/// `θ mod 2π` in `[0, 2π)`, bit for bit as `θ.rem_euclid(2π)`, which it calls only for angles
/// outside `(−2π, 2π)` (the planner's hot loop otherwise pays for `fmod`): `fmod` is exact, so
/// for `θ ∈ [0, 2π)` it returns `θ`, and for `θ ∈ (−2π, 0)` it returns `θ` and `rem_euclid`
/// adds `2π` (at `−2π` it returns `−0`, kept as is).
pub fn wrap_2pi(theta: f64) -> f64 {
    const TAU: f64 = 2.0 * PI;
    if (0.0..TAU).contains(&theta) {
        theta
    } else if theta > -TAU && theta < 0.0 {
        theta + TAU
    } else {
        theta.rem_euclid(TAU)
    }
}

/// Planner parameters (§4.2.2–4.2.4).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Params {
    /// Cost per push step.
    pub a: u32,
    /// Cost per control change.
    pub b: u32,
    /// Cost per contact change; `None` = ∞ (contact changes disallowed).
    pub c: Option<u32>,
    /// Step length: the largest distance a slider vertex moves in one step (m).
    pub step: f64,
    /// Pruning grid cell size in x and y (m).
    pub grid_xy: f64,
    /// Pruning grid cell size in θ (rad).
    pub grid_theta: f64,
    /// Half-width of the goal neighbourhood in x and y (m).
    pub goal_xy: f64,
    /// Half-width of the goal neighbourhood in θ (rad).
    pub goal_theta: f64,
    /// MAXCOST.
    pub max_cost: u32,
    /// Node limit: configurations expanded before giving up.
    pub max_nodes: usize,
    /// Within this distance of the goal position, step and grid are refined (§4.5); 0 = off.
    pub fine_radius: f64,
    /// Refinement factor (≥ 1) for step and grid cells near the goal.
    pub fine_factor: f64,
    /// Weight `w ≥ 1` of the A* bound in OPEN's order (`g + w·h`): 1 is A* (the plan the
    /// search would find with an exact order); above 1 the search expands fewer
    /// configurations and may return a plan costing up to `w` times more.
    pub weight: f64,
}

/// One pushing contact the planner may use: an edge, the pusher placed on it, its usable pushes
/// and the body `PS` (slider + pusher) it moves.
#[derive(Debug, Clone)]
pub struct ContactModel {
    /// Slider edge index (edges of the counter-clockwise [`Slider`]).
    pub edge: usize,
    /// The edge's number as the scene gives it: `edge`, unless the outline was given clockwise
    /// and stored counter-clockwise (then the scene's edge `i` is `edge` `n − 1 − i`). Plans
    /// and messages name edges by it.
    pub label: usize,
    /// The pusher's placement on the edge.
    pub placement: Placement,
    /// Stable ∩ pusher-feasible pushes.
    pub usable: Usable,
    /// Slider + pusher footprint, slider frame.
    pub body: Body,
    /// Pusher footprint in the slider frame (empty for negligible pushers).
    pub footprint: Vec<V2>,
    /// Step twists: control `k` scaled to one step.
    pub steps: Vec<V3>,
    /// Step twists near the goal (refined step, §4.5).
    pub fine_steps: Vec<V3>,
    /// Swept shapes of `body` under `steps`.
    pub swept: Vec<collision::Swept>,
    /// Swept shapes of `body` under `fine_steps`.
    pub fine_swept: Vec<collision::Swept>,
    /// The relative motion of each step, `exp(step)`.
    pub deltas: Vec<Pose>,
    /// The relative motion of each fine step.
    pub fine_deltas: Vec<Pose>,
    /// `(sin, cos)` of each step's rotation.
    pub delta_sc: Vec<(f64, f64)>,
    /// `(sin, cos)` of each fine step's rotation.
    pub fine_delta_sc: Vec<(f64, f64)>,
}

/// A stable-pushing planning problem.
#[derive(Debug, Clone)]
pub struct Problem {
    /// Table, walls and obstacles.
    pub world: World,
    /// The slider (slider frame at its centre of friction).
    pub slider: Slider,
    /// Pusher–slider friction coefficient.
    pub mu: f64,
    /// The pusher.
    pub pusher: Pusher,
    /// The contacts the pusher may use.
    pub contacts: Vec<ContactModel>,
    /// Start configuration.
    pub start: Pose,
    /// Goal configuration.
    pub goal: Pose,
    /// Parameters.
    pub params: Params,
    /// Contact (index into `contacts`) the pusher starts at; `None`: any, for free.
    pub start_contact: Option<usize>,
}

impl Problem {
    /// The same problem with pusher–slider friction `mu`: STABLE run again on every contact's
    /// edge (labels and start contact kept); `None` when an edge then has no usable push.
    pub fn with_mu(&self, mu: f64) -> Option<Problem> {
        let edges: Vec<usize> = self.contacts.iter().map(|c| c.edge).collect();
        let mut q = Problem::new(
            self.world.clone(),
            self.slider.clone(),
            mu,
            self.pusher.clone(),
            &edges,
            self.start,
            self.goal,
            self.params.clone(),
        )
        .ok()?;
        if q.contacts.iter().any(|c| c.usable.controls.is_empty()) {
            return None;
        }
        for (a, b) in q.contacts.iter_mut().zip(&self.contacts) {
            a.label = b.label;
        }
        q.start_contact = self.start_contact;
        Some(q)
    }

    /// Build a problem: run STABLE on each listed edge, intersect with the pusher's feasible
    /// pushes, scale the extremal directions to one step.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        world: World,
        slider: Slider,
        mu: f64,
        pusher: Pusher,
        edges: &[usize],
        start: Pose,
        goal: Pose,
        params: Params,
    ) -> Result<Self, MechanicsError> {
        let mut contacts = Vec::new();
        for &e in edges {
            let placement = pusher.placement(&slider, e)?;
            let st = stable(&slider, &placement.contact, mu)?;
            let usable = pusher.usable(&st, &placement);
            let footprint: Vec<V2> = pusher
                .footprint
                .iter()
                .map(|p| placement.to_slider(*p))
                .collect();
            // The slider exactly: a concave one as its convex parts, not its hull.
            let mut parts: Vec<Vec<V2>> = collision::Obstacle::parts(&slider.vertices)
                .map(|ps| ps.into_iter().map(|o| o.vertices).collect())
                .unwrap_or_else(|| vec![slider.vertices.clone()]);
            if !footprint.is_empty() {
                parts.push(footprint.clone());
            }
            let body = Body::new(&parts);
            let steps = usable
                .controls
                .iter()
                .map(|v| step_twist(&slider, v, params.step))
                .collect();
            let fine = params.step / params.fine_factor.max(1.0);
            let fine_steps: Vec<V3> = usable
                .controls
                .iter()
                .map(|v| step_twist(&slider, v, fine))
                .collect();
            let steps: Vec<V3> = steps;
            let swept = steps.iter().map(|xi| body.swept(xi)).collect();
            let fine_swept = fine_steps.iter().map(|xi| body.swept(xi)).collect();
            let origin = Pose::new(0.0, 0.0, 0.0);
            let deltas: Vec<Pose> = steps.iter().map(|xi| origin.integrate(xi)).collect();
            let fine_deltas: Vec<Pose> = fine_steps.iter().map(|xi| origin.integrate(xi)).collect();
            let delta_sc = deltas.iter().map(|d: &Pose| d.theta.sin_cos()).collect();
            let fine_delta_sc = fine_deltas.iter().map(|d| d.theta.sin_cos()).collect();
            contacts.push(ContactModel {
                edge: e,
                label: e,
                placement,
                usable,
                body,
                footprint,
                steps,
                fine_steps,
                swept,
                fine_swept,
                deltas,
                fine_deltas,
                delta_sc,
                fine_delta_sc,
            });
        }
        Ok(Problem {
            world,
            slider,
            mu,
            pusher,
            contacts,
            start,
            goal,
            params,
            start_contact: None,
        })
    }

    /// Whether `q` is in the refined region around the goal (§4.5).
    pub fn near_goal(&self, q: &Pose) -> bool {
        let (dx, dy) = (q.x - self.goal.x, q.y - self.goal.y);
        self.params.fine_factor > 1.0
            && dx * dx + dy * dy <= self.params.fine_radius * self.params.fine_radius
    }

    /// The step twists of contact `ci` at configuration `q`.
    pub fn steps_at(&self, ci: usize, q: &Pose) -> &[V3] {
        let cm = &self.contacts[ci];
        if self.near_goal(q) {
            &cm.fine_steps
        } else {
            &cm.steps
        }
    }

    /// The step twists of contact `ci` at `q`, their swept shapes and relative motions.
    pub fn steps_swept_at(&self, ci: usize, q: &Pose) -> (&[V3], &[collision::Swept], &[Pose]) {
        let cm = &self.contacts[ci];
        if self.near_goal(q) {
            (&cm.fine_steps, &cm.fine_swept, &cm.fine_deltas)
        } else {
            (&cm.steps, &cm.swept, &cm.deltas)
        }
    }

    /// The longest path any slider vertex takes under the motion `xi` (the measure of a
    /// step's length, [`step_twist`]).
    pub fn slider_reach(&self, xi: &V3) -> f64 {
        let unit = step_twist(&self.slider, xi, 1.0);
        xi.norm() / unit.norm()
    }

    /// Whether `q` is in the goal neighbourhood.
    pub fn in_goal(&self, q: &Pose) -> bool {
        (q.x - self.goal.x).abs() <= self.params.goal_xy
            && (q.y - self.goal.y).abs() <= self.params.goal_xy
            && angle_diff(q.theta, self.goal.theta).abs() <= self.params.goal_theta
    }
}

/// Scale a unit velocity direction so that no slider vertex moves farther than `step` along
/// its arc.
pub fn step_twist(slider: &Slider, v: &V3, step: f64) -> V3 {
    match cor_of(v) {
        Some(c) => {
            let rho = slider
                .vertices
                .iter()
                .map(|p| (p - c).norm())
                .fold(0.0, f64::max);
            v * (step / rho / v.z.abs())
        }
        None => v * (step / (v.x * v.x + v.y * v.y).sqrt()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn less_friction_narrows_every_contacts_turns() {
        // The closed loop re-plans with less pusher friction after the plate slid: STABLE run
        // again must give each contact turns no tighter than before, tighter somewhere
        // narrower, and keep the contacts' labels and order.
        let tightest = |p: &Problem| -> Vec<f64> {
            p.contacts
                .iter()
                .map(|c| {
                    c.usable
                        .controls
                        .iter()
                        .map(|v| v.z.abs() / v.x.hypot(v.y).max(1e-12))
                        .fold(0.0, f64::max)
                })
                .collect()
        };
        let mut narrower = 0;
        for seed in 1..=5 {
            let p = random_scene::random_scene(seed, random_scene::RandomPusher::DiffDrive)
                .unwrap()
                .problem()
                .unwrap();
            let q = p
                .with_mu(p.mu * 0.6)
                .expect("usable pushes with less friction");
            assert_eq!(q.mu, p.mu * 0.6);
            let labels = |p: &Problem| {
                p.contacts
                    .iter()
                    .map(|c| (c.edge, c.label))
                    .collect::<Vec<_>>()
            };
            assert_eq!(labels(&q), labels(&p));
            assert_eq!(q.start_contact, p.start_contact);
            for (a, b) in tightest(&q).into_iter().zip(tightest(&p)) {
                assert!(a <= b + 1e-9, "tighter with less friction: {a} > {b}");
                narrower += usize::from(a < b - 1e-6);
            }
        }
        assert!(narrower > 0);
    }

    #[test]
    fn integrate_and_twist_to_round_trip() {
        let q = Pose::new(1.0, 2.0, 0.3);
        for xi in [
            V3::new(0.2, 0.5, 0.0),
            V3::new(0.1, 0.3, 0.4),
            V3::new(-0.3, 0.2, -1.2),
        ] {
            let r = q.integrate(&xi);
            let back = q.twist_to(&r);
            assert!((back - xi).norm() < 1e-9, "{back:?} vs {xi:?}");
        }
        // Rotation about the centre of friction by π/2 keeps the position.
        let r = q.integrate(&V3::new(0.0, 0.0, PI / 2.0));
        assert!((r.x - 1.0).abs() < 1e-12 && (r.y - 2.0).abs() < 1e-12);
    }

    #[test]
    fn wrap_2pi_is_rem_euclid_bit_for_bit() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let edges = [0.0, -0.0, 2.0 * PI, -2.0 * PI, PI, -PI, 1e-300, -1e-300];
        let mut samples: Vec<f64> = edges.to_vec();
        samples.extend(edges.iter().map(|e| f64::from_bits(e.to_bits() + 1)));
        samples.extend((0..100_000).map(|_| (next() - 0.5) * 40.0));
        for t in samples {
            assert_eq!(
                wrap_2pi(t).to_bits(),
                t.rem_euclid(2.0 * PI).to_bits(),
                "{t:e}"
            );
        }
    }
}
