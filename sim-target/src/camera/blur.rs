//! The optics' blur: a separable Gaussian with clamped edges, of a whole image or of a window
//! of it (exactly as the whole image's blur gives that window, so a frame that changed only in
//! a part is blurred there alone).

use super::render::Window;

/// Separable Gaussian blur with standard deviation `sigma` pixels (edges clamped). Both passes
/// run along rows (the vertical one adds whole shifted rows), so the inner loops vectorise.
pub fn gaussian_blur(data: &mut [f32], width: usize, height: usize, sigma: f64) {
    if sigma <= 0.0 || width == 0 || height == 0 || data.len() < width * height {
        return;
    }
    let sharp = data[..width * height].to_vec();
    gaussian_blur_window(
        &sharp,
        data,
        width,
        height,
        sigma,
        Window::full(width, height),
    );
}

/// The Gaussian blur of `sharp` (`width × height`, edges clamped) written into `window` of
/// `out` (the same size), the rest of `out` untouched: each pixel exactly as the blur of the
/// whole image gives it, so a frame in which only a part changed is blurred there alone.
pub fn gaussian_blur_window(
    sharp: &[f32],
    out: &mut [f32],
    width: usize,
    height: usize,
    sigma: f64,
    window: Window,
) {
    let n = width * height;
    let w = Window {
        x1: window.x1.min(width),
        y1: window.y1.min(height),
        ..window
    };
    if w.is_empty() || sharp.len() < n || out.len() < n {
        return;
    }
    if !(sigma > 0.0 && sigma.is_finite()) {
        for y in w.y0..w.y1 {
            out[y * width + w.x0..y * width + w.x1]
                .copy_from_slice(&sharp[y * width + w.x0..y * width + w.x1]);
        }
        return;
    }
    let r = (3.0 * sigma).ceil() as usize;
    let mut k: Vec<f32> = (0..=2 * r)
        .map(|i| {
            let d = i as f64 - r as f64;
            (-(d * d) / (2.0 * sigma * sigma)).exp() as f32
        })
        .collect();
    let sum: f32 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
    // Horizontal, over the rows the vertical pass reads: each row's part padded with its
    // neighbours (clamped at the image's edges), then a dense convolution.
    let cols = w.x1 - w.x0;
    let (ya, yb) = (w.y0.saturating_sub(r), (w.y1 + r).min(height));
    let mut padded = vec![0.0f32; cols + 2 * r];
    let mut tmp = vec![0.0f32; cols * (yb - ya)];
    for (yy, row_out) in (ya..yb).zip(tmp.chunks_exact_mut(cols)) {
        let row = &sharp[yy * width..(yy + 1) * width];
        for (j, p) in padded.iter_mut().enumerate() {
            *p = row[(w.x0 + j).saturating_sub(r).min(width - 1)];
        }
        for (t, &kv) in k.iter().enumerate() {
            for (o, &v) in row_out.iter_mut().zip(&padded[t..t + cols]) {
                *o += kv * v;
            }
        }
    }
    // Vertical: output row y is the weighted sum of rows y − r … y + r (clamped).
    for y in w.y0..w.y1 {
        let o = &mut out[y * width + w.x0..y * width + w.x1];
        o.fill(0.0);
        for (t, &kv) in k.iter().enumerate() {
            let yy = (y + t).saturating_sub(r).min(height - 1) - ya;
            let src = &tmp[yy * cols..(yy + 1) * cols];
            for (o, &v) in o.iter_mut().zip(src) {
                *o += kv * v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_keeps_mean() {
        let mut d = vec![0.0f32; 100];
        d[55] = 1.0;
        gaussian_blur(&mut d, 10, 10, 0.8);
        let s: f32 = d.iter().sum();
        assert!((s - 1.0).abs() < 1e-4);
        assert!(d[55] < 0.5 && d[54] > 0.0);
    }

    /// The separable blur equals the direct 2-D convolution with clamped edges, at the edges
    /// too.
    #[test]
    fn blur_matches_the_direct_convolution() {
        use rand::{Rng, SeedableRng};
        let (w, h, sigma) = (13usize, 9usize, 0.9);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let img: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
        let mut fast = img.clone();
        gaussian_blur(&mut fast, w, h, sigma);
        let r = (3.0 * sigma).ceil() as isize;
        let g = |d: isize| (-((d * d) as f64) / (2.0 * sigma * sigma)).exp();
        let norm: f64 = (-r..=r).map(g).sum();
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut acc = 0.0;
                for dy in -r..=r {
                    for dx in -r..=r {
                        let xx = (x + dx).clamp(0, w as isize - 1) as usize;
                        let yy = (y + dy).clamp(0, h as isize - 1) as usize;
                        acc += g(dx) * g(dy) * f64::from(img[yy * w + xx]);
                    }
                }
                let want = acc / (norm * norm);
                let got = f64::from(fast[y as usize * w + x as usize]);
                assert!((got - want).abs() < 1e-5, "({x}, {y}): {got} vs {want}");
            }
        }
    }

    /// A window of the blur is the whole image's blur there, bit for bit (at the image's
    /// edges too), and leaves the rest of the output as it was.
    #[test]
    fn a_window_of_the_blur_is_the_blur_of_the_whole_there() {
        use rand::{Rng, SeedableRng};
        let (w, h, sigma) = (40usize, 30usize, 0.7);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let img: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
        let mut whole = img.clone();
        gaussian_blur(&mut whole, w, h, sigma);
        for win in [
            Window {
                x0: 5,
                y0: 7,
                x1: 17,
                y1: 12,
            },
            Window {
                x0: 0,
                y0: 0,
                x1: 3,
                y1: 30,
            },
            Window {
                x0: 33,
                y0: 25,
                x1: 40,
                y1: 30,
            },
        ] {
            let mut out = vec![-1.0f32; w * h];
            gaussian_blur_window(&img, &mut out, w, h, sigma, win);
            for y in 0..h {
                for x in 0..w {
                    let inside = (win.x0..win.x1).contains(&x) && (win.y0..win.y1).contains(&y);
                    let want = if inside { whole[y * w + x] } else { -1.0 };
                    assert_eq!(out[y * w + x], want, "({x}, {y}) in {win:?}");
                }
            }
        }
    }
}
