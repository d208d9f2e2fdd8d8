//! The camera's frame server: frames reach the host over a loopback TCP socket.
//!
//! Protocol (one direction, server → client, per frame, from the first frame published after
//! the client connected):
//!
//! 1. one header line of JSON ending in `\n`:
//!    `{"seq":N,"time":T,"width":W,"height":H,"format":"gray8","truth":[…]}`
//!    (`time` in simulated seconds; `truth` as [`super::MarkerTruth`], may be empty);
//! 2. exactly `W × H` bytes of 8-bit gray levels, row-major, top row first.
//!
//! The client sends nothing. A client that cannot keep up (a write blocks for more than the
//! write timeout) is dropped; the others go on. `pushbot-sim` announces the address in its first
//! JSON line as `"camera": "127.0.0.1:PORT"`.

use std::io::{self, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::CameraFrame;

pub use pushbot_world::camera::FrameHeader;

/// A frame server on a local socket; clients are accepted on a background thread.
#[derive(Debug)]
pub struct CameraServer {
    addr: SocketAddr,
    clients: Arc<Mutex<Vec<TcpStream>>>,
}

impl CameraServer {
    /// Listen on `addr` (use `127.0.0.1:0` for any free port).
    pub fn bind(addr: impl ToSocketAddrs) -> io::Result<CameraServer> {
        let listener = TcpListener::bind(addr)?;
        let addr = listener.local_addr()?;
        let clients = Arc::new(Mutex::new(Vec::new()));
        let accepted = Arc::clone(&clients);
        std::thread::Builder::new()
            .name("camera-accept".into())
            .spawn(move || {
                for stream in listener.incoming() {
                    let Ok(stream) = stream else { continue };
                    let _ = stream.set_nodelay(true);
                    let _ = stream.set_write_timeout(Some(Duration::from_secs(2)));
                    match accepted.lock() {
                        Ok(mut c) => c.push(stream),
                        Err(_) => return,
                    }
                }
            })?;
        Ok(CameraServer { addr, clients })
    }

    /// The address clients connect to.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Number of connected clients.
    pub fn clients(&self) -> usize {
        self.clients.lock().map(|c| c.len()).unwrap_or(0)
    }

    /// Send a frame to every connected client; clients whose connection fails are dropped.
    /// Returns how many clients got it.
    pub fn publish(&self, frame: &CameraFrame) -> usize {
        let header = FrameHeader {
            seq: frame.seq,
            time: frame.time,
            width: frame.width,
            height: frame.height,
            format: "gray8".into(),
            truth: frame.truth.clone(),
        };
        let Ok(mut line) = serde_json::to_vec(&header) else {
            return 0;
        };
        line.push(b'\n');
        let Ok(mut clients) = self.clients.lock() else {
            return 0;
        };
        clients.retain_mut(|c| {
            c.write_all(&line)
                .and_then(|_| c.write_all(&frame.pixels))
                .and_then(|_| c.flush())
                .is_ok()
        });
        clients.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{BufRead, BufReader, Read};

    #[test]
    fn client_receives_header_and_pixels() {
        let server = CameraServer::bind("127.0.0.1:0").unwrap();
        let client = TcpStream::connect(server.local_addr()).unwrap();
        for _ in 0..200 {
            if server.clients() == 1 {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let frame = CameraFrame {
            seq: 3,
            time: 0.1,
            width: 4,
            height: 2,
            pixels: (0..8).collect(),
            truth: vec![],
        };
        assert_eq!(server.publish(&frame), 1);
        let mut r = BufReader::new(client);
        let mut line = String::new();
        r.read_line(&mut line).unwrap();
        let h: FrameHeader = serde_json::from_str(&line).unwrap();
        assert_eq!(
            (h.seq, h.width, h.height, h.format.as_str()),
            (3, 4, 2, "gray8")
        );
        let mut px = vec![0u8; 8];
        r.read_exact(&mut px).unwrap();
        assert_eq!(px, frame.pixels);
    }
}
