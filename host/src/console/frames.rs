//! The camera's newest frame as JPEG for the page, encoded once on one thread for every browser
//! watching, at most [`MAX_FPS`] a second and only while someone watches.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use crate::exec::grabber::FrameGrabber;

/// The most frames a second the page is sent.
pub const MAX_FPS: f64 = 15.0;

/// The JPEG stream.
pub struct Frames {
    latest: tokio::sync::watch::Receiver<Option<Arc<Vec<u8>>>>,
    watchers: Arc<AtomicUsize>,
}

impl Frames {
    /// Start encoding the frames of `grabber`.
    pub fn start(grabber: Arc<FrameGrabber>) -> Frames {
        let (tx, rx) = tokio::sync::watch::channel(None);
        let watchers = Arc::new(AtomicUsize::new(0));
        let w = Arc::clone(&watchers);
        let spawned = std::thread::Builder::new()
            .name("console-frames".into())
            .spawn(move || {
                let mut last = 0;
                let period = Duration::from_secs_f64(1.0 / MAX_FPS);
                loop {
                    if tx.is_closed() {
                        return;
                    }
                    if w.load(Ordering::Relaxed) == 0 {
                        std::thread::sleep(Duration::from_millis(100));
                        continue;
                    }
                    let t0 = Instant::now();
                    if let Ok((n, frame)) = grabber.next_after(last, Duration::from_millis(500)) {
                        last = n;
                        if let Some(jpeg) = jpeg(&frame) {
                            let _ = tx.send(Some(Arc::new(jpeg)));
                        }
                    }
                    if let Some(rest) = period.checked_sub(t0.elapsed()) {
                        std::thread::sleep(rest);
                    }
                }
            });
        if let Err(e) = spawned {
            tracing::warn!("console: no camera stream: {e}");
        }
        Frames {
            latest: rx,
            watchers,
        }
    }

    /// A receiver of the newest JPEG; counts as a watcher until the guard is dropped.
    pub fn watch(&self) -> (tokio::sync::watch::Receiver<Option<Arc<Vec<u8>>>>, Watcher) {
        self.watchers.fetch_add(1, Ordering::Relaxed);
        (self.latest.clone(), Watcher(Arc::clone(&self.watchers)))
    }
}

/// One browser watching the camera.
pub struct Watcher(Arc<AtomicUsize>);

impl Drop for Watcher {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

fn jpeg(frame: &crate::vision::frame::Frame) -> Option<Vec<u8>> {
    let mut out = Vec::new();
    let mut enc = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 70);
    enc.encode(
        &frame.pixels,
        frame.width,
        frame.height,
        image::ExtendedColorType::L8,
    )
    .ok()?;
    Some(out)
}
