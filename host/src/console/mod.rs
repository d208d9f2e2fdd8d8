//! `pushbot console`: the operator's page, served by the host — the camera's image with its
//! detections and tracked poses, the table drawn to scale in its own metres with its obstacles,
//! an object to pick and a goal to place by clicking (and dragging for a heading), the task's
//! plan drawn before anything moves, Run, Pause, Stop and an emergency stop (button and
//! keyboard) that reaches the robot at once, collection with its progress, the log of events,
//! the link's state and telemetry, and every finished run's report and recording. It is the
//! same page on the built-in target and on a real robot (`--port`, `--camera`), as Lynch &
//! Mason's user entered the pushing problem in a graphical interface and the robot executed it.
//!
//! One router (axum), its state behind an `Arc`, a WebSocket per browser. The page only starts
//! tasks ([`crate::task`]) and shows their events; the [`worker`] runs them. Security: every
//! request and socket carries the token printed at start (`?token=` once, then a cookie); one
//! browser controls at a time, the others watch (any of them may press the emergency stop);
//! every input is checked as the CLI checks its arguments ([`request`]).

mod api;
mod frames;
pub mod request;
pub mod worker;

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result};
use pushbot_world::Scene;

use crate::exec::LiveOptions;
use crate::planner::rearrange::problem::Problem;
use crate::task::{Session, Where};

/// How a console starts.
#[derive(Debug, Clone)]
pub struct ConsoleOptions {
    /// Where it listens (default 127.0.0.1:7878; port 0: any free port).
    pub listen: SocketAddr,
    /// The table.
    pub scene: Scene,
    /// The table's rearrangement grid, when it is one (the scene was a case or has
    /// `[rearrange]`).
    pub rearrange: Option<Problem>,
    /// Where the robot is.
    pub at: Where,
    /// The robot's settings.
    pub live: LiveOptions,
    /// The console's folder: `runs/` (one folder per task) and `strategies/`.
    pub dir: PathBuf,
    /// Seed of collections in simulation.
    pub seed: u64,
    /// The token (default: a random one).
    pub token: Option<String>,
}

/// A random token of 32 hex digits.
pub fn new_token() -> String {
    let v: u128 = rand::random();
    format!("{v:032x}")
}

/// Connect to the robot and serve the console until the process ends; prints the address to
/// open (with its token) on stdout first.
pub fn serve(opts: ConsoleOptions) -> Result<()> {
    let token = opts.token.clone().unwrap_or_else(new_token);
    std::fs::create_dir_all(opts.dir.join("runs"))
        .with_context(|| format!("creating {}", opts.dir.join("runs").display()))?;
    std::fs::create_dir_all(opts.dir.join("strategies"))
        .with_context(|| format!("creating {}", opts.dir.join("strategies").display()))?;
    // The session lives on the worker's thread (the detector is not `Send`); what the server
    // needs of it comes back from there.
    let (jobs, rx) = std::sync::mpsc::channel();
    let (parts_tx, parts_rx) = std::sync::mpsc::channel();
    let published = Arc::new(Mutex::new(worker::Published::default()));
    let (events_tx, _) = tokio::sync::broadcast::channel::<String>(1024);
    let sink_slot: Arc<Mutex<Option<Arc<api::App>>>> = Arc::default();
    let slot = Arc::clone(&sink_slot);
    let sink: crate::task::EventSink = Arc::new(move |e| {
        if let Some(app) = &*slot
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
        {
            app.event(e);
        }
    });
    let (scene, at, live, runs) = (
        opts.scene.clone(),
        opts.at.clone(),
        opts.live.clone(),
        opts.dir.join("runs"),
    );
    let pubd = Arc::clone(&published);
    std::thread::Builder::new()
        .name("console-worker".into())
        .spawn(move || {
            let mut session = match Session::open(&scene, &at, live) {
                Ok(s) => s,
                Err(e) => {
                    let _ = parts_tx.send(Err(e));
                    return;
                }
            };
            let parts = (
                session.live.watch(),
                session.live.grabber(),
                session.live.stopper(),
                session.target(),
            );
            if let Err(e) = session.live.look() {
                let _ = parts_tx.send(Err(e));
                return;
            }
            let _ = parts_tx.send(Ok(parts));
            worker::work(session, rx, runs, pubd, sink);
        })
        .context("starting the console's worker")?;
    let (watch, grabber, stopper, target) = parts_rx
        .recv()
        .map_err(|_| anyhow::anyhow!("the console's worker stopped while connecting"))??;
    let app = Arc::new(api::App::new(api::AppParts {
        token: token.clone(),
        opts: &opts,
        jobs,
        watch,
        stopper,
        target,
        published,
        events: events_tx,
        frames: frames::Frames::start(grabber),
    }));
    *sink_slot
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(Arc::clone(&app));
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the console's server")?;
    rt.block_on(async move {
        let listener = tokio::net::TcpListener::bind(opts.listen)
            .await
            .with_context(|| format!("listening on {}", opts.listen))?;
        let addr = listener.local_addr()?;
        let shown = if addr.ip().is_unspecified() {
            SocketAddr::new(std::net::Ipv4Addr::LOCALHOST.into(), addr.port())
        } else {
            addr
        };
        println!("pushbot console: http://{shown}/?token={token}");
        use std::io::Write;
        let _ = std::io::stdout().flush();
        axum::serve(listener, api::router(app))
            .await
            .context("serving the console")
    })
}
