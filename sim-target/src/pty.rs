//! The robot's serial port on a pseudo-terminal, and [`PtySim`], the simulated robot served on
//! it from a background thread at a chosen pace.
//!
//! The pty itself and how it behaves is [`crate::terminal`]; its stable path and unplugs are
//! [`crate::plug`]. Every byte either way may pass a fault pipe ([`crate::faults`]).

use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

pub use crate::terminal::Pty;

use crate::faults::FaultyLink;
use crate::plug::{PlugShared, Port};
use crate::sim::{Sim, SimOptions, Truth, TruthRecord};

/// Bytes queued for the host beyond which the oldest are dropped.
const MAX_PENDING: usize = 64 * 1024;

/// The simulated robot served on a pty from a background thread.
pub struct PtySim {
    path: String,
    /// Whether the port has a stable link path (and so can be unplugged).
    linked: bool,
    plug: Arc<PlugShared>,
    truth: Arc<Mutex<Truth>>,
    objects: Arc<Mutex<Vec<(String, crate::Pose)>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<()>>>,
    camera: Option<crate::camera::live::LiveCamera>,
}

impl PtySim {
    /// Build the robot, open its pty and start stepping it, paced by `opts.speed`.
    pub fn start(opts: SimOptions) -> Result<PtySim> {
        if !(opts.speed.is_finite() && opts.speed >= 0.0) {
            anyhow::bail!("speed must be a finite number ≥ 0, not {}", opts.speed);
        }
        if !(opts.truth_hz.is_finite() && opts.truth_hz > 0.0) {
            anyhow::bail!("truth log rate must be positive, not {}", opts.truth_hz);
        }
        let sim = Sim::new(&opts)?;
        let plug = Arc::new(PlugShared::default());
        let port = Port::open(opts.link.clone(), opts.unplugs.clone(), Arc::clone(&plug))?;
        let log = match &opts.truth_log {
            Some(p) => {
                Some(BufWriter::new(File::create(p).with_context(|| {
                    format!("creating the truth log {}", p.display())
                })?))
            }
            None => None,
        };
        let path = port.host_path();
        let truth = Arc::new(Mutex::new(sim.truth()));
        let objects = Arc::new(Mutex::new(sim.object_poses()));
        let stop = Arc::new(AtomicBool::new(false));
        let camera = match &opts.camera {
            Some(c) => Some(crate::camera::live::LiveCamera::start(
                opts.effective_scene(),
                opts.seed,
                c,
                crate::camera::live::WorldView {
                    truth: Arc::clone(&truth),
                    objects: Arc::clone(&objects),
                },
            )?),
            None => None,
        };
        let runner = Runner {
            sim,
            port,
            speed: opts.speed,
            log,
            log_period_us: ((1e6 / opts.truth_hz) as u64).max(1),
            truth: Arc::clone(&truth),
            objects: Arc::clone(&objects),
            stop: Arc::clone(&stop),
            link: opts.faults.map(|f| FaultyLink::new(f, opts.seed)),
        };
        let thread = std::thread::Builder::new()
            .name("pushbot-sim".into())
            .spawn(move || runner.run())
            .context("starting the simulation thread")?;
        Ok(PtySim {
            path,
            linked: opts.link.is_some(),
            plug,
            truth,
            objects,
            stop,
            thread: Some(thread),
            camera,
        })
    }

    /// The camera socket's address (`HOST:PORT`), when the camera runs: a host opens
    /// `sim:HOST:PORT` as its camera.
    pub fn camera_addr(&self) -> Option<std::net::SocketAddr> {
        self.camera.as_ref().map(|c| c.addr())
    }

    /// Path of the robot's serial port: open it with `serialport` as a real robot's. With a
    /// link path ([`SimOptions::link`]) it is that path, which outlives unplugs.
    pub fn serial_path(&self) -> &str {
        &self.path
    }

    /// Unplug the port for `gap` of simulated time, then serve a new pty behind the same link
    /// path (a USB re-enumeration). Needs [`SimOptions::link`].
    pub fn unplug(&self, gap: Duration) -> Result<()> {
        if !self.linked {
            anyhow::bail!("unplugging the port needs a stable path for it (SimOptions::link)");
        }
        let us = u64::try_from(gap.as_micros()).unwrap_or(u64::MAX);
        match self.plug.requests.lock() {
            Ok(mut r) => r.push(us),
            Err(p) => p.into_inner().push(us),
        }
        Ok(())
    }

    /// How many times the port was unplugged, and plugged back, so far (each counted before a
    /// host can notice it).
    pub fn unplugs(&self) -> (u32, u32) {
        (
            self.plug.unplugs.load(Ordering::SeqCst),
            self.plug.replugs.load(Ordering::SeqCst),
        )
    }

    /// The latest true object poses (scene order, with ids).
    pub fn objects(&self) -> Vec<(String, crate::Pose)> {
        match self.objects.lock() {
            Ok(o) => o.clone(),
            Err(poisoned) => poisoned.into_inner().clone(),
        }
    }

    /// The latest true state.
    pub fn truth(&self) -> Truth {
        match self.truth.lock() {
            Ok(t) => *t,
            Err(poisoned) => *poisoned.into_inner(),
        }
    }

    /// Whether the simulation thread is still running (it stops on shutdown or on an I/O error,
    /// which [`PtySim::shutdown`] then returns).
    pub fn is_running(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// Stop the simulation and close the port; returns the error that stopped it, if any.
    pub fn shutdown(mut self) -> Result<()> {
        self.stop_and_join()
    }

    fn stop_and_join(&mut self) -> Result<()> {
        let camera = self.camera.take().map_or(Ok(()), |c| c.shutdown());
        self.stop.store(true, Ordering::Relaxed);
        let robot = match self.thread.take() {
            Some(t) => match t.join() {
                Ok(r) => r,
                Err(_) => Err(anyhow::anyhow!("the simulation thread panicked")),
            },
            None => Ok(()),
        };
        robot.and(camera)
    }
}

impl Drop for PtySim {
    fn drop(&mut self) {
        let _ = self.stop_and_join();
    }
}

/// The background loop's state.
struct Runner {
    sim: Sim,
    port: Port,
    speed: f64,
    log: Option<BufWriter<File>>,
    log_period_us: u64,
    truth: Arc<Mutex<Truth>>,
    objects: Arc<Mutex<Vec<(String, crate::Pose)>>>,
    stop: Arc<AtomicBool>,
    /// Fault injection between the pty and the firmware, if asked for.
    link: Option<FaultyLink>,
}

impl Runner {
    fn run(mut self) -> Result<()> {
        // Sleep only when ahead of the wall clock by at least this much (bounds wake-ups).
        const SLACK: Duration = Duration::from_millis(1);
        // Behind by more than this much wall time, give up catching up: the sim runs slower
        // than asked rather than in a burst. The bound is 20 ms of *robot* time, so a burst
        // never comes near the link watchdog (≥ 50 ms) while the host is still answering.
        let max_lag = Duration::from_secs_f64(if self.speed > 0.0 {
            (0.02 / self.speed).min(0.2)
        } else {
            0.2
        });
        let tick_us = u64::from(self.sim.tick_us());
        let mut wall0 = Instant::now();
        let sim0 = self.sim.now_us();
        let mut next_log_us = sim0;
        let mut rx = [0u8; 1024];
        let mut tx: Vec<u8> = Vec::new();
        let mut pending: VecDeque<u8> = VecDeque::new();
        let mut last_nxcl = Instant::now();
        self.log_truth(&mut next_log_us)?;
        while !self.stop.load(Ordering::Relaxed) {
            loop {
                let n = self.port.read(&mut rx)?;
                match self.link.as_mut() {
                    Some(link) => link.from_host(self.sim.now_us(), &rx[..n]),
                    None => self.sim.receive(&rx[..n]),
                }
                if n < rx.len() {
                    break;
                }
            }
            if self.speed > 0.0 {
                let sim_s = (self.sim.now_us() + tick_us - sim0) as f64 * 1e-6;
                let due = wall0 + Duration::from_secs_f64(sim_s / self.speed);
                let now = Instant::now();
                if due > now + SLACK {
                    // Wake early if the host sends something, to hand it over in time.
                    self.port
                        .wait_readable((due - now).min(Duration::from_millis(50)))?;
                    continue;
                }
                if now > due + max_lag {
                    wall0 += now - due;
                }
            }
            if let Some(link) = self.link.as_mut() {
                let mut inbound = Vec::new();
                link.to_robot(self.sim.now_us(), &mut inbound);
                self.sim.receive(&inbound);
            }
            self.sim.tick();
            self.port.step(self.sim.now_us())?;
            self.sim.transmit(&mut tx);
            if let Some(link) = self.link.as_mut() {
                let now = self.sim.now_us();
                link.from_robot(now, &tx);
                tx.clear();
                link.to_host(now, &mut tx);
            }
            if !tx.is_empty() || !pending.is_empty() {
                pending.extend(tx.drain(..));
                self.send(&mut pending)?;
            }
            match self.truth.lock() {
                Ok(mut t) => *t = self.sim.truth(),
                Err(poisoned) => *poisoned.into_inner() = self.sim.truth(),
            }
            if !self.sim.world().objects().is_empty() {
                let poses = self.sim.object_poses();
                match self.objects.lock() {
                    Ok(mut o) => *o = poses,
                    Err(poisoned) => *poisoned.into_inner() = poses,
                }
            }
            self.log_truth(&mut next_log_us)?;
            if last_nxcl.elapsed() > Duration::from_millis(20) {
                // A host that closed the port left it exclusive; let it (or another) reopen.
                last_nxcl = Instant::now();
                let _ = self.port.allow_reopen();
            }
        }
        if let Some(log) = self.log.as_mut() {
            log.flush().context("writing the truth log")?;
        }
        Ok(())
    }

    /// Write pending bytes; if the pty is full (nobody reads it), discard what sits unread.
    fn send(&mut self, pending: &mut VecDeque<u8>) -> Result<()> {
        for attempt in 0..2 {
            while !pending.is_empty() {
                let (a, _) = pending.as_slices();
                let n = self.port.write(a)?;
                if n == 0 {
                    break;
                }
                pending.drain(..n);
            }
            if pending.is_empty() || attempt == 1 {
                break;
            }
            self.port.discard_unread()?;
        }
        if pending.len() > MAX_PENDING {
            let excess = pending.len() - MAX_PENDING;
            pending.drain(..excess);
        }
        Ok(())
    }

    fn log_truth(&mut self, next_log_us: &mut u64) -> Result<()> {
        let Some(log) = self.log.as_mut() else {
            return Ok(());
        };
        if self.sim.now_us() < *next_log_us {
            return Ok(());
        }
        *next_log_us = (*next_log_us + self.log_period_us).max(self.sim.now_us());
        let mut rec = TruthRecord::from(&self.sim.truth());
        rec.objects = self
            .sim
            .world()
            .objects()
            .iter()
            .map(|(_, s)| [s.pose.x, s.pose.y, s.pose.theta])
            .collect();
        serde_json::to_writer(&mut *log, &rec).context("writing the truth log")?;
        log.write_all(b"\n")
            .and_then(|()| log.flush())
            .context("writing the truth log")
    }
}
