//! The simulated camera running beside a served robot: a thread that renders the scene at the
//! scene's frame rate in simulated time (as fast as the machine allows when it cannot keep up,
//! each frame stamped with the simulated time it shows), publishes each frame on the camera's
//! socket ([`super::server`]) and, if asked, writes it as PNG + ground truth JSON to a folder.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{Context, Result};

use super::scene_view::SceneCamera;
use super::server::CameraServer;
use crate::robot::Pose;
use crate::scene::Scene;
use crate::truth::Truth;

/// Most frames per second of wall time.
const MAX_WALL_FPS: f64 = 30.0;

/// How to run the camera beside a served robot.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveCameraOptions {
    /// Where the camera's socket listens (`127.0.0.1:0`: any free port on loopback).
    pub addr: String,
    /// Also write every frame to this folder as `frame-NNNNNN.png` + `.json`.
    pub frames_dir: Option<PathBuf>,
}

impl Default for LiveCameraOptions {
    fn default() -> Self {
        LiveCameraOptions {
            addr: "127.0.0.1:0".into(),
            frames_dir: None,
        }
    }
}

/// The state a camera thread reads: the latest true robot state and object poses.
#[derive(Debug, Clone)]
pub struct WorldView {
    /// Latest true robot state.
    pub truth: Arc<Mutex<Truth>>,
    /// Latest true object poses (scene order, with ids).
    pub objects: Arc<Mutex<Vec<(String, Pose)>>>,
}

/// A running camera thread.
#[derive(Debug)]
pub struct LiveCamera {
    addr: std::net::SocketAddr,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<()>>>,
}

impl LiveCamera {
    /// Bind the socket and start rendering `scene` as `view` changes.
    pub fn start(
        scene: Scene,
        seed: u64,
        opts: &LiveCameraOptions,
        view: WorldView,
    ) -> Result<LiveCamera> {
        let (wheel_radius, wheel_base) = (scene.robot.wheel_radius, scene.robot.wheel_base);
        let mut camera = SceneCamera::new(scene, seed ^ 0x00CA_3E4A)
            .context("setting up the simulated camera")?;
        let server = CameraServer::bind(opts.addr.as_str())
            .with_context(|| format!("binding the camera socket {}", opts.addr))?;
        let addr = server.local_addr();
        if let Some(dir) = &opts.frames_dir {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("creating the frames folder {}", dir.display()))?;
        }
        let frames_dir = opts.frames_dir.clone();
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let thread = std::thread::Builder::new()
            .name("pushbot-sim-camera".into())
            .spawn(move || -> Result<()> {
                let period = camera.camera().period();
                // Never faster than a real camera in wall time either, whatever the sim speed:
                // rendering is the costliest thing the sim does.
                let wall_period = Duration::from_secs_f64(period.max(1.0 / MAX_WALL_FPS));
                let mut next_wall = std::time::Instant::now();
                let mut next_t = 0.0_f64;
                while !stopped.load(Ordering::Relaxed) {
                    if server.clients() == 0 && frames_dir.is_none() {
                        std::thread::sleep(Duration::from_millis(10));
                        continue;
                    }
                    let truth = *lock(&view.truth);
                    if truth.t + 1e-9 < next_t || std::time::Instant::now() < next_wall {
                        std::thread::sleep(Duration::from_millis(1));
                        continue;
                    }
                    let objects = lock(&view.objects).clone();
                    // The robot's true motion, for the smear over the exposure.
                    let [wl, wr] = truth.wheel_speed;
                    let twist = [
                        wheel_radius * (wl + wr) / 2.0,
                        wheel_radius * (wr - wl) / wheel_base,
                    ];
                    let frame = camera.capture_moving(truth.t, &truth.pose, twist, &objects)?;
                    server.publish(&frame);
                    if let Some(dir) = &frames_dir {
                        frame.write_png(dir)?;
                    }
                    next_t = (next_t + period).max(truth.t);
                    next_wall = (next_wall + wall_period).max(std::time::Instant::now());
                }
                Ok(())
            })
            .context("starting the camera thread")?;
        Ok(LiveCamera {
            addr,
            stop,
            thread: Some(thread),
        })
    }

    /// The camera socket's address: a host opens `sim:ADDR` as its camera.
    pub fn addr(&self) -> std::net::SocketAddr {
        self.addr
    }

    /// Stop rendering; returns the error that stopped the thread, if any.
    pub fn shutdown(mut self) -> Result<()> {
        self.stop_and_join()
    }

    fn stop_and_join(&mut self) -> Result<()> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take() {
            Some(t) => t
                .join()
                .unwrap_or_else(|_| Err(anyhow::anyhow!("the camera thread panicked"))),
            None => Ok(()),
        }
    }
}

impl Drop for LiveCamera {
    fn drop(&mut self) {
        let _ = self.stop_and_join();
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}
