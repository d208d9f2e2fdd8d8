//! The serial driver: the link client behind a mutex, a reader thread on the port that hands
//! it bytes and time (so heartbeats keep going while the host computes), and writes of what it
//! transmits. It only moves bytes and time; everything the link means is in the client.

use std::io::{Read, Write};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serialport::TTYPort;

use super::client::{Client, ClientOptions, HostTime, RobotEvent};
use super::driver::{Driver, Subscribers, silent};
use super::error::LinkError;
use super::transport;

/// The client and what the driver knows about the port.
struct Inner {
    client: Client,
    /// Why the port closed under us, once it has.
    closed: Option<String>,
    stop: bool,
}

/// Everything the reader thread and the callers share.
struct Shared {
    path: String,
    epoch: Instant,
    inner: Mutex<Inner>,
    cond: Condvar,
    writer: Mutex<Option<TTYPort>>,
    subscribers: Mutex<Subscribers>,
}

/// The link client on a serial port.
pub struct SerialDriver {
    shared: Arc<Shared>,
    reader: Option<JoinHandle<()>>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic in another thread holding the lock leaves plain data behind; keep going.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl SerialDriver {
    /// Open `path`, start the reader thread and a client with `opts`.
    pub fn open(path: &str, opts: ClientOptions) -> Result<SerialDriver, LinkError> {
        let port = transport::open(path)?;
        let reader_port = port.try_clone_native().map_err(|e| LinkError::Open {
            path: path.to_string(),
            reason: e.description,
        })?;
        let shared = Arc::new(Shared {
            path: path.to_string(),
            epoch: Instant::now(),
            inner: Mutex::new(Inner {
                client: Client::new(HostTime::default(), opts),
                closed: None,
                stop: false,
            }),
            cond: Condvar::new(),
            writer: Mutex::new(Some(port)),
            subscribers: Mutex::new(Subscribers::default()),
        });
        let for_reader = Arc::clone(&shared);
        let reader = std::thread::Builder::new()
            .name("pushbot-link-rx".into())
            .spawn(move || reader_loop(&for_reader, reader_port))
            .map_err(|e| LinkError::Open {
                path: path.to_string(),
                reason: format!("cannot start the reader thread: {e}"),
            })?;
        Ok(SerialDriver {
            shared,
            reader: Some(reader),
        })
    }

    /// Stop the reader and close the port.
    pub fn close(&mut self) {
        lock(&self.shared.inner).stop = true;
        self.shared.cond.notify_all();
        if let Some(h) = self.reader.take() {
            let _ = h.join();
        }
        if let Some(mut port) = lock(&self.shared.writer).take() {
            transport::release(&mut port);
        }
    }
}

impl Drop for SerialDriver {
    fn drop(&mut self) {
        self.close();
    }
}

impl Shared {
    fn now(&self) -> HostTime {
        HostTime::from_micros(u64::try_from(self.epoch.elapsed().as_micros()).unwrap_or(u64::MAX))
    }

    fn disconnected(&self, reason: String) -> LinkError {
        LinkError::Disconnected {
            path: self.path.clone(),
            reason,
        }
    }

    fn mark_closed(&self, reason: String) {
        let mut inner = lock(&self.inner);
        if inner.closed.is_none() {
            inner.closed = Some(reason);
        }
        drop(inner);
        self.cond.notify_all();
    }

    /// Take what the client wants sent and pass its events on, release the lock, write.
    fn flush(&self, mut inner: MutexGuard<'_, Inner>) -> Result<(), LinkError> {
        let now = self.now();
        let mut out = Vec::new();
        while let Some(bytes) = inner.client.poll_transmit(now) {
            out.push(bytes);
        }
        lock(&self.subscribers).dispatch(&mut inner.client);
        let closed = inner.closed.clone();
        drop(inner);
        self.cond.notify_all();
        if out.is_empty() {
            return Ok(());
        }
        if let Some(reason) = closed {
            return Err(self.disconnected(reason));
        }
        let mut w = lock(&self.writer);
        let port = w
            .as_mut()
            .ok_or_else(|| self.disconnected("the link was closed".into()))?;
        let result = out.iter().try_for_each(|b| write_patiently(port, b));
        drop(w);
        result.map_err(|e| {
            let reason = e.to_string();
            self.mark_closed(reason.clone());
            self.disconnected(reason)
        })
    }
}

impl Driver for SerialDriver {
    fn path(&self) -> &str {
        &self.shared.path
    }

    fn with_client<T>(&self, f: impl FnOnce(&mut Client, HostTime) -> T) -> Result<T, LinkError> {
        let mut inner = lock(&self.shared.inner);
        let now = self.shared.now();
        let r = f(&mut inner.client, now);
        self.shared.flush(inner)?;
        Ok(r)
    }

    fn inspect<T>(&self, f: impl FnOnce(&Client) -> T) -> T {
        f(&lock(&self.shared.inner).client)
    }

    fn wait<T>(
        &self,
        mut f: impl FnMut(&mut Client, HostTime) -> Option<T>,
    ) -> Result<T, LinkError> {
        let shared = &self.shared;
        let mut inner = lock(&shared.inner);
        loop {
            let now = shared.now();
            if let Some(r) = f(&mut inner.client, now) {
                shared.flush(inner)?;
                return Ok(r);
            }
            if let Some(reason) = inner.closed.clone() {
                return Err(shared.disconnected(reason));
            }
            silent(&inner.client, now, &shared.path)?;
            inner = shared
                .cond
                .wait_timeout(inner, Duration::from_millis(50))
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }

    fn subscribe(&self) -> mpsc::Receiver<RobotEvent> {
        lock(&self.shared.subscribers).subscribe()
    }

    fn reopen(&mut self) -> Result<(), LinkError> {
        self.close();
        let opts = self.inspect(|c| ClientOptions {
            watchdog_ms: c.watchdog_ms(),
            first_seq: c.next_seq(),
            ..c.options().clone()
        });
        *self = SerialDriver::open(&self.shared.path.clone(), opts)?;
        Ok(())
    }
}

/// Write all of `bytes`, waiting out a full output buffer for up to [`WRITE_PATIENCE`].
fn write_patiently(port: &mut TTYPort, mut bytes: &[u8]) -> std::io::Result<()> {
    let deadline = Instant::now() + WRITE_PATIENCE;
    while !bytes.is_empty() {
        match port.write(bytes) {
            Ok(0) => return Err(std::io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if !transport::is_fatal(&e) && Instant::now() < deadline => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// How long a write may wait for room in the output buffer before the link counts as dead.
const WRITE_PATIENCE: Duration = Duration::from_secs(2);

fn reader_loop(shared: &Shared, mut port: TTYPort) {
    let mut buf = [0u8; 512];
    loop {
        if lock(&shared.inner).stop {
            return;
        }
        let read = port.read(&mut buf);
        let mut inner = lock(&shared.inner);
        let now = shared.now();
        match read {
            Ok(0) => {
                drop(inner);
                shared.mark_closed("end of file (hang-up)".into());
                return;
            }
            Ok(n) => inner.client.handle_bytes(now, &buf[..n]),
            Err(e) if !transport::is_fatal(&e) => {}
            Err(e) => {
                drop(inner);
                shared.mark_closed(e.to_string());
                return;
            }
        }
        if inner.closed.is_some() {
            drop(inner);
            shared.cond.notify_all();
            continue;
        }
        if inner.client.poll_timeout().is_some_and(|t| t <= now) {
            inner.client.handle_timeout(now);
        }
        // A failed write marks the link closed; waiters see it.
        let _ = shared.flush(inner);
    }
}
