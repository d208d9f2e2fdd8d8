//! The robot's serial port as a pseudo-terminal pair: the master the simulator reads and
//! writes, the slave a host opens as the robot's port.
//!
//! The pty is opened with `rustix` rather than `serialport::TTYPort::pair`, which does the same
//! `posix_openpt`/`grantpt`/`unlockpt` and `cfmakeraw` on the slave but hands back a blocking
//! master without `AsFd`, so it cannot be made non-blocking without `unsafe`; a blocking write
//! to a master whose slave nobody reads would stop the simulation. Here:
//! * the slave is put in raw mode (no echo, no CR/LF translation, 8 bits, no signals);
//! * the sim keeps the slave open itself, so the master never reads EIO while no host has it
//!   open, and a host can close and reopen the port at will. `serialport` opens ports
//!   exclusively (`TIOCEXCL`), and with the slave held here that flag outlives the host's close,
//!   so the sim clears it every 20 ms of wall time: a non-root host's reopen may see `EBUSY`
//!   for up to 20 ms (root is never refused), and exclusivity is not enforced against a second
//!   opener;
//! * the master is non-blocking: reads return what has arrived, writes take what fits; when the
//!   pty is full because nobody reads it, what waits unread is discarded (like a UART overrun)
//!   rather than blocking the robot.

use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::time::Duration;

use anyhow::{Context, Result};
use rustix::event::{PollFd, PollFlags, Timespec, poll};
use rustix::fs::OFlags;
use rustix::pty::{OpenptFlags, grantpt, openpt, ptsname, unlockpt};
use rustix::termios::{OptionalActions, QueueSelector, tcflush, tcgetattr, tcsetattr};

/// A pseudo-terminal pair: the master the sim reads and writes, the slave a host opens.
pub struct Pty {
    master: File,
    slave: File,
    path: String,
}

impl Pty {
    /// Open a new pty in raw mode with a non-blocking master.
    pub fn open() -> Result<Self> {
        let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC)
            .context("opening a pseudo-terminal")?;
        grantpt(&master).context("grantpt")?;
        unlockpt(&master).context("unlockpt")?;
        let path = ptsname(&master, Vec::new())
            .context("ptsname")?
            .into_string()
            .context("pty path is not UTF-8")?;
        let slave = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(OFlags::NOCTTY.bits() as i32)
            .open(&path)
            .with_context(|| format!("opening the pty slave {path}"))?;
        let mut termios = tcgetattr(&slave).context("tcgetattr on the pty")?;
        termios.make_raw();
        tcsetattr(&slave, OptionalActions::Now, &termios).context("tcsetattr on the pty")?;
        rustix::fs::fcntl_setfl(&master, OFlags::NONBLOCK).context("non-blocking pty master")?;
        Ok(Pty {
            master: File::from(master),
            slave,
            path,
        })
    }

    /// Path of the slave device, e.g. `/dev/pts/7`: what a host opens as the robot's port.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Read what has arrived from the host (0 if nothing).
    pub fn read(&mut self, buf: &mut [u8]) -> Result<usize> {
        loop {
            match self.master.read(buf) {
                Ok(n) => return Ok(n),
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) if e.kind() == ErrorKind::WouldBlock => return Ok(0),
                // EIO: no slave open, which cannot happen while we hold one; treat as quiet.
                Err(e) if e.raw_os_error() == Some(rustix::io::Errno::IO.raw_os_error()) => {
                    return Ok(0);
                }
                Err(e) => return Err(e).context("reading the pty"),
            }
        }
    }

    /// Write what fits now; returns how many bytes were taken (0 if the pty is full).
    pub fn write(&mut self, bytes: &[u8]) -> Result<usize> {
        loop {
            match self.master.write(bytes) {
                Ok(n) => return Ok(n),
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) if e.kind() == ErrorKind::WouldBlock => return Ok(0),
                Err(e) => return Err(e).context("writing the pty"),
            }
        }
    }

    /// Discard what was sent to the host but not read yet.
    pub fn discard_unread(&self) -> Result<()> {
        tcflush(&self.slave, QueueSelector::IFlush).context("flushing the pty")
    }

    /// Let any process open the port again (clears `TIOCEXCL`, which `serialport` sets).
    pub fn allow_reopen(&self) -> Result<()> {
        rustix::termios::ioctl_tiocnxcl(&self.slave).context("TIOCNXCL on the pty")
    }

    /// Wait until the host sent something or `timeout` passed; true if something arrived.
    pub fn wait_readable(&self, timeout: Duration) -> Result<bool> {
        let ts = Timespec::try_from(timeout).unwrap_or(Timespec {
            tv_sec: 1,
            tv_nsec: 0,
        });
        let mut fds = [PollFd::new(&self.master, PollFlags::IN)];
        match poll(&mut fds, Some(&ts)) {
            Ok(n) => Ok(n > 0),
            Err(rustix::io::Errno::INTR) => Ok(false),
            Err(e) => Err(e).context("polling the pty"),
        }
    }
}
