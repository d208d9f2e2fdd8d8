//! Following the object's global path (Lau, Mitani & Igarashi §III-E: "execute the robot to
//! push the object along sub-goals of this path"). The sub-goal is not a fixed point reached in
//! turn but moves with the object: it is the point a look-ahead distance further along the
//! path than the object's projection on it (pure pursuit). Pushing towards it keeps the object
//! on the path and never asks it to come back for a sub-goal it passed beside, which is where
//! fixed sub-goals made the object's path loop. A pure function of the path and the object's
//! measured position; [`crate::exec::deliver_path`] pushes along it.

use nalgebra::Vector2;

/// Where the object is wanted next, for an object at a measured position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aim {
    /// The moving sub-goal: the look-ahead point on the path.
    pub subgoal: Vector2<f64>,
    /// The object's way still to go: its distance to the path plus the path after its
    /// projection, m. Falls as the object makes progress; a stall is measured on it.
    pub left: f64,
    /// The object's distance from the path, m.
    pub off_path: f64,
    /// The way along the path from the sub-goal to its end, m (0 once the sub-goal is the end).
    pub to_end: f64,
}

/// A path followed by pure pursuit, with the progress made along it so far.
#[derive(Debug, Clone)]
pub struct PathFollower {
    points: Vec<Vector2<f64>>,
    /// Arc length at each point.
    arc: Vec<f64>,
    /// Arc length of the object's last projection.
    at: f64,
    lookahead: f64,
    end_blend: f64,
}

/// How far behind its last projection the object's projection may fall, m (it was pushed
/// back), and how far ahead of it the projection is looked for: a path that doubles back past
/// a wall is not joined further on, on the wall's other side.
const BEHIND: f64 = 0.15;
const AHEAD: f64 = 0.4;

impl PathFollower {
    /// Follow `path` (at least one point) with a look-ahead of `lookahead` m.
    pub fn new(path: &[Vector2<f64>], lookahead: f64) -> Option<PathFollower> {
        let mut points: Vec<Vector2<f64>> = Vec::with_capacity(path.len());
        for &p in path {
            if points.last().is_none_or(|q| (p - q).norm() > 1e-9) {
                points.push(p);
            }
        }
        if points.is_empty() || !(lookahead.is_finite() && lookahead > 0.0) {
            return None;
        }
        let mut arc = vec![0.0];
        for w in points.windows(2) {
            arc.push(arc[arc.len() - 1] + (w[1] - w[0]).norm());
        }
        Some(PathFollower {
            points,
            arc,
            at: 0.0,
            lookahead,
            end_blend: 0.0,
        })
    }

    /// The same follower with an end blend of `blend` m ([`PathFollower::shifted`]); 0 (the
    /// default) shifts the end only once the sub-goal is the end itself.
    pub fn with_end_blend(self, blend: f64) -> PathFollower {
        PathFollower {
            end_blend: blend.max(0.0),
            ..self
        }
    }

    /// The sub-goal of `aim` moved by `shift`: in full once the sub-goal is the path's end,
    /// not at all while the end blend or more of the path lies beyond it, and in proportion
    /// between. The path is planned for one point of the object (its body's centre) but the
    /// goal is for another (its marker), `shift` from it: the point planned for is wanted at
    /// the goal plus `shift`, which turns as the object does. Shifting the last stretch
    /// gradually joins the path to that end without a turn where the sub-goal reaches it.
    pub fn shifted(&self, aim: &Aim, shift: Vector2<f64>) -> Vector2<f64> {
        let k = if self.end_blend > 0.0 {
            (1.0 - aim.to_end / self.end_blend).clamp(0.0, 1.0)
        } else if aim.to_end > 0.0 {
            0.0
        } else {
            1.0
        };
        aim.subgoal + shift * k
    }

    /// Length of the path, m.
    pub fn length(&self) -> f64 {
        self.arc[self.arc.len() - 1]
    }

    /// The path's end.
    pub fn end(&self) -> Vector2<f64> {
        self.points[self.points.len() - 1]
    }

    /// The point at arc length `s` (clamped to the path).
    pub fn point_at(&self, s: f64) -> Vector2<f64> {
        let s = s.clamp(0.0, self.length());
        let i = self
            .arc
            .partition_point(|&a| a <= s)
            .clamp(1, self.points.len())
            - 1;
        if i + 1 >= self.points.len() {
            return self.end();
        }
        let seg = self.arc[i + 1] - self.arc[i];
        let t = if seg > 0.0 {
            (s - self.arc[i]) / seg
        } else {
            0.0
        };
        self.points[i] + (self.points[i + 1] - self.points[i]) * t
    }

    /// Project `o` on the path near the progress so far and aim `lookahead` beyond it (less
    /// when the object is off the path, so that it comes back to it before the path turns).
    pub fn aim(&mut self, o: Vector2<f64>) -> Aim {
        let (lo, hi) = (self.at - BEHIND, self.at + AHEAD);
        let mut best = (f64::INFINITY, self.at);
        if self.points.len() == 1 {
            best = ((o - self.points[0]).norm(), 0.0);
        }
        for i in 0..self.points.len().saturating_sub(1) {
            let (s0, s1) = (self.arc[i], self.arc[i + 1]);
            if s1 < lo || s0 > hi {
                continue;
            }
            let (a, b) = (self.points[i], self.points[i + 1]);
            let ab = b - a;
            let t = ((o - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let s = (s0 + t * (s1 - s0)).clamp(lo.max(0.0), hi);
            let d = (self.point_at(s) - o).norm();
            if d < best.0 {
                best = (d, s);
            }
        }
        let (off_path, s) = best;
        self.at = s;
        let ahead = (self.lookahead - off_path).max(self.lookahead / 3.0);
        Aim {
            subgoal: self.point_at(s + ahead),
            to_end: (self.length() - s - ahead).max(0.0),
            left: off_path + (self.length() - s),
            off_path,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vector2<f64> {
        Vector2::new(x, y)
    }

    #[test]
    fn on_a_straight_path_it_aims_the_lookahead_ahead() {
        let mut f = PathFollower::new(&[v(0.0, 0.0), v(1.0, 0.0)], 0.1).unwrap();
        let a = f.aim(v(0.3, 0.0));
        assert!((a.subgoal - v(0.4, 0.0)).norm() < 1e-9, "{a:?}");
        assert!((a.left - 0.7).abs() < 1e-9);
        // Off the path by 4 cm: the aim comes closer, so the object returns to the path.
        let a = f.aim(v(0.5, 0.04));
        assert!((a.subgoal - v(0.56, 0.0)).norm() < 1e-9, "{a:?}");
        assert!((a.off_path - 0.04).abs() < 1e-9);
        assert!((a.left - 0.54).abs() < 1e-9);
        // Near the end the aim is the end.
        f.aim(v(0.8, 0.0));
        let a = f.aim(v(0.97, 0.0));
        assert_eq!(a.subgoal, v(1.0, 0.0));
        assert_eq!(a.to_end, 0.0);
    }

    /// The end is shifted in full at the end, not at all a blend or more before it, half way
    /// half; with no blend only at the end.
    #[test]
    fn the_shifted_end_blends_in_over_the_last_stretch() {
        let path = [v(0.0, 0.0), v(1.0, 0.0)];
        let mut f = PathFollower::new(&path, 0.1).unwrap().with_end_blend(0.2);
        let shift = v(0.0, 0.06);
        for (x, k) in [(0.5, 0.0), (0.7, 0.0), (0.8, 0.5), (0.95, 1.0)] {
            let a = f.aim(v(x, 0.0));
            let want = a.subgoal + shift * k;
            assert!((f.shifted(&a, shift) - want).norm() < 1e-9, "{x}: {a:?}");
        }
        let mut plain = PathFollower::new(&path, 0.1).unwrap();
        plain.aim(v(0.5, 0.0));
        let a = plain.aim(v(0.85, 0.0));
        assert_eq!(plain.shifted(&a, shift), a.subgoal);
        let a = plain.aim(v(0.95, 0.0));
        assert_eq!(plain.shifted(&a, shift), v(1.0, 0.06));
    }

    #[test]
    fn a_path_that_doubles_back_is_not_joined_on_its_far_side() {
        // Up one side of a wall (x = 0.5) and down the other: the far leg passes 10 cm from
        // the near one.
        let path = [v(0.45, 0.0), v(0.45, 1.0), v(0.55, 1.0), v(0.55, 0.0)];
        let mut f = PathFollower::new(&path, 0.1).unwrap();
        let a = f.aim(v(0.5, 0.2));
        // The nearest point overall is on either leg (5 cm); progress so far is at the start,
        // so the near leg is the one followed.
        assert!(a.subgoal.x < 0.5, "{a:?}");
        assert!(a.left > 1.9, "{a:?}");
        // Walking up the near leg the projection follows.
        for k in 1..=9 {
            let y = k as f64 * 0.1;
            let a = f.aim(v(0.46, y));
            assert!(a.subgoal.x < 0.5 || y > 0.85, "{y}: {a:?}");
        }
        // Round the top and down the far leg.
        f.aim(v(0.5, 1.0));
        let a = f.aim(v(0.55, 0.8));
        assert!(a.subgoal.x > 0.5 && a.subgoal.y < 0.8, "{a:?}");
    }

    #[test]
    fn point_at_walks_the_path_and_clamps() {
        let f = PathFollower::new(&[v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0)], 0.1).unwrap();
        assert_eq!(f.length(), 2.0);
        assert!((f.point_at(1.5) - v(1.0, 0.5)).norm() < 1e-12);
        assert_eq!(f.point_at(-1.0), v(0.0, 0.0));
        assert_eq!(f.point_at(9.0), v(1.0, 1.0));
        assert!(PathFollower::new(&[], 0.1).is_none());
        assert!(PathFollower::new(&[v(0.0, 0.0)], 0.0).is_none());
    }
}
