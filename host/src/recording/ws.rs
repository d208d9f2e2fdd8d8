//! The live view in Foxglove (`--foxglove [ADDR]`): the recording's channels served over the
//! Foxglove WebSocket protocol (`foxglove.websocket.v1`) while the run goes. Foxglove connects
//! to `ws://ADDR`, is told the channels (`serverInfo`, `advertise`: topic, JSON encoding, the
//! same schema names and JSON schemas as the file), subscribes, and receives each message as it
//! is recorded (binary frames: opcode 1, subscription id, time stamp in ns, the JSON message).
//!
//! Plain threads on `tungstenite`: one accepting, one per client, which reads the client's
//! subscriptions and sends it what it subscribed to. A client that falls behind loses messages
//! (a bounded queue per client), never slows the run. The `foxglove` crate serves the same
//! protocol, but on tokio with protobuf schemas and a TLS stack: far more to build for the
//! handful of messages this needs.

use std::collections::HashMap;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{Context, Result};
use serde_json::{Value, json};
use tungstenite::Message;
use tungstenite::handshake::server::{Request, Response};

/// The WebSocket subprotocol Foxglove speaks.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";

/// Messages a client's queue holds before it starts dropping.
const QUEUE: usize = 512;

/// One message for the clients: channel, time (ns), the JSON message.
type Outgoing = (u16, u64, Arc<Vec<u8>>);

/// A channel as advertised: id, topic, schema name, JSON schema.
#[derive(Debug, Clone)]
pub struct Advertised {
    /// The channel's id (the MCAP channel id).
    pub id: u16,
    /// Topic.
    pub topic: String,
    /// Schema name.
    pub schema_name: String,
    /// The JSON schema.
    pub schema: Value,
}

/// A running Foxglove WebSocket server; stops when dropped.
pub struct FoxgloveServer {
    addr: SocketAddr,
    clients: Arc<Mutex<Vec<SyncSender<Outgoing>>>>,
    stop: Arc<AtomicBool>,
}

impl std::fmt::Debug for FoxgloveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FoxgloveServer")
            .field("addr", &self.addr)
            .finish()
    }
}

impl FoxgloveServer {
    /// Listen on `addr` (port 0 picks one) and advertise `channels` to every client.
    pub fn start(addr: &str, channels: Vec<Advertised>) -> Result<FoxgloveServer> {
        let listener =
            TcpListener::bind(addr).with_context(|| format!("--foxglove: listening on {addr}"))?;
        let local = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let clients: Arc<Mutex<Vec<SyncSender<Outgoing>>>> = Arc::default();
        let stop = Arc::new(AtomicBool::new(false));
        let advertise = advertise_message(&channels);
        let (c, s) = (clients.clone(), stop.clone());
        std::thread::Builder::new()
            .name("foxglove-accept".into())
            .spawn(move || accept_loop(&listener, &c, &s, &advertise))?;
        Ok(FoxgloveServer {
            addr: local,
            clients,
            stop,
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Send a message on `channel` at `ns` to every client subscribed to it.
    pub fn publish(&self, channel: u16, ns: u64, data: &[u8]) {
        let data = Arc::new(data.to_vec());
        if let Ok(mut clients) = self.clients.lock() {
            // A full queue drops the message; a gone client is forgotten.
            clients.retain(|tx| {
                !matches!(
                    tx.try_send((channel, ns, data.clone())),
                    Err(std::sync::mpsc::TrySendError::Disconnected(_))
                )
            });
        }
    }
}

impl Drop for FoxgloveServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Ok(mut c) = self.clients.lock() {
            c.clear();
        }
    }
}

fn advertise_message(channels: &[Advertised]) -> String {
    let chans: Vec<Value> = channels
        .iter()
        .map(|c| {
            json!({"id": c.id, "topic": c.topic, "encoding": "json",
                   "schemaName": c.schema_name, "schema": c.schema.to_string(),
                   "schemaEncoding": "jsonschema"})
        })
        .collect();
    json!({"op": "advertise", "channels": chans}).to_string()
}

fn accept_loop(
    listener: &TcpListener,
    clients: &Arc<Mutex<Vec<SyncSender<Outgoing>>>>,
    stop: &AtomicBool,
    advertise: &str,
) {
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((stream, peer)) => {
                let (tx, rx) = sync_channel(QUEUE);
                if let Ok(mut c) = clients.lock() {
                    c.push(tx);
                }
                let advertise = advertise.to_string();
                let _ = std::thread::Builder::new()
                    .name("foxglove-client".into())
                    .spawn(move || {
                        if let Err(e) = serve(stream, &rx, &advertise) {
                            tracing::debug!("foxglove client {peer}: {e:#}");
                        }
                    });
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_millis(50));
            }
            Err(e) => {
                tracing::warn!("--foxglove: {e}");
                std::thread::sleep(Duration::from_millis(200));
            }
        }
    }
}

// The handshake callback's error type is tungstenite's (an HTTP response), not ours.
#[allow(clippy::result_large_err)]
fn serve(stream: TcpStream, rx: &Receiver<Outgoing>, advertise: &str) -> Result<()> {
    stream.set_nonblocking(false)?;
    let mut ws = tungstenite::accept_hdr(stream, |req: &Request, mut resp: Response| {
        let offered = req
            .headers()
            .get("Sec-WebSocket-Protocol")
            .and_then(|v| v.to_str().ok())
            .is_some_and(|v| v.split(',').any(|p| p.trim() == SUBPROTOCOL));
        if offered {
            resp.headers_mut().insert(
                "Sec-WebSocket-Protocol",
                tungstenite::http::HeaderValue::from_static(SUBPROTOCOL),
            );
        }
        Ok(resp)
    })
    .map_err(|e| anyhow::anyhow!("handshake: {e}"))?;
    ws.get_ref()
        .set_read_timeout(Some(Duration::from_millis(20)))?;
    let info = json!({"op": "serverInfo", "name": "pushbot", "capabilities": [],
                      "supportedEncodings": [], "metadata": {},
                      "sessionId": format!("{}", std::process::id())});
    ws.send(Message::text(info.to_string()))?;
    ws.send(Message::text(advertise))?;
    let mut subs: HashMap<u16, u32> = HashMap::new();
    loop {
        match ws.read() {
            Ok(Message::Text(t)) => handle(&mut subs, t.as_str()),
            Ok(Message::Close(_)) => return Ok(()),
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(e) => return Err(e.into()),
        }
        loop {
            match rx.try_recv() {
                Ok((chan, ns, data)) => {
                    if let Some(sub) = subs.get(&chan) {
                        ws.send(Message::binary(frame(*sub, ns, &data)))?;
                    }
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    let _ = ws.close(None);
                    return Ok(());
                }
            }
        }
    }
}

/// A client's `subscribe` or `unsubscribe`.
fn handle(subs: &mut HashMap<u16, u32>, text: &str) {
    let Ok(v) = serde_json::from_str::<Value>(text) else {
        return;
    };
    let list = |k: &str| {
        v.get(k)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    match v.get("op").and_then(Value::as_str) {
        Some("subscribe") => {
            for s in list("subscriptions") {
                let (Some(id), Some(ch)) = (
                    s.get("id").and_then(Value::as_u64),
                    s.get("channelId").and_then(Value::as_u64),
                ) else {
                    continue;
                };
                if let (Ok(id), Ok(ch)) = (u32::try_from(id), u16::try_from(ch)) {
                    subs.insert(ch, id);
                }
            }
        }
        Some("unsubscribe") => {
            let gone: Vec<u64> = list("subscriptionIds")
                .iter()
                .filter_map(Value::as_u64)
                .collect();
            subs.retain(|_, id| !gone.contains(&u64::from(*id)));
        }
        _ => {}
    }
}

/// A message data frame: opcode 1, subscription id, time stamp (ns), payload; little-endian.
pub fn frame(sub: u32, ns: u64, data: &[u8]) -> Vec<u8> {
    let mut f = Vec::with_capacity(13 + data.len());
    f.push(1);
    f.extend_from_slice(&sub.to_le_bytes());
    f.extend_from_slice(&ns.to_le_bytes());
    f.extend_from_slice(data);
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use tungstenite::WebSocket;
    use tungstenite::client::IntoClientRequest;

    #[test]
    fn a_client_is_told_the_channels_and_gets_what_it_subscribed_to() {
        let chans = vec![
            Advertised {
                id: 3,
                topic: "/log".into(),
                schema_name: "foxglove.Log".into(),
                schema: json!({"title": "foxglove.Log"}),
            },
            Advertised {
                id: 4,
                topic: "/tf".into(),
                schema_name: "foxglove.FrameTransforms".into(),
                schema: json!({}),
            },
        ];
        let server = FoxgloveServer::start("127.0.0.1:0", chans).expect("server");
        let mut req = format!("ws://{}", server.addr())
            .into_client_request()
            .expect("request");
        req.headers_mut().insert(
            "Sec-WebSocket-Protocol",
            tungstenite::http::HeaderValue::from_static(SUBPROTOCOL),
        );
        let (mut ws, resp) = tungstenite::connect(req).expect("connect");
        assert_eq!(
            resp.headers()
                .get("Sec-WebSocket-Protocol")
                .and_then(|v| v.to_str().ok()),
            Some(SUBPROTOCOL)
        );
        let text = |ws: &mut WebSocket<_>| -> Value {
            match ws.read().expect("read") {
                Message::Text(t) => serde_json::from_str(t.as_str()).expect("json"),
                m => panic!("expected text, got {m:?}"),
            }
        };
        assert_eq!(text(&mut ws)["op"], "serverInfo");
        let adv = text(&mut ws);
        assert_eq!(adv["op"], "advertise");
        assert_eq!(adv["channels"][0]["schemaName"], "foxglove.Log");
        assert_eq!(adv["channels"][0]["schemaEncoding"], "jsonschema");
        let sub = json!({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": 3}]});
        ws.send(Message::text(sub.to_string())).expect("subscribe");
        // Publish until the subscription has arrived (the server reads it between sends).
        let got = (0..200).find_map(|i| {
            server.publish(4, 5, b"{\"tf\":1}");
            server.publish(3, 1_000 + i, b"{\"message\":\"hi\"}");
            match ws.read() {
                Ok(Message::Binary(b)) => Some(b.to_vec()),
                _ => None,
            }
        });
        let b = got.expect("a data frame");
        assert_eq!(b[0], 1);
        assert_eq!(u32::from_le_bytes(b[1..5].try_into().expect("4")), 7);
        assert!(u64::from_le_bytes(b[5..13].try_into().expect("8")) >= 1_000);
        assert_eq!(
            &b[13..],
            b"{\"message\":\"hi\"}",
            "only the subscribed channel"
        );
        drop(server);
    }
}
