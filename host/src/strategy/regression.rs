//! Object delivery by kernel regression over the pushing strategy: Lau, Mitani & Igarashi
//! §III-E, Algorithm 2.
//!
//! General case: given the robot's position p and the wanted object motion s (the goal
//! direction scaled by `offset`, both in the object's frame), take the k samples nearest in
//! (p_x, p_y, s_x, s_y) and return the Gaussian-weighted mean of their robot motions r.
//! Special case (the last push moved the object away from the goal): the k samples nearest in
//! (s_x, s_y) alone give both where the robot should stand (p) and how it should push (r).
//! Beyond the paper, the special case also asks that the object not turn: its key is
//! (s_x, s_y, w·θ) queried at θ = 0 ([`KernelParams::turn_weight`] w, 3 cm a radian by
//! default; 0 is the paper). An elongated object (the snake) is turned 0.26 rad by the
//! average push of its collection, and where the paper's average re-positions the robot for a
//! push that swings it, the next pushes swing it further and the robot re-positions again —
//! 40 times in a trial that then runs out of time.
//!
//! Nearest neighbours come from `kiddo` k-d trees, so a query stays fast at 100 000 samples;
//! samples added during delivery (the paper's supplemental samples, used at once) are searched
//! linearly until enough of them gather to rebuild the trees.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use super::sample::Sample;

/// Parameters of the regression.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KernelParams {
    /// Neighbours used (the paper: 5).
    pub k: usize,
    /// Gaussian kernel width K_w, metres (the paper: 8 px ≈ 1.8 cm).
    pub kernel_width: f64,
    /// How much the special case prefers pushes that do not turn the object, metres of object
    /// motion a radian of turn weighs (0: the paper, which keys on the motion alone).
    pub turn_weight: f64,
}

impl Default for KernelParams {
    fn default() -> Self {
        KernelParams {
            k: 5,
            kernel_width: 0.018,
            turn_weight: TURN_WEIGHT,
        }
    }
}

/// The special case's answer: where to stand and how to push, object frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reposition {
    /// Robot position to push from.
    pub p: [f64; 2],
    /// Robot motion of the push.
    pub r: [f64; 2],
}

/// Which pushes [`PushStrategy::offer`] keeps: only those that teach the strategy something
/// (selective sampling). A push is informative when its (p, s) lies farther than
/// `novel_distance` from every sample (a region the strategy has not seen), or when the robot
/// motion the strategy answers at its (p, s) points more than `surprise` away from the robot
/// motion that really produced s (the strategy is wrong there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Admission {
    /// Distance in (p_x, p_y, s_x, s_y) beyond which a push is new, m.
    pub novel_distance: f64,
    /// Angle between the answered and the real robot motion beyond which a push is a surprise,
    /// rad.
    pub surprise: f64,
}

impl Default for Admission {
    fn default() -> Self {
        Admission {
            novel_distance: 0.01,
            surprise: 20f64.to_radians(),
        }
    }
}

/// The special case's default [`KernelParams::turn_weight`], m/rad.
pub const TURN_WEIGHT: f64 = 0.03;

/// Samples added since the trees were built are searched linearly up to this many.
const REBUILD_AFTER: usize = 256;

/// A pushing strategy ready for queries.
pub struct PushStrategy {
    samples: Vec<Sample>,
    params: KernelParams,
    /// Over (p_x, p_y, s_x, s_y) of `samples[..indexed]`.
    general: Option<ImmutableKdTree<f64, 4>>,
    /// Over (s_x, s_y, turn_weight·θ) of `samples[..indexed]`.
    special: Option<ImmutableKdTree<f64, 3>>,
    indexed: usize,
    s_len_sum: f64,
    admission: Option<Admission>,
}

fn general_key(s: &Sample) -> [f64; 4] {
    [s.p[0], s.p[1], s.s[0], s.s[1]]
}

/// The special case's key of `s` with `turn_weight` (see [`KernelParams::turn_weight`]).
fn special_key(s: &Sample, turn_weight: f64) -> [f64; 3] {
    [s.s[0], s.s[1], turn_weight * s.theta]
}

fn dist2<const K: usize>(a: &[f64; K], b: &[f64; K]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

impl PushStrategy {
    /// Index `samples` (non-finite samples are skipped).
    pub fn new(samples: impl IntoIterator<Item = Sample>, params: KernelParams) -> Self {
        let samples: Vec<Sample> = samples.into_iter().filter(Sample::is_finite).collect();
        let mut s = PushStrategy {
            s_len_sum: samples.iter().map(Sample::s_len).sum(),
            samples,
            params,
            general: None,
            special: None,
            indexed: 0,
            admission: None,
        };
        s.rebuild();
        s
    }

    fn rebuild(&mut self) {
        self.indexed = self.samples.len();
        if self.samples.is_empty() {
            self.general = None;
            self.special = None;
            return;
        }
        let g: Vec<[f64; 4]> = self.samples.iter().map(general_key).collect();
        let w = self.params.turn_weight;
        let s: Vec<[f64; 3]> = self.samples.iter().map(|x| special_key(x, w)).collect();
        self.general = Some(ImmutableKdTree::new_from_slice(&g));
        self.special = Some(ImmutableKdTree::new_from_slice(&s));
    }

    /// The same samples keyed on the motion of the object's point `c` (object frame) rather
    /// than its marker's ([`Sample::about`]): asked for a wanted motion, it answers with the
    /// pushes that moved that point so. Among obstacles the object's path is planned for its
    /// outline's enclosing circle, whose centre is the point to move
    /// ([`crate::exec::deliver::deliver_learned_among`]). No admission rule.
    pub fn about(&self, c: [f64; 2]) -> PushStrategy {
        PushStrategy::new(self.samples.iter().map(|s| s.about(c)), self.params)
    }

    /// Add a sample for immediate use (non-finite samples are ignored).
    pub fn add(&mut self, s: Sample) {
        if !s.is_finite() {
            return;
        }
        self.s_len_sum += s.s_len();
        self.samples.push(s);
        if self.samples.len() - self.indexed > REBUILD_AFTER {
            self.rebuild();
        }
    }

    /// Use `params` from now on (the trees are built anew, the samples kept).
    pub fn set_params(&mut self, params: KernelParams) {
        if params != self.params {
            self.params = params;
            self.rebuild();
        }
    }

    /// Set which pushes [`Self::offer`] keeps: `None` keeps every push (the paper).
    pub fn set_admission(&mut self, admission: Option<Admission>) {
        self.admission = admission;
    }

    /// Offer a push observed while the strategy is in use (a supplemental sample): added, and
    /// `true` returned, when the admission rule (if any) finds it informative
    /// ([`Self::informative`]).
    pub fn offer(&mut self, s: Sample) -> bool {
        if !s.is_finite() {
            return false;
        }
        if self.admission.is_some_and(|a| !self.informative(&s, &a)) {
            return false;
        }
        self.add(s);
        true
    }

    /// Whether `s` would teach the strategy something under `a` (see [`Admission`]).
    pub fn informative(&self, s: &Sample, a: &Admission) -> bool {
        let key = general_key(s);
        let near = self.nearest(self.general.as_ref(), &general_key, &key);
        let Some(&(d2, _)) = near.first() else {
            return true;
        };
        if d2.sqrt() > a.novel_distance {
            return true;
        }
        let Some(r) = self.predict(s.p, s.s) else {
            return true;
        };
        let turn = (r[1].atan2(r[0]) - s.r[1].atan2(s.r[0])).abs();
        let turn = turn.min(2.0 * std::f64::consts::PI - turn);
        turn > a.surprise
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The kernel parameters.
    pub fn params(&self) -> KernelParams {
        self.params
    }

    /// The samples.
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// The paper's `offset`: the mean length of the samples' object displacements, so a query's
    /// wanted motion has the length the data has.
    pub fn offset(&self) -> f64 {
        if self.samples.is_empty() {
            0.0
        } else {
            self.s_len_sum / self.samples.len() as f64
        }
    }

    /// The k nearest samples to `q` by `key`, as (squared distance, index), nearest first.
    fn nearest<const K: usize>(
        &self,
        tree: Option<&ImmutableKdTree<f64, K>>,
        key: &dyn Fn(&Sample) -> [f64; K],
        q: &[f64; K],
    ) -> Vec<(f64, usize)> {
        let k = self.params.k.max(1);
        let mut found: Vec<(f64, usize)> = match (tree, NonZeroUsize::new(k)) {
            (Some(t), Some(nz)) => t
                .nearest_n::<SquaredEuclidean>(q, nz)
                .into_iter()
                .map(|n| (n.distance, n.item as usize))
                .collect(),
            _ => Vec::new(),
        };
        for (i, s) in self.samples.iter().enumerate().skip(self.indexed) {
            found.push((dist2(&key(s), q), i));
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found.truncate(k);
        found
    }

    /// Gaussian weights of neighbours; relative to the nearest so far-away queries do not
    /// underflow to all-zero weights (the normalised mean is the same).
    fn weights(&self, near: &[(f64, usize)]) -> Vec<f64> {
        let kw2 = self.params.kernel_width * self.params.kernel_width;
        let d0 = near.first().map_or(0.0, |n| n.0);
        near.iter()
            .map(|(d2, _)| (-(d2 - d0) / kw2).exp())
            .collect()
    }

    /// General case: the robot motion r that moves the object along `goal_dir` (a unit vector)
    /// from robot position `p`, both in the object's frame. `None` without samples or for a
    /// non-finite query.
    pub fn general(&self, p: [f64; 2], goal_dir: [f64; 2]) -> Option<[f64; 2]> {
        let off = self.offset();
        self.predict(p, [off * goal_dir[0], off * goal_dir[1]])
    }

    /// The general case at a raw key: the kernel-weighted robot motion of the k samples nearest
    /// to (p, s), object frame. `None` without samples or for a non-finite query.
    pub fn predict(&self, p: [f64; 2], s: [f64; 2]) -> Option<[f64; 2]> {
        let near = self.general_near(p, s)?;
        let w = self.weights(&near);
        let total: f64 = w.iter().sum();
        if near.is_empty() || total <= 0.0 {
            return None;
        }
        let mut r = [0.0; 2];
        for ((_, i), wi) in near.iter().zip(&w) {
            r[0] += wi * self.samples[*i].r[0];
            r[1] += wi * self.samples[*i].r[1];
        }
        Some([r[0] / total, r[1] / total])
    }

    /// How far the general case's nearest sample is from its query ([`Self::general`]: the
    /// robot at `p`, the object wanted along `goal_dir`), m in (p_x, p_y, s_x, s_y): how much
    /// the strategy has seen of pushing from there that way. `None` without samples or for a
    /// non-finite query.
    pub fn general_distance(&self, p: [f64; 2], goal_dir: [f64; 2]) -> Option<f64> {
        let off = self.offset();
        let near = self.general_near(p, [off * goal_dir[0], off * goal_dir[1]])?;
        near.first().map(|n| n.0.sqrt())
    }

    /// The general case's k nearest samples to (p, s) ([`Self::nearest`]); `None` for a
    /// non-finite query.
    fn general_near(&self, p: [f64; 2], s: [f64; 2]) -> Option<Vec<(f64, usize)>> {
        let q = [p[0], p[1], s[0], s[1]];
        if q.iter().any(|v| !v.is_finite()) {
            return None;
        }
        Some(self.nearest(self.general.as_ref(), &general_key, &q))
    }

    /// Special case: where to stand and how to push so the object moves along `goal_dir`.
    pub fn special(&self, goal_dir: [f64; 2]) -> Option<Reposition> {
        let off = self.offset();
        // Moved along the wanted direction, and not turned.
        let q = [off * goal_dir[0], off * goal_dir[1], 0.0];
        if q.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let tw = self.params.turn_weight;
        let near = self.nearest(self.special.as_ref(), &|x| special_key(x, tw), &q);
        let w = self.weights(&near);
        let total: f64 = w.iter().sum();
        if near.is_empty() || total <= 0.0 {
            return None;
        }
        let mut out = [0.0; 4];
        for ((_, i), wi) in near.iter().zip(&w) {
            let s = &self.samples[*i];
            for (o, v) in out.iter_mut().zip([s.p[0], s.p[1], s.r[0], s.r[1]]) {
                *o += wi * v;
            }
        }
        Some(Reposition {
            p: [out[0] / total, out[1] / total],
            r: [out[2] / total, out[3] / total],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_samples(n: usize, seed: u64) -> Vec<Sample> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let a: f64 = rng.random_range(-3.2..3.2);
                let push: f64 = rng.random_range(0.01..0.05);
                Sample {
                    p: [0.08 * a.cos(), 0.08 * a.sin()],
                    r: [
                        -push * a.cos() + rng.random_range(-0.01..0.01),
                        -push * a.sin(),
                    ],
                    s: [
                        -0.8 * push * a.cos(),
                        -0.8 * push * a.sin() + rng.random_range(-0.005..0.005),
                    ],
                    theta: rng.random_range(-0.2..0.2),
                }
            })
            .collect()
    }

    /// Brute force: Algorithm 2 written out over every sample.
    fn brute_general(
        samples: &[Sample],
        params: KernelParams,
        p: [f64; 2],
        dir: [f64; 2],
    ) -> [f64; 2] {
        let off = samples.iter().map(Sample::s_len).sum::<f64>() / samples.len() as f64;
        let q = [p[0], p[1], off * dir[0], off * dir[1]];
        let mut d: Vec<(f64, usize)> = samples
            .iter()
            .enumerate()
            .map(|(i, s)| (dist2(&general_key(s), &q), i))
            .collect();
        d.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let (mut r, mut tot) = ([0.0; 2], 0.0);
        for (d2, i) in d.iter().take(params.k) {
            let w = (-d2 / (params.kernel_width * params.kernel_width)).exp();
            r[0] += w * samples[*i].r[0];
            r[1] += w * samples[*i].r[1];
            tot += w;
        }
        [r[0] / tot, r[1] / tot]
    }

    #[test]
    fn general_case_matches_brute_force() {
        let samples = random_samples(3000, 7);
        let params = KernelParams::default();
        // Part indexed, part recent: both search paths take part.
        let mut strat = PushStrategy::new(samples[..2900].iter().copied(), params);
        for s in &samples[2900..] {
            strat.add(*s);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for _ in 0..300 {
            let p = [rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1)];
            let a: f64 = rng.random_range(-3.2..3.2);
            let dir = [a.cos(), a.sin()];
            let got = strat.general(p, dir).unwrap();
            let want = brute_general(&samples, params, p, dir);
            assert!(
                (got[0] - want[0]).abs() < 1e-9 && (got[1] - want[1]).abs() < 1e-9,
                "{got:?} vs {want:?}"
            );
        }
    }

    /// The general case's nearest-sample distance is the brute-force one, over indexed and
    /// recent samples, and 0 at a sample's own key.
    #[test]
    fn general_distance_is_the_nearest_samples_distance() {
        let samples = random_samples(1000, 11);
        let mut strat = PushStrategy::new(samples[..900].iter().copied(), KernelParams::default());
        for s in &samples[900..] {
            strat.add(*s);
        }
        let off = strat.offset();
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        for _ in 0..200 {
            let p = [rng.random_range(-0.2..0.2), rng.random_range(-0.2..0.2)];
            let a: f64 = rng.random_range(-3.2..3.2);
            let q = [p[0], p[1], off * a.cos(), off * a.sin()];
            let want = samples
                .iter()
                .map(|s| dist2(&general_key(s), &q).sqrt())
                .fold(f64::INFINITY, f64::min);
            let got = strat.general_distance(p, [a.cos(), a.sin()]).unwrap();
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        let s = samples[950];
        let dir = [s.s[0] / off, s.s[1] / off];
        assert!(strat.general_distance(s.p, dir).unwrap() < 1e-12);
        let empty = PushStrategy::new([], KernelParams::default());
        assert_eq!(empty.general_distance([0.0, 0.0], [1.0, 0.0]), None);
        assert_eq!(strat.general_distance([f64::NAN, 0.0], [1.0, 0.0]), None);
    }

    #[test]
    fn special_case_returns_the_push_that_moves_the_object_the_wanted_way() {
        // Samples from a disc-like object: pushing from angle a moves it towards a + π.
        let samples = random_samples(2000, 3);
        let strat = PushStrategy::new(samples, KernelParams::default());
        for a in [0.0f64, 1.0, 2.5, -2.0] {
            let rep = strat.special([a.cos(), a.sin()]).unwrap();
            // To move the object along a, stand on the opposite side and push along a.
            let stand = rep.p[1].atan2(rep.p[0]);
            let diff = crate::strategy::sample::wrap_angle(stand - (a + std::f64::consts::PI));
            assert!(diff.abs() < 0.3, "a={a}: stands at {stand}");
            let push = rep.r[1].atan2(rep.r[0]);
            assert!(
                crate::strategy::sample::wrap_angle(push - a).abs() < 0.4,
                "a={a}: pushes {push}"
            );
        }
    }

    #[test]
    fn far_queries_do_not_underflow_and_empty_strategies_answer_none() {
        let strat = PushStrategy::new(random_samples(50, 1), KernelParams::default());
        assert!(strat.general([100.0, 100.0], [1.0, 0.0]).is_some());
        assert!(strat.general([f64::NAN, 0.0], [1.0, 0.0]).is_none());
        let empty = PushStrategy::new(Vec::new(), KernelParams::default());
        assert!(empty.general([0.0, 0.0], [1.0, 0.0]).is_none());
        assert!(empty.special([1.0, 0.0]).is_none());
    }

    #[test]
    fn an_admission_rule_keeps_only_new_or_mispredicted_pushes() {
        let samples = random_samples(500, 11);
        let mut strat = PushStrategy::new(samples.iter().copied(), KernelParams::default());
        // Without a rule every push is kept (the paper).
        assert!(strat.offer(samples[0]));
        strat.set_admission(Some(Admission::default()));
        // A push the strategy has seen exactly: neither new nor a surprise.
        let seen = samples[1];
        assert!(!strat.offer(seen));
        // The same (p, s) reached by a robot motion turned 90°: a surprise.
        let turned = Sample {
            r: [-seen.r[1], seen.r[0]],
            ..seen
        };
        assert!(strat.informative(&turned, &Admission::default()));
        // A push from where the robot never stood: new.
        let far = Sample {
            p: [0.3, 0.3],
            ..seen
        };
        let n = strat.len();
        assert!(strat.offer(far));
        assert_eq!(strat.len(), n + 1);
        assert!(!strat.offer(Sample {
            theta: f64::NAN,
            ..far
        }));
    }

    #[test]
    fn many_identical_samples_are_fine() {
        let s = random_samples(1, 5)[0];
        let mut strat = PushStrategy::new(std::iter::repeat_n(s, 1000), KernelParams::default());
        for _ in 0..600 {
            strat.add(s);
        }
        let r = strat.general(s.p, [1.0, 0.0]).unwrap();
        assert!((r[0] - s.r[0]).abs() < 1e-12 && (r[1] - s.r[1]).abs() < 1e-12);
    }

    /// Two ways of moving an object 2 cm along +x: pushed from behind its upper half it also
    /// turns by 0.4 rad, from behind its lower half it does not. Keyed on the motion alone (the
    /// paper) the special case averages both stand points; with a turn weight it stands where
    /// the push does not turn the object, and pushes as from there.
    #[test]
    fn the_turn_weight_prefers_pushes_that_do_not_turn_the_object() {
        let push = |i: usize| {
            let upper = i.is_multiple_of(2);
            let jitter = 0.001 * (i / 2) as f64;
            Sample {
                p: [-0.08, if upper { 0.03 } else { -0.03 } + jitter],
                r: [0.03, if upper { 0.004 } else { -0.004 }],
                s: [0.02, jitter],
                theta: if upper { 0.4 } else { 0.0 },
            }
        };
        let samples: Vec<Sample> = (0..10).map(push).collect();
        let paper = KernelParams {
            turn_weight: 0.0,
            ..KernelParams::default()
        };
        let rep = PushStrategy::new(samples.iter().copied(), paper)
            .special([1.0, 0.0])
            .unwrap();
        assert!(
            rep.p[1].abs() < 0.02,
            "the paper averages both sides: {rep:?}"
        );
        let weighted = KernelParams {
            turn_weight: TURN_WEIGHT,
            ..paper
        };
        let rep = PushStrategy::new(samples.iter().copied(), weighted)
            .special([1.0, 0.0])
            .unwrap();
        assert!(rep.p[1] < -0.025, "stands behind the lower half: {rep:?}");
        assert!(rep.r[1] < -0.003, "pushes as from there: {rep:?}");
    }

    /// An object that turns as it is pushed: pushed from angle a, its point c goes 2.4 cm
    /// towards a + π and it turns by 0.3 sin a, so its marker (the origin) goes another way.
    #[test]
    fn a_strategy_about_a_point_moves_that_point_the_wanted_way() {
        let c = [0.0, 0.06];
        let push = |a: f64| {
            let d = [a.cos(), a.sin()];
            let theta = 0.3 * a.sin();
            let (sin, cos) = theta.sin_cos();
            // The marker's displacement: c's less the swing of c about the marker.
            let swing = [
                cos * c[0] - sin * c[1] - c[0],
                sin * c[0] + cos * c[1] - c[1],
            ];
            Sample {
                p: [0.08 * d[0], 0.08 * d[1]],
                r: [-0.03 * d[0], -0.03 * d[1]],
                s: [-0.024 * d[0] - swing[0], -0.024 * d[1] - swing[1]],
                theta,
            }
        };
        let samples: Vec<Sample> = (0..720)
            .map(|i| push(i as f64 * std::f64::consts::TAU / 720.0))
            .collect();
        // The paper's keys (no turn weight): this is about which point the keys follow.
        let paper = KernelParams {
            turn_weight: 0.0,
            ..KernelParams::default()
        };
        let marker = PushStrategy::new(samples.iter().copied(), paper);
        let centre = marker.about(c);
        let heading = |v: [f64; 2]| v[1].atan2(v[0]);
        // How far c's motion, pushing from where the strategy stands, is off `dir`.
        let miss = |s: &PushStrategy, dir: f64| {
            let rep = s.special([dir.cos(), dir.sin()]).unwrap();
            let moved = push(heading(rep.p)).about(c).s;
            crate::strategy::sample::wrap_angle(heading(moved) - dir).abs()
        };
        let mut worst_marker: f64 = 0.0;
        for dir in [0.3f64, 1.2, 1.9, 2.8, -0.8, -1.6, -2.5] {
            assert!(miss(&centre, dir) < 0.05, "{dir}: {}", miss(&centre, dir));
            worst_marker = worst_marker.max(miss(&marker, dir));
        }
        // Keyed on the marker, the same queries move the point well off the wanted way.
        assert!(worst_marker > 0.3, "{worst_marker}");
    }
}
