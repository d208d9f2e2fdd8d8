//! A frame grabber: a thread that reads a camera continuously and keeps only the newest frame,
//! so a host that looks only now and then always sees the present (and a camera socket or
//! V4L2 queue never backs up while the host plans).

use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::vision::source::{Frame, FrameSource, SourceError, open_source};

#[derive(Default)]
struct Slot {
    /// The newest frame and how many frames were grabbed before it.
    latest: Option<(u64, Frame)>,
    /// Why the source stopped, once it has.
    ended: Option<String>,
    /// Frames the source could not give (corrupt or truncated), skipped.
    bad_frames: u64,
}

/// The newest frame of a camera, read on a background thread.
pub struct FrameGrabber {
    describe: String,
    shared: Arc<(Mutex<Slot>, Condvar)>,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for FrameGrabber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameGrabber")
            .field("source", &self.describe)
            .finish()
    }
}

impl FrameGrabber {
    /// Open the camera `spec` (as `--camera` spells it) and start grabbing.
    pub fn open(spec: &str, fps: f64) -> Result<FrameGrabber, SourceError> {
        let (tx, rx) = std::sync::mpsc::channel();
        let shared: Arc<(Mutex<Slot>, Condvar)> = Arc::default();
        let sh = Arc::clone(&shared);
        let spec = spec.to_owned();
        let thread = std::thread::Builder::new()
            .name("frame-grabber".into())
            .spawn(move || {
                let mut src = match open_source(&spec, fps) {
                    Ok(s) => {
                        let _ = tx.send(Ok(s.describe()));
                        s
                    }
                    Err(e) => {
                        let _ = tx.send(Err(e));
                        return;
                    }
                };
                grab(src.as_mut(), &sh);
                drop(sh);
            })
            .map_err(|e| SourceError::Read(format!("starting the frame grabber: {e}")))?;
        let describe = match rx.recv() {
            Ok(Ok(d)) => d,
            Ok(Err(e)) => return Err(e),
            Err(_) => return Err(SourceError::Read("the frame grabber died".into())),
        };
        Ok(FrameGrabber {
            describe,
            shared,
            thread: Some(thread),
        })
    }

    /// The source's description.
    pub fn describe(&self) -> &str {
        &self.describe
    }

    /// How many bad frames (corrupt or truncated) the source skipped so far.
    pub fn bad_frames(&self) -> u64 {
        lock(&self.shared.0).bad_frames
    }

    /// How many frames have been grabbed so far.
    pub fn count(&self) -> u64 {
        lock(&self.shared.0).latest.as_ref().map_or(0, |(n, _)| *n)
    }

    /// The first frame grabbed after frame number `after` (see [`FrameGrabber::count`]),
    /// waiting up to `timeout`; with its number.
    pub fn next_after(&self, after: u64, timeout: Duration) -> Result<(u64, Frame), SourceError> {
        let deadline = Instant::now() + timeout;
        let (m, cv) = &*self.shared;
        let mut slot = lock(m);
        loop {
            if let Some((n, f)) = &slot.latest
                && *n > after
            {
                return Ok((*n, f.clone()));
            }
            if let Some(why) = &slot.ended {
                return Err(SourceError::Read(format!("{}: {why}", self.describe)));
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(SourceError::Read(format!(
                    "{}: no new frame within {:.1} s",
                    self.describe,
                    timeout.as_secs_f64()
                )));
            }
            slot = cv
                .wait_timeout(slot, deadline - now)
                .map(|(g, _)| g)
                .unwrap_or_else(|e| e.into_inner().0);
        }
    }
}

impl Drop for FrameGrabber {
    fn drop(&mut self) {
        // The thread ends when its source does; a live source is dropped with the process.
        // Do not join: a blocked read cannot be interrupted portably.
        drop(self.thread.take());
    }
}

fn grab(src: &mut dyn FrameSource, shared: &Arc<(Mutex<Slot>, Condvar)>) {
    let (m, cv) = &**shared;
    let mut n = 0u64;
    loop {
        let next = src.next_frame();
        let mut slot = lock(m);
        match next {
            Ok(Some(frame)) => {
                n += 1;
                slot.latest = Some((n, frame));
            }
            Ok(None) => {
                slot.ended = Some("the source ended".into());
                cv.notify_all();
                return;
            }
            Err(SourceError::BadFrame(e)) => {
                slot.bad_frames += 1;
                tracing::warn!("camera: a bad frame skipped: {e}");
            }
            Err(e) => {
                slot.ended = Some(e.to_string());
                cv.notify_all();
                return;
            }
        }
        drop(slot);
        cv.notify_all();
        if Arc::strong_count(shared) == 1 {
            // The grabber was dropped: nobody looks any more.
            return;
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}
