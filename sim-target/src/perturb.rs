//! One perturbed world per trial: the simulated world runs values drawn from a
//! scene's `[perturb]` ranges ([`pushbot_world::scene::perturb::Perturb`]) while the planner
//! keeps the nominal ones — Lynch & Mason's stable pushes (§3) are planned with a friction
//! guess and a known start, and this is how far the world may be from both. A draw is a
//! function of the seed and the trial number only.
//!
//! What it changes: the start of the pushed object (with the robot's start moved rigidly with
//! it, so a plate flush on the object stays flush), the object's support and pusher
//! friction, its centre of friction (the support pressure tilted linearly, §2's support
//! distribution), a systematic slip of each wheel ([`crate::Hardware::wheel_slip`]), and the
//! camera's noise (for the host's in-process camera, which reads it from here).

use anyhow::{Result, anyhow, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::pushing::point_in_polygon;
use crate::scene::perturb::Perturb;
use crate::scene::{Scene, Support};

/// The values one perturbed world runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Perturbation {
    /// The object it applies to (the pushed one).
    pub object: String,
    /// Start error of the object, table frame: dx, dy (m), dθ (rad) about its frame's origin.
    pub start: [f64; 3],
    /// Factor on the object's support friction.
    pub support_friction: f64,
    /// Factor on the object's pusher friction.
    pub pusher_friction: f64,
    /// Offset of the object's centre of friction, object frame, m.
    pub cof_offset: [f64; 2],
    /// Each wheel's systematic rim-speed error (share), left and right.
    pub wheel_slip: [f64; 2],
    /// Camera position noise, standard deviation, m.
    pub camera_xy: f64,
    /// Camera heading noise, standard deviation, rad.
    pub camera_theta: f64,
}

impl Perturbation {
    /// Draw trial `trial`'s world from `ranges` with `seed`, for the object `object`.
    pub fn draw(ranges: &Perturb, object: &str, seed: u64, trial: u64) -> Perturbation {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(0x5045_5254_0000 + trial);
        let mut sym = |r: f64| {
            if r > 0.0 {
                rng.random_range(-r..=r)
            } else {
                0.0
            }
        };
        let start = [
            sym(ranges.start_xy),
            sym(ranges.start_xy),
            sym(ranges.start_theta_deg).to_radians(),
        ];
        let support_friction = 1.0 + sym(ranges.support_friction);
        let pusher_friction = 1.0 + sym(ranges.pusher_friction);
        let wheel_slip = [sym(ranges.wheel_slip), sym(ranges.wheel_slip)];
        // Uniform in the disk of radius cof_offset.
        let (r, a) = (
            ranges.cof_offset * sym(1.0).abs().sqrt(),
            sym(std::f64::consts::PI),
        );
        Perturbation {
            object: object.to_string(),
            start,
            support_friction,
            pusher_friction,
            cof_offset: [r * a.cos(), r * a.sin()],
            wheel_slip,
            camera_xy: ranges.camera_xy,
            camera_theta: ranges.camera_theta_deg.to_radians(),
        }
    }

    /// Change `scene` into this perturbed world: the object's start (and the robot's, moved
    /// rigidly with it), frictions and centre of friction. Errors when the scene has no such
    /// object or the offset cannot be made with positive support pressure.
    pub fn apply(&self, scene: &mut Scene) -> Result<()> {
        let o = scene
            .objects
            .iter_mut()
            .find(|o| o.id == self.object)
            .ok_or_else(|| anyhow!("perturb: the scene has no object {:?}", self.object))?;
        let [dx, dy, dth] = self.start;
        let (s, c) = dth.sin_cos();
        let about = |p: &mut crate::Pose| {
            let (rx, ry) = (p.x - o.pose.x, p.y - o.pose.y);
            p.x = o.pose.x + c * rx - s * ry + dx;
            p.y = o.pose.y + s * rx + c * ry + dy;
            p.theta += dth;
        };
        about(&mut scene.robot.start);
        let mut op = o.pose;
        about(&mut op);
        o.pose = op;
        o.support_friction *= self.support_friction;
        o.pusher_friction *= self.pusher_friction;
        if self.cof_offset != [0.0, 0.0] {
            o.support = offset_support(&o.support, &o.outline, self.cof_offset)?;
        }
        Ok(())
    }
}

/// Support points of `support` over `outline`: its own points, or a 24 × 24 grid of points
/// inside the outline for uniform pressure; with their weights.
fn support_points(support: &Support, outline: &[[f64; 2]]) -> (Vec<[f64; 2]>, Vec<f64>) {
    match support {
        Support::Points { points, weights } => {
            let w = weights.clone().unwrap_or_else(|| vec![1.0; points.len()]);
            (points.clone(), w)
        }
        Support::Uniform => {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for v in outline {
                for k in 0..2 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            const N: usize = 24;
            let mut pts = Vec::new();
            for i in 0..N {
                for j in 0..N {
                    let x = lo[0] + (hi[0] - lo[0]) * (i as f64 + 0.5) / N as f64;
                    let y = lo[1] + (hi[1] - lo[1]) * (j as f64 + 0.5) / N as f64;
                    if point_in_polygon([x, y], outline) {
                        pts.push([x, y]);
                    }
                }
            }
            let n = pts.len();
            (pts, vec![1.0; n])
        }
    }
}

/// The support distribution with its centre of pressure (the centre of friction) moved by
/// `offset`: the weights tilted linearly, `w_i (1 + (p_i − c)·a)`, with `a` solving
/// `Cov · a = offset` so the weighted mean moves by exactly `offset`.
fn offset_support(support: &Support, outline: &[[f64; 2]], offset: [f64; 2]) -> Result<Support> {
    let (pts, w0) = support_points(support, outline);
    let total: f64 = w0.iter().sum();
    if pts.len() < 3 || total <= 0.0 {
        bail!("perturb: the object's support has too few points to move its centre of friction");
    }
    let mut c = [0.0; 2];
    for (p, w) in pts.iter().zip(&w0) {
        c[0] += w * p[0] / total;
        c[1] += w * p[1] / total;
    }
    let mut cov = [[0.0; 2]; 2];
    for (p, w) in pts.iter().zip(&w0) {
        let d = [p[0] - c[0], p[1] - c[1]];
        for i in 0..2 {
            for j in 0..2 {
                cov[i][j] += w * d[i] * d[j] / total;
            }
        }
    }
    let det = cov[0][0] * cov[1][1] - cov[0][1] * cov[1][0];
    if det.abs() < 1e-12 {
        bail!("perturb: the object's support points are collinear");
    }
    let a = [
        (cov[1][1] * offset[0] - cov[0][1] * offset[1]) / det,
        (-cov[1][0] * offset[0] + cov[0][0] * offset[1]) / det,
    ];
    let weights: Vec<f64> = pts
        .iter()
        .zip(&w0)
        .map(|(p, w)| w * (1.0 + (p[0] - c[0]) * a[0] + (p[1] - c[1]) * a[1]))
        .collect();
    if weights.iter().zip(&w0).any(|(w, w0)| *w <= 0.05 * w0) {
        bail!(
            "perturb: a centre of friction {:.1} mm off is too far for this object (the support \
             pressure would not stay positive); lower cof_offset",
            offset[0].hypot(offset[1]) * 1e3
        );
    }
    Ok(Support::Points {
        points: pts,
        weights: Some(weights),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pushing::Slider;

    fn scene() -> Scene {
        Scene::preset("fig15").unwrap()
    }

    #[test]
    fn a_draw_is_a_function_of_seed_and_trial_within_its_ranges() {
        let r = Perturb::default();
        let a = Perturbation::draw(&r, "slider", 1, 3);
        assert_eq!(a, Perturbation::draw(&r, "slider", 1, 3));
        assert_ne!(a, Perturbation::draw(&r, "slider", 1, 4));
        assert_ne!(a, Perturbation::draw(&r, "slider", 2, 3));
        for t in 0..200 {
            let p = Perturbation::draw(&r, "slider", 7, t);
            assert!(p.start[0].abs() <= 0.01 && p.start[1].abs() <= 0.01);
            assert!(p.start[2].abs() <= 5f64.to_radians());
            assert!((0.7..=1.3).contains(&p.pusher_friction));
            assert!((0.7..=1.3).contains(&p.support_friction));
            assert!(p.cof_offset[0].hypot(p.cof_offset[1]) <= 0.005 + 1e-12);
            assert!(p.wheel_slip.iter().all(|s| s.abs() <= 0.005));
        }
        let none = Perturbation::draw(&Perturb::none(), "slider", 7, 1);
        assert_eq!(none.start, [0.0; 3]);
        assert_eq!((none.pusher_friction, none.support_friction), (1.0, 1.0));
    }

    #[test]
    fn applied_it_moves_the_start_rigidly_and_the_centre_of_friction_exactly() {
        let mut s = scene();
        let id = s.objects[0].id.clone();
        let before = (s.objects[0].clone(), s.robot.start);
        let p = Perturbation {
            object: id.clone(),
            start: [0.004, -0.006, 3f64.to_radians()],
            support_friction: 1.2,
            pusher_friction: 0.8,
            cof_offset: [0.004, -0.003],
            wheel_slip: [0.0; 2],
            camera_xy: 0.0,
            camera_theta: 0.0,
        };
        p.apply(&mut s).unwrap();
        let o = &s.objects[0];
        assert!((o.pusher_friction - 0.8 * before.0.pusher_friction).abs() < 1e-12);
        assert!((o.support_friction - 1.2 * before.0.support_friction).abs() < 1e-12);
        assert!((o.pose.theta - before.0.pose.theta - 3f64.to_radians()).abs() < 1e-12);
        // The robot keeps its distance to the object (moved rigidly with it).
        let d = |a: crate::Pose, b: crate::Pose| (a.x - b.x).hypot(a.y - b.y);
        assert!((d(s.robot.start, o.pose) - d(before.1, before.0.pose)).abs() < 1e-12);
        let c0 = Slider::from_object(&before.0).cof;
        let c1 = Slider::from_object(o).cof;
        assert!(
            (c1[0] - c0[0] - 0.004).abs() < 5e-4 && (c1[1] - c0[1] + 0.003).abs() < 5e-4,
            "{c0:?} → {c1:?}"
        );
        let mut bad = p.clone();
        bad.object = "nothing".into();
        assert!(bad.apply(&mut scene()).is_err());
        bad = p;
        bad.cof_offset = [0.5, 0.0];
        assert!(bad.apply(&mut scene()).is_err());
    }
}
