//! The serial transport: open a port by path with `serialport` (default features off, so no
//! libudev), classify what goes wrong (no such path, not a tty, in use, vanished).

use std::io;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::time::Duration;

use serialport::{ClearBuffer, SerialPort, TTYPort};

use super::error::LinkError;

/// Baud rate asked of real UARTs (ignored by USB CDC and ptys).
pub const BAUD_RATE: u32 = 115_200;

/// How long one read waits for bytes before the reader loop looks around again.
pub const READ_POLL: Duration = Duration::from_millis(10);

/// Open the serial port at `path` for the link: raw mode, exclusive, input buffer cleared.
pub fn open(path: &str) -> Result<TTYPort, LinkError> {
    let meta = std::fs::metadata(Path::new(path)).map_err(|e| match e.kind() {
        io::ErrorKind::NotFound => LinkError::NoSuchPort {
            path: path.to_string(),
        },
        _ => LinkError::Open {
            path: path.to_string(),
            reason: e.to_string(),
        },
    })?;
    if !meta.file_type().is_char_device() {
        let what = if meta.is_dir() {
            "a directory"
        } else if meta.is_file() {
            "a regular file"
        } else {
            "not a character device"
        };
        return Err(LinkError::NotASerialPort {
            path: path.to_string(),
            reason: what.to_string(),
        });
    }
    let port = serialport::new(path, BAUD_RATE)
        .timeout(READ_POLL)
        .exclusive(true)
        .open_native()
        .map_err(|e| classify_open_error(path, &e))?;
    // Bytes that arrived before we opened belong to nobody; a stale answer must not be read as
    // the answer to our first command.
    let _ = port.clear(ClearBuffer::Input);
    Ok(port)
}

fn classify_open_error(path: &str, e: &serialport::Error) -> LinkError {
    use serialport::ErrorKind as K;
    match e.kind() {
        K::NoDevice => LinkError::Open {
            path: path.to_string(),
            reason: format!("{} (in use by another program?)", e.description),
        },
        K::Io(io::ErrorKind::NotFound) => LinkError::NoSuchPort {
            path: path.to_string(),
        },
        K::Io(io::ErrorKind::PermissionDenied) => LinkError::Open {
            path: path.to_string(),
            reason: format!("{} (add yourself to the dialout group?)", e.description),
        },
        // tcgetattr on something that is not a terminal: ENOTTY, reported as Unknown.
        _ => LinkError::NotASerialPort {
            path: path.to_string(),
            reason: format!("not a terminal device ({})", e.description),
        },
    }
}

/// Whether a read or write error means the port is gone (rather than "no bytes yet").
pub fn is_fatal(e: &io::Error) -> bool {
    !matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// Give up exclusive use of the port before closing it, so a later open (a reconnect, the next
/// command) finds it free even while the other end keeps the tty open.
pub fn release(port: &mut TTYPort) {
    let _ = port.set_exclusive(false);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_path_is_named() {
        let err = open("/nonexistent/ttyPUSHBOT").unwrap_err();
        assert!(matches!(err, LinkError::NoSuchPort { .. }), "{err:?}");
        assert!(err.to_string().contains("/nonexistent/ttyPUSHBOT"));
        assert!(err.is_bad_input());
    }

    #[test]
    fn regular_file_is_not_a_serial_port() {
        let file = tempfile::NamedTempFile::new().unwrap();
        let path = file.path().to_str().unwrap().to_string();
        let err = open(&path).unwrap_err();
        assert!(matches!(err, LinkError::NotASerialPort { .. }), "{err:?}");
        assert!(err.to_string().contains(&path));
    }

    #[test]
    fn char_device_that_is_not_a_tty_is_refused() {
        let err = open("/dev/null").unwrap_err();
        assert!(matches!(err, LinkError::NotASerialPort { .. }), "{err:?}");
        assert!(err.to_string().contains("/dev/null"));
    }

    /// A pty opens raw (the frame delimiter 0x00, CR, LF and ^C pass unchanged both ways),
    /// exclusive (a second open is refused as in use), and is free again after [`release`].
    #[test]
    fn a_pty_opens_raw_and_exclusive() {
        use std::io::{Read, Write};
        let (mut master, slave) = TTYPort::pair().unwrap();
        let path = slave.name().unwrap();
        drop(slave);
        let mut port = open(&path).unwrap();
        let mut buf = [0u8; 16];
        let raw = [0x00, b'\r', b'\n', 0x03, 0x7f, 0xff];
        port.write_all(&raw).unwrap();
        port.flush().unwrap();
        let mut got = Vec::new();
        master.set_timeout(Duration::from_millis(200)).unwrap();
        while got.len() < raw.len() {
            let n = master.read(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        assert_eq!(got, raw, "host → robot bytes changed on the way");
        master.write_all(&raw).unwrap();
        let mut back = Vec::new();
        while back.len() < raw.len() {
            let n = port.read(&mut buf).unwrap();
            back.extend_from_slice(&buf[..n]);
        }
        assert_eq!(back, raw, "robot → host bytes changed on the way");
        let second = open(&path).unwrap_err();
        assert!(
            second.to_string().contains("in use"),
            "a second open was not refused as in use: {second}"
        );
        release(&mut port);
        drop(port);
        let mut again = open(&path).expect("free again after release");
        release(&mut again);
    }
}
