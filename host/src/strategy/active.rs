//! Active selection of the pushes that build the pushing strategy: the extension of Lau, Mitani
//! & Igarashi's Algorithm 1 (§III-C initial collection) that pushes where the strategy is least
//! sure what a push does, instead of at random.
//!
//! The strategy knows what a push r from robot position p does (the object's motion s) only
//! through samples near (p, r); [`push_density`] is their Gaussian-kernel weight in
//! (p_x, p_y, r_x, r_y), and [`least_known`] picks, among candidate pushes, the one with the
//! least. Which supplemental pushes are kept is [`super::regression::Admission`].

use super::sample::Sample;

/// How the initial collection chooses its next push.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Selection {
    /// A random spin and push length (the paper).
    Random,
    /// Among random candidates, the push the strategy knows least ([`least_known`]).
    Uncertain,
}

impl Selection {
    /// The selection's name, as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Selection::Random => "random",
            Selection::Uncertain => "uncertain",
        }
    }
}

/// Kernel weight of the samples around the push r from p (object frame): Σ exp(−d²/w²) over
/// the samples, d the distance in (p_x, p_y, r_x, r_y). Near 0 where the strategy has never
/// pushed.
pub fn push_density(samples: &[Sample], p: [f64; 2], r: [f64; 2], width: f64) -> f64 {
    let w2 = width * width;
    samples
        .iter()
        .map(|s| {
            let d2 = (s.p[0] - p[0]).powi(2)
                + (s.p[1] - p[1]).powi(2)
                + (s.r[0] - r[0]).powi(2)
                + (s.r[1] - r[1]).powi(2);
            (-d2 / w2).exp()
        })
        .sum()
}

/// Index of the candidate robot motion (object frame, from `p`) with the least
/// [`push_density`]; the first on ties, `None` without candidates.
pub fn least_known(
    samples: &[Sample],
    p: [f64; 2],
    candidates: &[[f64; 2]],
    width: f64,
) -> Option<usize> {
    candidates
        .iter()
        .map(|r| push_density(samples, p, *r, width))
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
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
}
