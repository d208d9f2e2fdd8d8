//! The in-process driver: the simulated target ([`pushbot_sim::Sim`], the real firmware core
//! on simulated hardware) stepping on the same bytes a serial port would carry. The client's
//! host time is the simulated time, so everything runs as fast as the machine goes and is a
//! function of the seed. It only moves bytes and time: before each tick the client's
//! transmits go into the simulator, after it the simulator's output goes to the client.
//!
//! With [`InProcess::with_faults`] a seeded fault pipe ([`FaultyLink`]: drops, bit flips,
//! garbage, lost and duplicated frames, delays, cuts) sits between the two, one per direction.

use std::ops::Deref;
use std::sync::mpsc;
use std::sync::{Mutex, MutexGuard};

use pushbot_sim::Sim;
use pushbot_sim::faults::{FaultyLink, LinkFaults};

use crate::link::driver::{Subscribers, silent};
use crate::link::{Client, ClientOptions, Driver, HostTime, LinkError, RobotEvent};

/// The simulator and the client.
pub struct Inner {
    sim: Sim,
    client: Client,
    subscribers: Subscribers,
    rx: Vec<u8>,
    faults: Option<FaultyLink>,
}

/// The link client on a simulator in process.
pub struct InProcess {
    inner: Mutex<Inner>,
}

/// A view of the simulator (holds the driver's lock).
pub struct SimRef<'a>(MutexGuard<'a, Inner>);

impl Deref for SimRef<'_> {
    type Target = Sim;
    fn deref(&self) -> &Sim {
        &self.0.sim
    }
}

/// The name the in-process target goes by in messages.
pub const PATH: &str = "in-process simulator";

impl Inner {
    fn now(&self) -> HostTime {
        HostTime::from_micros(self.sim.now_us())
    }

    /// Hand the client's transmits to the simulator and its events to subscribers.
    fn flush(&mut self) {
        let now = self.now();
        while let Some(bytes) = self.client.poll_transmit(now) {
            match self.faults.as_mut() {
                Some(link) => link.from_host(now.as_micros(), &bytes),
                None => self.sim.receive(&bytes),
            }
        }
        self.subscribers.dispatch(&mut self.client);
    }

    /// One tick of the simulator, with the bytes either way.
    fn step(&mut self) {
        self.flush();
        if let Some(link) = self.faults.as_mut() {
            self.rx.clear();
            link.to_robot(self.sim.now_us(), &mut self.rx);
            self.sim.receive(&self.rx);
        }
        self.sim.tick();
        let now = self.now();
        self.rx.clear();
        self.sim.transmit(&mut self.rx);
        if let Some(link) = self.faults.as_mut() {
            let sent = std::mem::take(&mut self.rx);
            link.from_robot(now.as_micros(), &sent);
            self.rx = sent;
            self.rx.clear();
            link.to_host(now.as_micros(), &mut self.rx);
        }
        let rx = std::mem::take(&mut self.rx);
        self.client.handle_bytes(now, &rx);
        self.rx = rx;
        if self.client.poll_timeout().is_some_and(|t| t <= now) {
            self.client.handle_timeout(now);
        }
        self.subscribers.dispatch(&mut self.client);
    }
}

impl InProcess {
    /// The simulated target serving `scene` with every random draw from `seed`, stepped only
    /// while the host waits (no wall clock), driven with a client made with `opts`.
    pub fn start(
        scene: pushbot_world::Scene,
        seed: u64,
        opts: ClientOptions,
    ) -> anyhow::Result<InProcess> {
        InProcess::start_perturbed(scene, seed, None, opts)
    }

    /// As [`InProcess::start`], the world perturbed by `perturb` ([`pushbot_sim::perturb`]).
    pub fn start_perturbed(
        scene: pushbot_world::Scene,
        seed: u64,
        perturb: Option<pushbot_sim::perturb::Perturbation>,
        opts: ClientOptions,
    ) -> anyhow::Result<InProcess> {
        let sim = Sim::new(&pushbot_sim::SimOptions {
            seed,
            speed: 0.0,
            scene: Some(scene),
            perturb,
            ..pushbot_sim::SimOptions::default()
        })?;
        Ok(InProcess::new(sim, opts))
    }

    /// The simulated robot alone on an empty `table` (metres, walls at its edges) at `start`,
    /// every random draw from `seed`, its wire through a fault pipe with `faults` each way
    /// (what `bench link` measures), driven with a client made with `opts`.
    pub fn on_open_table(
        table: (f64, f64),
        start: pushbot_world::Pose,
        seed: u64,
        faults: LinkFaults,
        opts: ClientOptions,
    ) -> anyhow::Result<InProcess> {
        let sim = Sim::new(&pushbot_sim::SimOptions {
            seed,
            speed: 0.0,
            table,
            start,
            ..pushbot_sim::SimOptions::default()
        })?;
        Ok(InProcess::with_faults(sim, opts, faults, seed))
    }

    /// Drive `sim` with a client made with `opts`, at the simulator's time.
    pub fn new(sim: Sim, opts: ClientOptions) -> InProcess {
        let client = Client::new(HostTime::from_micros(sim.now_us()), opts);
        InProcess {
            inner: Mutex::new(Inner {
                sim,
                client,
                subscribers: Subscribers::default(),
                rx: Vec::new(),
                faults: None,
            }),
        }
    }

    /// Drive `sim` as [`InProcess::new`] does, through a fault pipe with `faults` in each
    /// direction, drawing from `seed`.
    pub fn with_faults(sim: Sim, opts: ClientOptions, faults: LinkFaults, seed: u64) -> InProcess {
        let driver = InProcess::new(sim, opts);
        driver.lock().faults = Some(FaultyLink::new(faults, seed));
        driver
    }

    /// Cut the wire both ways from now for `len_us` of simulated time (no effect without a
    /// fault pipe).
    pub fn cut_for(&self, len_us: u64) {
        let mut inner = self.lock();
        let now = inner.sim.now_us();
        if let Some(link) = inner.faults.as_mut() {
            link.cut_for(now, len_us);
        }
    }

    /// What the fault pipe did so far (host → robot, robot → host), if there is one.
    pub fn fault_stats(
        &self,
    ) -> Option<(
        pushbot_sim::faults::PipeStats,
        pushbot_sim::faults::PipeStats,
    )> {
        self.lock().faults.as_ref().map(FaultyLink::stats)
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The simulator.
    pub fn sim(&self) -> SimRef<'_> {
        SimRef(self.lock())
    }

    /// Run whole ticks, moving bytes, until at least `seconds` more of simulated time passed.
    pub fn run_for(&self, seconds: f64) {
        let mut inner = self.lock();
        let end = inner.sim.now_us() + (seconds.max(0.0) * 1e6) as u64;
        while inner.sim.now_us() < end {
            inner.step();
        }
    }
}

impl Driver for InProcess {
    fn path(&self) -> &str {
        PATH
    }

    fn with_client<T>(&self, f: impl FnOnce(&mut Client, HostTime) -> T) -> Result<T, LinkError> {
        let mut inner = self.lock();
        let now = inner.now();
        let r = f(&mut inner.client, now);
        inner.flush();
        Ok(r)
    }

    fn inspect<T>(&self, f: impl FnOnce(&Client) -> T) -> T {
        f(&self.lock().client)
    }

    fn wait<T>(
        &self,
        mut f: impl FnMut(&mut Client, HostTime) -> Option<T>,
    ) -> Result<T, LinkError> {
        let mut inner = self.lock();
        loop {
            let now = inner.now();
            if let Some(r) = f(&mut inner.client, now) {
                inner.flush();
                return Ok(r);
            }
            silent(&inner.client, now, PATH)?;
            inner.step();
        }
    }

    fn subscribe(&self) -> mpsc::Receiver<RobotEvent> {
        self.lock().subscribers.subscribe()
    }

    /// A fresh client on the same simulator and wire (as a serial port closed and opened
    /// again): the sequence numbers go on, bytes already on the wire stay there.
    fn reopen(&mut self) -> Result<(), LinkError> {
        let mut inner = self.lock();
        let now = inner.now();
        let opts = ClientOptions {
            watchdog_ms: inner.client.watchdog_ms(),
            first_seq: inner.client.next_seq(),
            ..inner.client.options().clone()
        };
        inner.client = Client::new(now, opts);
        Ok(())
    }
}
