//! Reads a recording back: every message with its topic, schema name and time, decoded from
//! JSON. A file cut short (the process was killed while recording) is read up to its last
//! whole chunk and said to be incomplete; a file that is not MCAP, or a message that is not
//! JSON, is a clear error.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use serde_json::Value;

/// One message of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// Its channel's topic.
    pub topic: String,
    /// Its channel's schema name (`foxglove.CompressedImage`, `pushbot.TrackedPoses`, …).
    pub schema: String,
    /// Recording time, ns (robot time, see [`super::writer`]).
    pub log_time: u64,
    /// The message.
    pub value: Value,
}

/// What a recording holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Contents {
    /// Every message that could be read, in file order.
    pub messages: Vec<Message>,
    /// `None` for a whole file; otherwise why reading stopped early (a file cut short).
    pub cut: Option<String>,
}

impl Contents {
    /// The messages on `topic`.
    pub fn on<'a>(&'a self, topic: &'a str) -> impl Iterator<Item = &'a Message> + 'a {
        self.messages.iter().filter(move |m| m.topic == topic)
    }
}

/// Read the recording at `path`.
pub fn read(path: &Path) -> Result<Contents> {
    let bytes =
        std::fs::read(path).with_context(|| format!("reading the recording {}", path.display()))?;
    read_bytes(&bytes).with_context(|| format!("reading the recording {}", path.display()))
}

/// Read a recording from its bytes.
pub fn read_bytes(bytes: &[u8]) -> Result<Contents> {
    if bytes.len() < mcap::MAGIC.len() || !bytes.starts_with(mcap::MAGIC) {
        bail!("not an MCAP file (it does not start with the MCAP magic bytes)");
    }
    let stream =
        mcap::MessageStream::new_with_options(bytes, mcap::read::Options::IgnoreEndMagic.into())
            .map_err(|e| anyhow!("{e}"))?;
    let mut messages = Vec::new();
    let mut cut = None;
    for m in stream {
        let m = match m {
            Ok(m) => m,
            Err(e) => {
                cut = Some(format!(
                    "the file is cut short or damaged after {} messages: {e}",
                    messages.len()
                ));
                break;
            }
        };
        let value: Value = serde_json::from_slice(&m.data).map_err(|e| {
            anyhow!(
                "message {} on {} is not JSON: {e}",
                m.sequence,
                m.channel.topic
            )
        })?;
        messages.push(Message {
            topic: m.channel.topic.clone(),
            schema: m
                .channel
                .schema
                .as_ref()
                .map(|s| s.name.clone())
                .unwrap_or_default(),
            log_time: m.log_time,
            value,
        });
    }
    if cut.is_none() && !bytes.ends_with(mcap::MAGIC) {
        cut = Some("the file has no end (its writer did not finish it)".into());
    }
    Ok(Contents { messages, cut })
}
