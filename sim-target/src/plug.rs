//! The robot's USB port as a user sees it: a stable path to the current pseudo-terminal (a
//! symlink, as udev keeps `/dev/serial/by-id/…`), which can be unplugged — the pty closes under
//! the host and the path vanishes — and plugged back: a new pty behind the same path, as after a
//! USB re-enumeration. This makes a host's `--reconnect` testable without hardware.
//!
//! Unplugs come from a schedule in simulated time ([`Unplug`], `pushbot-sim --unplug-at`) or
//! on request ([`crate::PtySim::unplug`]). While unplugged, the robot keeps running (its link
//! watchdog sees silence) and every byte either way is lost.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{Context, Result, bail};

use crate::terminal::Pty;

/// One unplug: at `at_us` of simulated time the port goes away for `for_us`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unplug {
    /// When, µs of simulated time.
    pub at_us: u64,
    /// How long the port stays away, µs of simulated time.
    pub for_us: u64,
}

/// What the served robot and its [`crate::PtySim`] handle share about the port.
#[derive(Debug, Default)]
pub(crate) struct PlugShared {
    /// Unplugs asked for through the handle: how long each, µs of simulated time.
    pub requests: Mutex<Vec<u64>>,
    /// Unplugs that have happened.
    pub unplugs: AtomicU32,
    /// Re-plugs that have happened (a new pty served behind the link).
    pub replugs: AtomicU32,
}

/// The served port: a pty that may be absent (unplugged), behind an optional stable link.
pub(crate) struct Port {
    pty: Option<Pty>,
    link: Option<PathBuf>,
    /// Scheduled unplugs still to come, earliest last.
    schedule: Vec<Unplug>,
    /// When the port comes back, while it is away.
    replug_at: Option<u64>,
    shared: Arc<PlugShared>,
}

/// Point `link` at `target`, replacing an older symlink atomically (a symlink beside it, then a
/// rename); refuses to replace anything that is not a symlink.
fn point(link: &Path, target: &str) -> Result<()> {
    if let Ok(meta) = std::fs::symlink_metadata(link)
        && !meta.file_type().is_symlink()
    {
        bail!(
            "{} exists and is not a symlink: refusing to replace it with the robot's port",
            link.display()
        );
    }
    let mut tmp = link.as_os_str().to_owned();
    tmp.push(format!(".{}.tmp", std::process::id()));
    let tmp = PathBuf::from(tmp);
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(target, &tmp)
        .with_context(|| format!("creating the link {}", tmp.display()))?;
    std::fs::rename(&tmp, link).with_context(|| format!("creating the link {}", link.display()))
}

impl Port {
    /// Open a pty (and point `link` at it); `schedule` in any order.
    pub fn open(
        link: Option<PathBuf>,
        mut schedule: Vec<Unplug>,
        shared: Arc<PlugShared>,
    ) -> Result<Port> {
        if !schedule.is_empty() && link.is_none() {
            bail!("unplugging the port needs a stable path for it (--link PATH)");
        }
        schedule.sort_by_key(|u| std::cmp::Reverse(u.at_us));
        let pty = Pty::open()?;
        if let Some(l) = &link {
            point(l, pty.path())?;
        }
        Ok(Port {
            pty: Some(pty),
            link,
            schedule,
            replug_at: None,
            shared,
        })
    }

    /// The path a host opens: the link if there is one, else the pty's own.
    pub fn host_path(&self) -> String {
        match (&self.link, &self.pty) {
            (Some(l), _) => l.display().to_string(),
            (None, Some(p)) => p.path().to_owned(),
            (None, None) => String::new(),
        }
    }

    /// Unplug or plug back as the schedule, the requests and `now_us` say.
    pub fn step(&mut self, now_us: u64) -> Result<()> {
        if let Some(at) = self.replug_at {
            if now_us >= at {
                let pty = Pty::open()?;
                // Counted before the link shows the new pty (as an unplug is).
                self.shared.replugs.fetch_add(1, Ordering::SeqCst);
                if let Some(l) = &self.link {
                    point(l, pty.path())?;
                }
                tracing::info!("port plugged back in: {}", pty.path());
                self.pty = Some(pty);
                self.replug_at = None;
            }
            return Ok(());
        }
        let requested = match self.shared.requests.lock() {
            Ok(mut r) => r.pop(),
            Err(p) => p.into_inner().pop(),
        };
        let scheduled = match self.schedule.last() {
            Some(u) if u.at_us <= now_us => self.schedule.pop().map(|u| u.for_us),
            _ => None,
        };
        if let Some(for_us) = requested.or(scheduled) {
            if self.link.is_none() {
                // A request without a link: PtySim::unplug refuses it before it gets here.
                return Ok(());
            }
            // Counted before the host can see it: a host that gives up at once and asks how
            // many unplugs there were must not find the one that ended its session missing.
            self.shared.unplugs.fetch_add(1, Ordering::SeqCst);
            if let Some(l) = &self.link {
                let _ = std::fs::remove_file(l);
            }
            tracing::info!("port unplugged for {} ms", for_us / 1000);
            self.pty = None;
            self.replug_at = Some(now_us.saturating_add(for_us));
        }
        Ok(())
    }

    /// Read what arrived from the host (0 while unplugged).
    pub fn read(&mut self, buf: &mut [u8]) -> Result<usize> {
        self.pty.as_mut().map_or(Ok(0), |p| p.read(buf))
    }

    /// Write what fits; while unplugged every byte is taken and lost.
    pub fn write(&mut self, bytes: &[u8]) -> Result<usize> {
        self.pty
            .as_mut()
            .map_or(Ok(bytes.len()), |p| p.write(bytes))
    }

    /// Discard what was sent to the host but not read yet.
    pub fn discard_unread(&self) -> Result<()> {
        self.pty.as_ref().map_or(Ok(()), Pty::discard_unread)
    }

    /// Let any process open the port again.
    pub fn allow_reopen(&self) -> Result<()> {
        self.pty.as_ref().map_or(Ok(()), Pty::allow_reopen)
    }

    /// Wait until the host sent something or `timeout` passed (just wait while unplugged).
    pub fn wait_readable(&self, timeout: Duration) -> Result<bool> {
        match &self.pty {
            Some(p) => p.wait_readable(timeout),
            None => {
                std::thread::sleep(timeout.min(Duration::from_millis(5)));
                Ok(false)
            }
        }
    }
}

impl Drop for Port {
    fn drop(&mut self) {
        // The device is gone with us: so is its stable path (if it is still ours).
        if let (Some(l), Some(p)) = (&self.link, &self.pty)
            && std::fs::read_link(l).is_ok_and(|t| t == Path::new(p.path()))
        {
            let _ = std::fs::remove_file(l);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_link_follows_the_pty_through_an_unplug() {
        let dir = tempfile::tempdir().expect("tempdir");
        let link = dir.path().join("robot");
        let shared = Arc::new(PlugShared::default());
        let sched = vec![Unplug {
            at_us: 1000,
            for_us: 500,
        }];
        let mut port = Port::open(Some(link.clone()), sched, Arc::clone(&shared)).expect("open");
        std::fs::read_link(&link).expect("a symlink to the pty");
        assert_eq!(port.host_path(), link.display().to_string());
        port.step(999).expect("step");
        assert!(link.exists(), "not yet unplugged");
        port.step(1000).expect("step");
        assert!(
            std::fs::symlink_metadata(&link).is_err(),
            "the path vanished"
        );
        assert_eq!(port.write(b"lost").expect("write"), 4);
        assert_eq!(port.read(&mut [0; 8]).expect("read"), 0);
        port.step(1499).expect("step");
        assert!(std::fs::symlink_metadata(&link).is_err(), "still away");
        port.step(1500).expect("step");
        let second = std::fs::read_link(&link).expect("back");
        assert!(Path::new(&second).exists(), "the link names a live pty");
        assert_eq!(shared.unplugs.load(Ordering::Relaxed), 1);
        assert_eq!(shared.replugs.load(Ordering::Relaxed), 1);
        drop(port);
        assert!(std::fs::symlink_metadata(&link).is_err(), "removed on drop");
    }

    #[test]
    fn a_link_over_a_regular_file_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let link = dir.path().join("robot");
        std::fs::write(&link, b"precious").expect("write");
        let err = Port::open(Some(link.clone()), vec![], Arc::default())
            .err()
            .expect("refused");
        assert!(format!("{err:#}").contains("not a symlink"), "{err:#}");
        assert_eq!(std::fs::read(&link).expect("kept"), b"precious");
    }

    #[test]
    fn an_unplug_schedule_without_a_link_is_refused() {
        let err = Port::open(
            None,
            vec![Unplug {
                at_us: 0,
                for_us: 1,
            }],
            Arc::default(),
        )
        .err()
        .expect("refused");
        assert!(format!("{err:#}").contains("--link"), "{err:#}");
    }
}
