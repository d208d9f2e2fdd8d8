//! One Kalman filter per body (`adskalman`): constant-velocity model on position and heading,
//! state `[x, y, θ, vx, vy, ω]`, observed `[x, y, θ]`. The heading stays on the circle: each
//! observed heading is unwrapped next to the predicted one before the update and the state's
//! heading is wrapped back into (−π, π] after it. Missed detections only predict; an
//! observation whose innovation fails a χ² gate is rejected as an outlier, unless the body has
//! been rejected several frames running (it really moved: the filter restarts there). Every
//! pose carries the time of the frame it is for and the age of its last accepted detection.
//!
//! A body the filter can no longer place is **lost**: no accepted detection for
//! [`TrackerParams::lost_after`], or for long enough that a body accelerating at
//! [`TrackerParams::max_accel`] could have strayed [`TrackerParams::lost_drift`] from the
//! prediction (two frames at 30 fps with the defaults: a robot that starts to drive fast, its marker smeared, is
//! lost rather than left behind), or a position uncertainty (1 σ, from the covariance) past
//! [`TrackerParams::lost_sigma`].
//!
//! A body whose odometry the tracker is given ([`Tracker::odometry`]: the robot's telemetry) is
//! predicted from it instead of from its velocity ([`super::odometry`]), as the filter's control
//! input: its unseen motion is then known, and it is lost only by its uncertainty or after
//! [`TrackerParams::lost_after_odometry`]. A lost body's pose is a guess that grows without bound; users
//! of the tracker report lost instead of a pose.

use std::collections::BTreeMap;

use adskalman::{
    CovarianceUpdateMethod, ObservationModel, StateAndCovariance, TransitionModelLinearNoControl,
};
use nalgebra::{SMatrix, SVector, U3, U6};
use serde::{Deserialize, Serialize};

use super::layout::{Pose, wrap_angle};
use super::odometry::OdometryLog;

type M6 = SMatrix<f64, 6, 6>;
type M3x6 = SMatrix<f64, 3, 6>;
type M6x3 = SMatrix<f64, 6, 3>;
type M3 = SMatrix<f64, 3, 3>;

/// Noise and gating settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackerParams {
    /// Standard deviation of a measured position, metres.
    pub pos_sigma: f64,
    /// Standard deviation of a measured heading, radians.
    pub heading_sigma: f64,
    /// Acceleration noise (white), m/s².
    pub accel_sigma: f64,
    /// Angular acceleration noise, rad/s² (20: a small robot spins up to 180°/s in a tenth of
    /// a second, and the filter must follow the marker it sees as it does).
    pub ang_accel_sigma: f64,
    /// χ² gate on the 3-dof innovation (16.27 ≈ p = 0.001).
    pub gate: f64,
    /// Consecutive rejections after which the filter restarts at the observation.
    pub restart_after: u32,
    /// Seconds without an accepted detection after which a body is lost.
    #[serde(default = "default_lost_after")]
    pub lost_after: f64,
    /// Position uncertainty (1 σ, metres) past which a body is lost.
    #[serde(default = "default_lost_sigma")]
    pub lost_sigma: f64,
    /// The most a body accelerates, m/s²: a body unseen for `age` seconds may be
    /// `max_accel·age²/2` from its prediction.
    #[serde(default = "default_max_accel")]
    pub max_accel: f64,
    /// How far (metres) an unseen body may have strayed from its prediction, at `max_accel`,
    /// before it is lost.
    #[serde(default = "default_lost_drift")]
    pub lost_drift: f64,
    /// Seconds without an accepted detection after which a body whose motion the robot's
    /// odometry has predicted all along ([`Tracker::odometry`]) is lost.
    #[serde(default = "default_lost_after_odometry")]
    pub lost_after_odometry: f64,
    /// The odometry's error, when it drives the prediction.
    #[serde(default)]
    pub odometry_noise: super::odometry::OdometryNoise,
}

fn default_lost_after_odometry() -> f64 {
    3.0
}

fn default_max_accel() -> f64 {
    3.0
}

fn default_lost_drift() -> f64 {
    0.01
}

fn default_lost_after() -> f64 {
    0.5
}

fn default_lost_sigma() -> f64 {
    0.02
}

impl Default for TrackerParams {
    fn default() -> Self {
        TrackerParams {
            pos_sigma: 0.0008,
            heading_sigma: 0.006,
            accel_sigma: 1.5,
            ang_accel_sigma: 20.0,
            gate: 30.0,
            restart_after: 4,
            lost_after: default_lost_after(),
            lost_sigma: default_lost_sigma(),
            max_accel: default_max_accel(),
            lost_drift: default_lost_drift(),
            lost_after_odometry: default_lost_after_odometry(),
            odometry_noise: super::odometry::OdometryNoise::default(),
        }
    }
}

struct Motion {
    f: M6,
    ft: M6,
    q: M6,
}

impl Motion {
    fn new(dt: f64, p: &TrackerParams) -> Motion {
        let mut f = M6::identity();
        for i in 0..3 {
            f[(i, i + 3)] = dt;
        }
        let mut q = M6::zeros();
        for (i, s) in [
            (0, p.accel_sigma),
            (1, p.accel_sigma),
            (2, p.ang_accel_sigma),
        ] {
            let s2 = s * s;
            q[(i, i)] = s2 * dt.powi(4) / 4.0;
            q[(i, i + 3)] = s2 * dt.powi(3) / 2.0;
            q[(i + 3, i)] = s2 * dt.powi(3) / 2.0;
            q[(i + 3, i + 3)] = s2 * dt * dt;
        }
        Motion {
            f,
            ft: f.transpose(),
            q,
        }
    }
}

impl TransitionModelLinearNoControl<f64, U6> for Motion {
    fn F(&self) -> &M6 {
        &self.f
    }
    fn FT(&self) -> &M6 {
        &self.ft
    }
    fn Q(&self) -> &M6 {
        &self.q
    }
}

struct Observe {
    h: M3x6,
    ht: M6x3,
    r: M3,
}

impl Observe {
    fn new(p: &TrackerParams) -> Observe {
        let mut h = M3x6::zeros();
        for i in 0..3 {
            h[(i, i)] = 1.0;
        }
        let r = M3::from_diagonal(&SVector::<f64, 3>::new(
            p.pos_sigma.powi(2),
            p.pos_sigma.powi(2),
            p.heading_sigma.powi(2),
        ));
        Observe {
            h,
            ht: h.transpose(),
            r,
        }
    }
}

impl ObservationModel<f64, U6, U3> for Observe {
    fn H(&self) -> &M3x6 {
        &self.h
    }
    fn HT(&self) -> &M6x3 {
        &self.ht
    }
    fn R(&self) -> &M3 {
        &self.r
    }
}

struct Track {
    est: StateAndCovariance<f64, U6>,
    time: f64,
    last_seen: f64,
    rejected_run: u32,
    /// Seconds predicted without odometry since the last accepted detection.
    blind: f64,
}

/// A body's filtered pose at one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackedPose {
    /// The body's name.
    pub body: String,
    /// Filtered pose at `time`.
    pub pose: Pose,
    /// Time of the frame this pose is for, seconds.
    pub time: f64,
    /// Whether the body's marker was detected in this frame (accepted or not).
    pub seen: bool,
    /// Whether this frame's detection was rejected as an outlier.
    pub rejected: bool,
    /// Seconds since the last accepted detection.
    pub age: f64,
    /// Position uncertainty, metres (1 σ, the mean of the covariance's x and y variances).
    pub sigma_m: f64,
    /// Whether the body is lost (see the module docs): `pose` is then no measurement.
    pub lost: bool,
}

/// Kalman filters for every body seen so far.
pub struct Tracker {
    params: TrackerParams,
    observe: Observe,
    tracks: BTreeMap<String, Track>,
    /// Odometry of the bodies that report it (the robot), by name.
    odometry: BTreeMap<String, OdometryLog>,
}

impl std::fmt::Debug for Tracker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tracker")
            .field("params", &self.params)
            .field("bodies", &self.tracks.keys().collect::<Vec<_>>())
            .finish()
    }
}

impl Tracker {
    /// A tracker with these settings.
    pub fn new(params: TrackerParams) -> Tracker {
        Tracker {
            observe: Observe::new(&params),
            params,
            tracks: BTreeMap::new(),
            odometry: BTreeMap::new(),
        }
    }

    /// Forget `body`'s odometry (see [`Tracker::odometry`]).
    pub fn forget_odometry(&mut self, body: &str) {
        self.odometry.remove(body);
    }

    /// The odometry pose of `body` (its own frame) at `time` (the frames' clock): between
    /// frames the body's motion is then predicted from its odometry ([`super::odometry`]).
    pub fn odometry(&mut self, body: &str, time: f64, pose: Pose) {
        self.odometry
            .entry(body.to_string())
            .or_default()
            .push(time, pose);
    }

    fn start(&self, z: &Pose, time: f64) -> Track {
        let p = &self.params;
        let x = SVector::<f64, 6>::new(z.x, z.y, z.theta, 0.0, 0.0, 0.0);
        let cov = M6::from_diagonal(&SVector::<f64, 6>::new(
            p.pos_sigma.powi(2),
            p.pos_sigma.powi(2),
            p.heading_sigma.powi(2),
            0.25,
            0.25,
            4.0,
        ));
        Track {
            est: StateAndCovariance::new(x, cov),
            time,
            last_seen: time,
            rejected_run: 0,
            blind: 0.0,
        }
    }

    /// Advance every track to `time` and fold in this frame's observations (body name, measured
    /// body pose). Returns every tracked body's pose at `time`, by name.
    pub fn update(&mut self, time: f64, observations: &[(String, Pose)]) -> Vec<TrackedPose> {
        let mut seen: BTreeMap<&str, &Pose> = BTreeMap::new();
        for (name, pose) in observations {
            seen.insert(name, pose);
        }
        let mut out = Vec::new();
        let names: Vec<String> = self
            .tracks
            .keys()
            .cloned()
            .chain(seen.keys().map(|s| s.to_string()))
            .collect();
        let mut done = std::collections::BTreeSet::new();
        for name in names {
            if !done.insert(name.clone()) {
                continue;
            }
            let obs = seen.get(name.as_str()).copied();
            let mut rejected = false;
            let track = match (self.tracks.remove(&name), obs) {
                (None, Some(z)) => self.start(z, time),
                (None, None) => continue,
                (Some(mut t), obs) => {
                    let dt = (time - t.time).max(0.0);
                    let moved = self
                        .odometry
                        .get(&name)
                        .and_then(|log| log.increment(t.time, time));
                    let prior = match moved {
                        Some(d) => {
                            let (x, p) = super::odometry::predict(
                                t.est.state(),
                                t.est.covariance(),
                                d,
                                dt,
                                &self.params.odometry_noise,
                            );
                            StateAndCovariance::new(x, p)
                        }
                        None => {
                            t.blind += dt;
                            let prior = Motion::new(dt, &self.params).predict(&t.est);
                            // Keep the covariance exactly symmetric (the library checks it).
                            StateAndCovariance::new(
                                *prior.state(),
                                prior.covariance().symmetric_part(),
                            )
                        }
                    };
                    t.time = time;
                    t.est = prior;
                    if let Some(z) = obs {
                        match self.correct(&t.est, z) {
                            Some(post) => {
                                t.est = post;
                                t.last_seen = time;
                                t.rejected_run = 0;
                                t.blind = 0.0;
                            }
                            None => {
                                t.rejected_run += 1;
                                rejected = true;
                                if t.rejected_run >= self.params.restart_after {
                                    t = self.start(z, time);
                                    rejected = false;
                                }
                            }
                        }
                    }
                    t
                }
            };
            let s = track.est.state();
            let c = track.est.covariance();
            let sigma_m = (0.5 * (c[(0, 0)] + c[(1, 1)])).max(0.0).sqrt();
            let age = time - track.last_seen;
            out.push(TrackedPose {
                body: name.clone(),
                pose: Pose::new(s[0], s[1], wrap_angle(s[2])),
                time,
                seen: obs.is_some(),
                rejected,
                age,
                sigma_m,
                lost: track.blind > self.params.lost_after
                    || age > self.params.lost_after_odometry
                    || 0.5 * self.params.max_accel * track.blind.powi(2) > self.params.lost_drift
                    || sigma_m.is_nan()
                    || sigma_m > self.params.lost_sigma
                    || !s.iter().all(|v| v.is_finite()),
            });
            self.tracks.insert(name, track);
        }
        out
    }

    /// The posterior, or `None` if the observation fails the gate.
    fn correct(
        &self,
        prior: &StateAndCovariance<f64, U6>,
        z: &Pose,
    ) -> Option<StateAndCovariance<f64, U6>> {
        let x = prior.state();
        let zt = x[2] + wrap_angle(z.theta - x[2]);
        let zv = SVector::<f64, 3>::new(z.x, z.y, zt);
        let innov = zv - self.observe.h * x;
        let s = self.observe.h * prior.covariance() * self.observe.ht + self.observe.r;
        let d2 = s.cholesky()?.solve(&innov).dot(&innov);
        if d2.is_nan() || d2 > self.params.gate {
            return None;
        }
        let post = self
            .observe
            .update(prior, &zv, CovarianceUpdateMethod::JosephForm)
            .ok()?;
        let mut st = *post.state();
        st[2] = wrap_angle(st[2]);
        Some(StateAndCovariance::new(st, *post.covariance()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A body circling across the ±π seam, measured with noise, with dropped frames and
    /// injected outliers: the filter keeps it, rejects the outliers and beats the raw error.
    #[test]
    fn tracks_through_drops_outliers_and_the_seam() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let pos = Normal::new(0.0, 0.0008).unwrap();
        let ang = Normal::new(0.0, 0.006).unwrap();
        let mut tracker = Tracker::new(TrackerParams::default());
        let truth = |t: f64| {
            Pose::new(
                0.6 + 0.2 * (0.5 * t).cos(),
                0.45 + 0.2 * (0.5 * t).sin(),
                wrap_angle(3.0 + 0.8 * t),
            )
        };
        let (mut raw_err, mut filt_err, mut n) = (0.0, 0.0, 0);
        let mut rejected = 0;
        for k in 0..300 {
            let t = k as f64 / 30.0;
            let g = truth(t);
            let mut obs = vec![];
            let outlier = k % 37 == 20;
            if k % 10 != 3 {
                let mut z = Pose::new(
                    g.x + pos.sample(&mut rng),
                    g.y + pos.sample(&mut rng),
                    wrap_angle(g.theta + ang.sample(&mut rng)),
                );
                if outlier {
                    z.x += 0.15;
                    z.theta += 1.0;
                }
                obs.push(("robot".to_string(), z));
                if !outlier && k > 30 {
                    raw_err += (z.x - g.x).hypot(z.y - g.y);
                }
            }
            let out = tracker.update(t, &obs);
            assert_eq!(out.len(), 1);
            let p = &out[0];
            assert_eq!(p.seen, k % 10 != 3);
            assert_eq!(p.time, t);
            if outlier && k % 10 != 3 {
                assert!(p.rejected, "outlier at frame {k} accepted");
                rejected += 1;
            }
            if k % 10 == 3 {
                assert!(p.age > 0.0 && p.age < 0.1);
            }
            let e = (p.pose.x - g.x).hypot(p.pose.y - g.y);
            assert!(e < 0.005, "frame {k}: error {e}");
            // A prediction (a dropped or rejected frame) is a little looser: the filter lets
            // the heading rate change fast (a robot starting to spin), so its rate is noisier.
            let bound = if p.seen && !p.rejected { 0.03 } else { 0.045 };
            assert!(
                wrap_angle(p.pose.theta - g.theta).abs() < bound,
                "frame {k}: heading {} vs {}",
                p.pose.theta,
                g.theta
            );
            if k > 30 && k % 10 != 3 && !outlier {
                filt_err += e;
                n += 1;
            }
        }
        assert!(rejected >= 7);
        assert!(
            filt_err < raw_err,
            "filter {:.5} vs raw {:.5} over {n}",
            filt_err / n as f64,
            raw_err / n as f64
        );
    }

    /// A body that stops being seen is lost after `lost_after` (its pose a guess), and found
    /// again with its next detection.
    #[test]
    fn a_body_unseen_for_too_long_is_lost_then_found() {
        let mut tracker = Tracker::new(TrackerParams::default());
        let z = |x: f64| ("o".to_string(), Pose::new(x, 0.3, 0.0));
        for k in 0..30 {
            let out = tracker.update(k as f64 / 30.0, &[z(0.2 + 0.005 * k as f64)]);
            assert!(!out[0].lost && out[0].sigma_m < 0.002, "{:?}", out[0]);
        }
        let mut lost_at = None;
        for k in 30..60 {
            let out = tracker.update(k as f64 / 30.0, &[]);
            if out[0].lost && lost_at.is_none() {
                lost_at = Some(k);
            }
            if let Some(at) = lost_at {
                assert!(out[0].lost, "stays lost ({k}, lost at {at})");
            }
        }
        let at = lost_at.expect("lost");
        // Not for a frame or two missed; at the third, a body accelerating at `max_accel`
        // could be `lost_drift` away (½·3·0.1² > 0.01 m).
        assert_eq!(at, 32, "lost at frame {at}");
        // A slow-moving body (`max_accel` 0.3 m/s²) is lost later, at the latest after
        // `lost_after` (0.5 s, 15 frames).
        let mut slow = Tracker::new(TrackerParams {
            max_accel: 0.3,
            ..TrackerParams::default()
        });
        for k in 0..30 {
            slow.update(k as f64 / 30.0, &[z(0.2 + 0.005 * k as f64)]);
        }
        let at = (30..60)
            .find(|&k| slow.update(k as f64 / 30.0, &[])[0].lost)
            .expect("lost");
        assert!((33..=45).contains(&at), "slow body lost at frame {at}");
        let out = tracker.update(2.0, &[z(0.5)]);
        assert!(!out[0].lost, "found again: {:?}", out[0]);
    }

    /// A body that really jumps is picked up again after a few rejected frames.
    #[test]
    fn restarts_after_a_real_jump() {
        let mut tracker = Tracker::new(TrackerParams::default());
        for k in 0..10 {
            tracker.update(k as f64 / 30.0, &[("o".into(), Pose::new(0.2, 0.2, 0.0))]);
        }
        let mut last = None;
        for k in 10..16 {
            last = Some(tracker.update(k as f64 / 30.0, &[("o".into(), Pose::new(0.8, 0.5, 1.0))]));
        }
        let p = &last.unwrap()[0];
        assert!((p.pose.x - 0.8).abs() < 0.01 && !p.rejected, "{p:?}");
    }
}
