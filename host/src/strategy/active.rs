//! Active selection of the pushes that build the pushing strategy: the extension of Lau, Mitani
//! & Igarashi's Algorithm 1 (§III-C initial collection) that pushes where the strategy is least
//! sure what a push does, instead of at random.
//!
//! The strategy knows what a push r from robot position p does (the object's motion s) only
//! through samples near (p, r); [`push_density`] is their Gaussian-kernel weight in
//! (p_x, p_y, r_x, r_y), and [`least_known`] picks, among candidate pushes, the one with the
//! least. [`least_known_ahead`] also counts how well the strategy knows the place the robot is
//! expected to touch the object after the push ([`next_contact`]), so the collection moves on
//! to contacts it has not pushed from. Which supplemental pushes are kept is
//! [`super::regression::Admission`].

use super::sample::Sample;

/// How the initial collection chooses its next push.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Selection {
    /// A random spin and push length (the paper).
    Random,
    /// Among random candidates, the push the strategy knows least ([`least_known`]).
    Uncertain,
    /// Among random candidates, the push that, with the contact it leads to, the strategy knows
    /// least ([`least_known_ahead`]).
    Explore,
}

impl Selection {
    /// The selection's name, as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Selection::Random => "random",
            Selection::Uncertain => "uncertain",
            Selection::Explore => "explore",
        }
    }
}

/// Kernel weight of the samples around the push r from p (object frame): Σ exp(−d²/w²) over
/// the samples, d the distance in (p_x, p_y, r_x, r_y). Near 0 where the strategy has never
/// pushed.
pub fn push_density(samples: &[Sample], p: [f64; 2], r: [f64; 2], width: f64) -> f64 {
    samples.iter().map(|s| kernel(s, p, r, width)).sum()
}

/// One sample's Gaussian weight around the push r from p: exp(−d²/w²), d in (p, r).
fn kernel(s: &Sample, p: [f64; 2], r: [f64; 2], width: f64) -> f64 {
    let d2 = (s.p[0] - p[0]).powi(2)
        + (s.p[1] - p[1]).powi(2)
        + (s.r[0] - r[0]).powi(2)
        + (s.r[1] - r[1]).powi(2);
    (-d2 / (width * width)).exp()
}

/// Index of the least score, the first on ties; `None` without scores.
fn least(scores: impl Iterator<Item = f64>) -> Option<usize> {
    scores
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Index of the candidate robot motion (object frame, from `p`) with the least
/// [`push_density`]; the first on ties, `None` without candidates.
pub fn least_known(
    samples: &[Sample],
    p: [f64; 2],
    candidates: &[[f64; 2]],
    width: f64,
) -> Option<usize> {
    least(
        candidates
            .iter()
            .map(|r| push_density(samples, p, *r, width)),
    )
}

/// Where the robot is expected to touch the object after the push `r` from `p` (object frame,
/// in the object's frame after the push): `p + r − s` turned by `−θ`, with `s` and `θ` the
/// [`push_density`]-weighted means of the samples around (p, r). `None` where no sample is near.
pub fn next_contact(samples: &[Sample], p: [f64; 2], r: [f64; 2], width: f64) -> Option<[f64; 2]> {
    let (mut sum, mut sx, mut sy, mut st) = (0.0, 0.0, 0.0, 0.0);
    for s in samples {
        let w = kernel(s, p, r, width);
        sum += w;
        sx += w * s.s[0];
        sy += w * s.s[1];
        st += w * s.theta;
    }
    if sum < 1e-3 {
        return None;
    }
    let (x, y, t) = (p[0] + r[0] - sx / sum, p[1] + r[1] - sy / sum, st / sum);
    let (c, sn) = (t.cos(), t.sin());
    Some([c * x + sn * y, -sn * x + c * y])
}

/// Kernel weight of the samples pushed from around `p` (object frame), whatever their push.
pub fn contact_density(samples: &[Sample], p: [f64; 2], width: f64) -> f64 {
    let w2 = width * width;
    samples
        .iter()
        .map(|s| (-((s.p[0] - p[0]).powi(2) + (s.p[1] - p[1]).powi(2)) / w2).exp())
        .sum()
}

/// Index of the candidate robot motion (object frame, from `p`) with the least
/// [`push_density`] plus [`contact_density`] at its [`next_contact`] (0 where the strategy
/// cannot tell where the robot ends): the push that is new and leads to a contact that is new.
/// The first on ties, `None` without candidates.
pub fn least_known_ahead(
    samples: &[Sample],
    p: [f64; 2],
    candidates: &[[f64; 2]],
    width: f64,
) -> Option<usize> {
    least(candidates.iter().map(|r| {
        let ahead =
            next_contact(samples, p, *r, width).map_or(0.0, |q| contact_density(samples, q, width));
        push_density(samples, p, *r, width) + ahead
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_known_push_is_the_one_away_from_the_samples() {
        // Every sample pushes along +x from (−0.1, 0): a push along +y is the unknown one.
        let s = Sample {
            p: [-0.1, 0.0],
            r: [0.04, 0.0],
            s: [0.03, 0.0],
            theta: 0.0,
        };
        let samples = vec![s; 20];
        let cands = [[0.04, 0.0], [0.03, 0.01], [0.0, 0.04]];
        assert_eq!(least_known(&samples, s.p, &cands, 0.018), Some(2));
        assert!(push_density(&samples, s.p, [0.04, 0.0], 0.018) > 19.9);
        assert_eq!(least_known(&samples, s.p, &[], 0.018), None);
        // Without samples every push is unknown alike: the first wins.
        assert_eq!(least_known(&[], s.p, &cands, 0.018), Some(0));
    }

    #[test]
    fn the_next_contact_follows_the_objects_motion_and_turn() {
        // Pushed 4 cm along +x from (−0.1, 0), the object moved 3 cm and turned 90°: the robot,
        // 1 cm further in, is at (−0.09, 0) in the old frame, (0, 0.09) in the turned one.
        let s = Sample {
            p: [-0.1, 0.0],
            r: [0.04, 0.0],
            s: [0.03, 0.0],
            theta: std::f64::consts::FRAC_PI_2,
        };
        let q = next_contact(&[s], s.p, s.r, 0.018).unwrap();
        assert!(
            (q[0] - 0.0).abs() < 1e-9 && (q[1] - 0.09).abs() < 1e-9,
            "{q:?}"
        );
        // Far from every sample the strategy cannot tell.
        assert_eq!(next_contact(&[s], [0.1, 0.1], s.r, 0.018), None);
        assert!(contact_density(&[s; 3], s.p, 0.018) > 2.99);
        assert!(contact_density(&[s; 3], [0.0, 0.09], 0.018) < 1e-6);
    }

    #[test]
    fn exploring_prefers_a_push_that_leads_to_an_unknown_contact() {
        // From (−0.1, 0) two pushes: a straight one, after which the robot stays at the same
        // contact (pushed from there 21 times), and a turning one, known a little better, after
        // which it touches the object where it never pushed.
        let straight = Sample {
            p: [-0.1, 0.0],
            r: [0.04, 0.0],
            s: [0.04, 0.0],
            theta: 0.0,
        };
        let turning = Sample {
            p: [-0.1, 0.0],
            r: [0.0, 0.04],
            s: [0.0, 0.0],
            theta: 0.6,
        };
        let mut samples = vec![straight; 10];
        samples.extend(vec![turning; 11]);
        let cands = [straight.r, turning.r];
        let (a, b) = (
            push_density(&samples, straight.p, straight.r, 0.018),
            push_density(&samples, straight.p, turning.r, 0.018),
        );
        assert!(a < b, "{a} {b}");
        assert_eq!(least_known(&samples, straight.p, &cands, 0.018), Some(0));
        assert_eq!(
            least_known_ahead(&samples, straight.p, &cands, 0.018),
            Some(1)
        );
        assert_eq!(least_known_ahead(&samples, straight.p, &[], 0.018), None);
    }
}
