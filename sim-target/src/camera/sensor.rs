//! The camera's sensor: what light it is given becomes 8-bit gray levels through the exposure,
//! the black and white levels, and a fresh Gaussian read noise in every pixel of every frame.
//!
//! The noise is drawn by inverse transform: 16 random bits pick one of 65 536 equally likely
//! quantiles of the standard normal distribution (computed once a process), so four pixels take
//! one 64-bit draw of the seeded generator. Within the table's resolution that is the Gaussian
//! itself, its tails cut at 4.3 σ; a frame develops in about a millisecond, where sampling the
//! normal distribution pixel by pixel took ten (`cargo bench -p pushbot-sim --bench camera`).

use std::sync::OnceLock;

use rand::RngCore;

use super::render::Window;

/// Random bits per pixel, and so the size of the quantile table.
const BITS: u32 = 16;

/// The standard normal distribution's quantiles at `(i + 0.5) / 2¹⁶`, `i = 0 … 2¹⁶ − 1`.
pub fn normal_quantiles() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = 1usize << BITS;
        let mut q = vec![0.0f32; n];
        // The lower half by Newton's method on Φ(x) − p, each from the one before (p grows),
        // kept in its bracket by bisection; the upper half by symmetry.
        let mut lo = -10.0f64;
        for i in 0..n / 2 {
            let p = (i as f64 + 0.5) / n as f64;
            let x = normal_quantile(p, lo, 0.0);
            q[i] = x as f32;
            q[n - 1 - i] = -x as f32;
            lo = x;
        }
        q
    })
}

/// The standard normal quantile of `p` (below one half) within `[lo, hi]`.
fn normal_quantile(p: f64, mut lo: f64, mut hi: f64) -> f64 {
    let cdf = |x: f64| 0.5 * libm::erfc(-x / std::f64::consts::SQRT_2);
    let pdf = |x: f64| (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let mut x = lo;
    for _ in 0..200 {
        let f = cdf(x) - p;
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - f / pdf(x);
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - x).abs() < 1e-13 {
            return next;
        }
        x = next;
    }
    x
}

/// Develop an image: gray level = `black + (white − black) · exposure · irradiance + noise`,
/// rounded and clamped to 8 bits, with Gaussian noise of `noise_sigma` gray levels drawn from
/// `rng`.
pub fn develop(
    data: &[f32],
    exposure: f64,
    black: f64,
    white: f64,
    noise_sigma: f64,
    rng: &mut impl RngCore,
) -> Vec<u8> {
    let mut out = vec![0u8; data.len()];
    Levels::new(exposure, black, white, noise_sigma).develop_into(&mut out, data, rng);
    out
}

/// Develop only `windows` of an image `width` pixels wide through `levels` (as [`develop`] does, with noise
/// drawn for their pixels alone); every other pixel is 0. A reader that looks only there (a
/// tracker searching regions around its markers) gets the frame at a fraction of the cost.
pub fn develop_within(
    data: &[f32],
    width: usize,
    windows: &[Window],
    levels: &Levels,
    rng: &mut impl RngCore,
) -> Vec<u8> {
    let mut out = vec![0u8; data.len()];
    let height = data.len().checked_div(width).unwrap_or(0);
    for w in windows {
        let (x1, y1) = (w.x1.min(width), w.y1.min(height));
        for y in w.y0..y1 {
            if w.x0 < x1 {
                let span = y * width + w.x0..y * width + x1;
                levels.develop_into(&mut out[span.clone()], &data[span], rng);
            }
        }
    }
    out
}

/// The sensor's transfer from irradiance to gray levels, with its read noise.
#[derive(Debug, Clone, Copy)]
pub struct Levels {
    gain: f32,
    black: f32,
    /// Read noise, gray levels (0: none).
    sigma: f32,
}

impl Levels {
    /// Gray level `black + (white − black) · exposure · irradiance`, plus Gaussian noise of
    /// `noise_sigma` gray levels (none when 0).
    pub fn new(exposure: f64, black: f64, white: f64, noise_sigma: f64) -> Levels {
        let noisy = noise_sigma > 0.0 && noise_sigma.is_finite();
        Levels {
            gain: ((white - black) * exposure) as f32,
            black: black as f32,
            sigma: if noisy { noise_sigma as f32 } else { 0.0 },
        }
    }

    /// Develop `data` into `out` (the same length).
    fn develop_into(&self, out: &mut [u8], data: &[f32], rng: &mut impl RngCore) {
        let (gain, black) = (self.gain, self.black);
        let level = |v: f32| (v.clamp(0.0, 255.0) + 0.5) as u8;
        if self.sigma == 0.0 {
            for (o, &r) in out.iter_mut().zip(data) {
                *o = level(black + gain * r);
            }
            return;
        }
        let sigma = self.sigma;
        let table = normal_quantiles();
        let per_draw = (64 / BITS) as usize;
        for (o, d) in out.chunks_mut(per_draw).zip(data.chunks(per_draw)) {
            let bits = rng.next_u64();
            for (k, (o, &r)) in o.iter_mut().zip(d).enumerate() {
                let z = table[((bits >> (BITS as usize * k)) & ((1 << BITS) - 1)) as usize];
                *o = level(black + gain * r + sigma * z);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Known quantiles of the standard normal distribution, and the table's symmetry.
    #[test]
    fn the_table_holds_the_normal_quantiles() {
        let q = normal_quantiles();
        assert_eq!(q.len(), 65_536);
        assert!(q.windows(2).all(|w| w[0] < w[1]), "increasing");
        assert!(
            q.iter().zip(q.iter().rev()).all(|(a, b)| *a == -*b),
            "symmetric"
        );
        // Φ⁻¹(0.975) = 1.959964, Φ⁻¹(0.841345) = 1.0, Φ⁻¹(0.5 + 0.5/65536) = 1.91241e-5.
        assert!((normal_quantile(0.025, -10.0, 0.0) + 1.959_963_985).abs() < 1e-8);
        assert!((normal_quantile(0.158_655_253_9, -10.0, 0.0) + 1.0).abs() < 1e-8);
        assert!((f64::from(q[32_768]) - 1.912_41e-5).abs() < 1e-9);
        assert!((f64::from(q[0]) + 4.324).abs() < 1e-3, "tail {}", q[0]);
    }

    /// A uniform gray developed with noise: the mean and the spread of the Gaussian (plus the
    /// rounding's 1/12), two thirds within one σ, and neighbours independent.
    #[test]
    fn noise_is_gaussian_and_independent_between_pixels() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let data = vec![0.5f32; 400_000];
        let px = develop(&data, 1.0, 20.0, 220.0, 3.0, &mut rng);
        let v: Vec<f64> = px.iter().map(|&p| f64::from(p) - 120.0).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n;
        assert!(mean.abs() < 0.02, "mean {mean}");
        assert!((var - (9.0 + 1.0 / 12.0)).abs() < 0.1, "variance {var}");
        let within = v.iter().filter(|x| x.abs() <= 3.0).count() as f64 / n;
        // P(|N(0, 3) + rounding| ≤ 3 gray levels) = P(|N| < 3.5 / 3) = 0.7566.
        assert!((within - 0.7566).abs() < 0.005, "within one σ: {within}");
        for lag in 1..=4 {
            let c = v.iter().zip(&v[lag..]).map(|(a, b)| a * b).sum::<f64>() / (n * var);
            assert!(c.abs() < 0.01, "correlation at lag {lag}: {c}");
        }
        // The next frame's noise is fresh.
        let px2 = develop(&data, 1.0, 20.0, 220.0, 3.0, &mut rng);
        let same = px.iter().zip(&px2).filter(|(a, b)| a == b).count() as f64 / n;
        assert!(same < 0.2, "{same} of the pixels repeat");
    }

    /// Without noise the levels are exact, rounded and clamped.
    #[test]
    fn levels_round_and_clamp() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let px = develop(&[0.0, 0.5, 1.0, 2.0, -1.0], 1.0, 20.0, 235.0, 0.0, &mut rng);
        assert_eq!(px, vec![20, 128, 235, 255, 0]);
    }

    /// Developed within windows: the same levels and noise there, nothing elsewhere.
    #[test]
    fn developing_windows_develops_them_alone() {
        let (w, h) = (64usize, 48usize);
        let data: Vec<f32> = (0..w * h).map(|i| (i % 97) as f32 / 96.0).collect();
        let windows = [
            Window {
                x0: 3,
                y0: 2,
                x1: 20,
                y1: 10,
            },
            Window {
                x0: 50,
                y0: 40,
                x1: 70,
                y1: 60,
            },
        ];
        let exact = develop(
            &data,
            1.0,
            20.0,
            235.0,
            0.0,
            &mut rand_chacha::ChaCha8Rng::seed_from_u64(1),
        );
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let exact_levels = Levels::new(1.0, 20.0, 235.0, 0.0);
        let part = develop_within(&data, w, &windows, &exact_levels, &mut rng);
        let noisy_levels = Levels::new(1.0, 20.0, 235.0, 3.0);
        let noisy = develop_within(&data, w, &windows, &noisy_levels, &mut rng);
        let inside = |x: usize, y: usize| {
            windows
                .iter()
                .any(|v| (v.x0..v.x1).contains(&x) && (v.y0..v.y1).contains(&y))
        };
        let (mut n, mut err) = (0, 0.0);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if inside(x, y) {
                    assert_eq!(part[i], exact[i], "({x}, {y})");
                    err += (f64::from(noisy[i]) - f64::from(exact[i])).powi(2);
                    n += 1;
                } else {
                    assert_eq!((part[i], noisy[i]), (0, 0), "({x}, {y}) outside");
                }
            }
        }
        let rms = (err / f64::from(n)).sqrt();
        assert!((2.5..3.5).contains(&rms), "noise {rms} gray levels");
    }
}
