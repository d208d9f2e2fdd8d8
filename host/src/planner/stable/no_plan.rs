//! Why the stable-push planner found no plan. Lynch & Mason (1996) §4.2.4 end a search at the
//! goal neighbourhood, at MAXCOST or at the node limit; a user needs to hear which, and what in
//! the scene stands in the way: the goal cut off from the start ([`super::reach`]), the goal
//! itself blocked, no push possible from the start, the node or cost budget spent (and the
//! option that raises it), a pusher that cannot turn the slider as tightly as the task needs
//! (no plan even on the table without its obstacles), or every reachable configuration
//! explored, with the closest approach to the goal and what blocks the pushes there.
//!
//! Each reason is decided from the search's own trace ([`super::search::SearchTrace`]) and
//! from collision tests against the scene's obstacles one at a time, so the obstacles it names
//! are the ones the pushes actually meet.

use std::fmt;

use super::collision::{Body, World};
use super::reach::{Unreachable, unreachable};
use super::search::{Plan, SearchEnd, plan};
use super::{Pose, Problem, angle_diff};

/// Where a failed search came closest to the goal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// The configuration.
    pub pose: Pose,
    /// Its distance from the goal position, m.
    pub distance_m: f64,
    /// Its angle from the goal heading, degrees (absolute).
    pub angle_deg: f64,
}

impl fmt::Display for Closest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the closest approach was {:.0} mm and {:.0}° from the goal, at ({:.3}, {:.3}, {:.0}°)",
            self.distance_m * 1e3,
            self.angle_deg,
            self.pose.x,
            self.pose.y,
            self.pose.theta.to_degrees()
        )
    }
}

/// Why a stable-push plan was not found.
#[derive(Debug, Clone, PartialEq)]
pub enum NoPlan {
    /// Obstacles and walls separate the start from the goal, whatever the pusher.
    Unreachable(Unreachable),
    /// At the goal the slider overlaps these obstacles (with the pusher on any contact too).
    GoalBlocked {
        /// Their names.
        blockers: Vec<String>,
    },
    /// No push can start: for each contact (its edge as the scene numbers it), what its first
    /// pushes meet at the start.
    StartBlocked {
        /// `(edge, names)` per contact.
        contacts: Vec<(usize, Vec<String>)>,
    },
    /// The search expanded its budget of configurations.
    NodeLimit {
        /// The budget (`planner.max_nodes`).
        nodes: usize,
        /// Where it came closest.
        closest: Option<Closest>,
    },
    /// Every sequence left would cost more than MAXCOST.
    CostLimit {
        /// The limit (`planner.max_cost`).
        max_cost: u32,
        /// Configurations expanded.
        nodes: usize,
        /// Where it came closest.
        closest: Option<Closest>,
    },
    /// Even on the table without its obstacles no plan exists: the stable pushes cannot turn
    /// the slider as tightly as the task needs within the table's edges.
    TurnsTooWide {
        /// The tightest turn of the slider's centre under a stable push, m (∞: straight only).
        slider_radius_m: f64,
        /// A car's minimum turning radius, m.
        car_radius_m: Option<f64>,
        /// Where the search (with the obstacles) came closest.
        closest: Option<Closest>,
    },
    /// Every configuration the grid lets the search reach was expanded.
    Exhausted {
        /// Configurations expanded.
        nodes: usize,
        /// Where it came closest.
        closest: Option<Closest>,
        /// What the pushes from there meet.
        blockers: Vec<String>,
        /// Contact changes dropped for want of a transit path of the pusher.
        no_transit: u64,
    },
}

fn list(names: &[String]) -> String {
    match names {
        [] => "nothing".to_string(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

fn closest_sentence(c: &Option<Closest>) -> String {
    c.as_ref().map_or_else(String::new, |c| format!("; {c}"))
}

impl fmt::Display for NoPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NoPlan::Unreachable(u) => write!(f, "{u}"),
            NoPlan::GoalBlocked { blockers } => write!(
                f,
                "the goal is blocked: there the slider overlaps {}",
                list(blockers)
            ),
            NoPlan::StartBlocked { contacts } => {
                let per: Vec<String> = contacts
                    .iter()
                    .map(|(edge, names)| format!("on edge {edge} it meets {}", list(names)))
                    .collect();
                write!(
                    f,
                    "the start contact is unreachable: no push can start from the start \
                     configuration ({})",
                    per.join("; ")
                )
            }
            NoPlan::NodeLimit { nodes, closest } => write!(
                f,
                "the search spent its budget of {nodes} configurations without reaching the \
                 goal{}; raise it with --max-nodes (or planner.max_nodes in the scene's \
                 [stable] section)",
                closest_sentence(closest)
            ),
            NoPlan::CostLimit {
                max_cost,
                nodes,
                closest,
            } => write!(
                f,
                "every push sequence left would cost more than the limit of {max_cost} (after \
                 {nodes} configurations){}; raise it with --max-cost (or planner.max_cost in \
                 the scene's [stable] section)",
                closest_sentence(closest)
            ),
            NoPlan::TurnsTooWide {
                slider_radius_m,
                car_radius_m,
                closest,
            } => {
                let car = car_radius_m.map_or_else(String::new, |r| {
                    format!("; the car turns no tighter than {:.0} mm", r * 1e3)
                });
                write!(
                    f,
                    "the pusher cannot turn as tightly as the task needs: even on the table \
                     without its obstacles no stable push sequence reaches the goal within the \
                     table's edges (the slider's tightest stable turn has a radius of {:.0} \
                     mm{car}){}",
                    slider_radius_m * 1e3,
                    closest_sentence(closest)
                )
            }
            NoPlan::Exhausted {
                nodes,
                closest,
                blockers,
                no_transit,
            } => {
                write!(
                    f,
                    "the search exhausted all {nodes} configurations it could reach without \
                     reaching the goal{}",
                    closest_sentence(closest)
                )?;
                if !blockers.is_empty() {
                    write!(f, "; there, the pushes meet {}", list(blockers))?;
                }
                if *no_transit > 0 {
                    write!(
                        f,
                        "; {no_transit} contact changes were dropped: the pusher found no way \
                         around the slider to the new contact"
                    )?;
                }
                Ok(())
            }
        }
    }
}

/// The obstacles of `world` (by name) that `body` overlaps at `q`.
fn overlapped(body: &Body, world: &World, q: &Pose) -> Vec<usize> {
    (0..world.obstacles.len())
        .filter(|&j| !body.free_at(&world.only(|i| i == j), q))
        .collect()
}

/// The obstacles that some push of contact `ci` from `q` meets.
fn met_by_pushes(p: &Problem, ci: usize, q: &Pose) -> Vec<usize> {
    let cm = &p.contacts[ci];
    let mut out: Vec<usize> = Vec::new();
    for xi in p.steps_at(ci, q) {
        if cm.body.step_free(&p.world, q, xi) {
            continue;
        }
        for j in 0..p.world.obstacles.len() {
            if !out.contains(&j) && !cm.body.step_free(&p.world.only(|i| i == j), q, xi) {
                out.push(j);
            }
        }
    }
    out.sort_unstable();
    out
}

/// What blocks every push of contact `ci` from `q`: the obstacles its body overlaps there, or
/// those its pushes meet; `None` if some push from there is free.
fn blocking_pushes(p: &Problem, ci: usize, q: &Pose) -> Option<Vec<usize>> {
    let cm = &p.contacts[ci];
    let at = overlapped(&cm.body, &p.world, q);
    if !at.is_empty() {
        return Some(at);
    }
    if p.steps_at(ci, q)
        .iter()
        .any(|xi| cm.body.step_free(&p.world, q, xi))
    {
        return None;
    }
    Some(met_by_pushes(p, ci, q))
}

/// The tightest turn of the slider's centre under any contact's stable pushes, m.
pub fn tightest_turn(p: &Problem) -> f64 {
    p.contacts
        .iter()
        .flat_map(|c| c.steps.iter())
        .filter(|xi| xi.z.abs() > 1e-12)
        .map(|xi| xi.x.hypot(xi.y) / xi.z.abs())
        .fold(f64::INFINITY, f64::min)
}

fn closest_of(p: &Problem, plan: &Plan) -> Option<Closest> {
    plan.search.closest.map(|(q, _)| Closest {
        pose: q,
        distance_m: (q.x - p.goal.x).hypot(q.y - p.goal.y),
        angle_deg: angle_diff(q.theta, p.goal.theta).abs().to_degrees(),
    })
}

/// The problem on the table without its obstacles (the walls kept).
pub fn without_obstacles(p: &Problem) -> Problem {
    let mut q = p.clone();
    q.world = p.world.only(|i| i < p.world.n_walls);
    q
}

/// Why `plan` (the planner's answer to `p`) is not a plan; `None` if it is one.
pub fn why(p: &Problem, plan_found: &Plan) -> Option<NoPlan> {
    if plan_found.found {
        return None;
    }
    let s = &plan_found.search;
    let closest = closest_of(p, plan_found);
    if s.ended == SearchEnd::Unreachable
        && let Some(u) = unreachable(p)
    {
        return Some(NoPlan::Unreachable(u));
    }
    // The goal: the slider there overlaps something, and so does the pusher on every contact.
    let slider = Body::new(std::slice::from_ref(&p.slider.vertices));
    let at_goal = overlapped(&slider, &p.world, &p.goal);
    if !at_goal.is_empty()
        && p.contacts
            .iter()
            .all(|c| !c.body.free_at(&p.world, &p.goal))
    {
        return Some(NoPlan::GoalBlocked {
            blockers: p.world.names_of(at_goal),
        });
    }
    if s.ended == SearchEnd::NodeLimit {
        return Some(NoPlan::NodeLimit {
            nodes: plan_found.nodes_expanded,
            closest,
        });
    }
    if plan_found.nodes_expanded <= 1 {
        let tried: Vec<usize> = match p.start_contact {
            Some(c) => vec![c],
            None => (0..p.contacts.len()).collect(),
        };
        let per: Option<Vec<(usize, Vec<String>)>> = tried
            .iter()
            .map(|&ci| {
                blocking_pushes(p, ci, &p.start)
                    .map(|b| (p.contacts[ci].label, p.world.names_of(b)))
            })
            .collect();
        if let Some(contacts) = per {
            return Some(NoPlan::StartBlocked { contacts });
        }
    }
    if s.cut_by_cost > 0 {
        return Some(NoPlan::CostLimit {
            max_cost: p.params.max_cost,
            nodes: plan_found.nodes_expanded,
            closest,
        });
    }
    if p.world.obstacles.len() > p.world.n_walls {
        let open = plan(&without_obstacles(p));
        if !open.found && open.search.ended == SearchEnd::Exhausted {
            return Some(NoPlan::TurnsTooWide {
                slider_radius_m: tightest_turn(p),
                car_radius_m: p.pusher.min_turning_radius(),
                closest,
            });
        }
    } else {
        return Some(NoPlan::TurnsTooWide {
            slider_radius_m: tightest_turn(p),
            car_radius_m: p.pusher.min_turning_radius(),
            closest,
        });
    }
    let blockers = closest.map_or_else(Vec::new, |c| {
        let mut all: Vec<usize> = Vec::new();
        for ci in 0..p.contacts.len() {
            for j in met_by_pushes(p, ci, &c.pose) {
                if !all.contains(&j) {
                    all.push(j);
                }
            }
        }
        all.sort_unstable();
        p.world.names_of(all)
    });
    Some(NoPlan::Exhausted {
        nodes: plan_found.nodes_expanded,
        closest,
        blockers,
        no_transit: s.no_transit,
    })
}
