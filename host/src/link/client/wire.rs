//! The host's framing of the link, used only by the client ([`super`]): encode a
//! [`HostFrame`], and read [`RobotMsg`]s from a byte stream, recognising a `HelloReply` of
//! another protocol version by the fields every version keeps in place.

use pushbot_protocol::{DecodeError, FrameDecoder, HostFrame, MAX_FRAME, RobotMsg, encode_frame};

/// What one completed frame held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Incoming {
    /// A message of this protocol version.
    Msg(RobotMsg),
    /// A frame that was rejected, with the protocol version it carries if it is a `HelloReply`
    /// of another version.
    Rejected {
        /// Why it was rejected.
        error: DecodeError,
        /// The version of a foreign `HelloReply`.
        foreign_hello: Option<u16>,
    },
}

/// A streaming reader of robot messages.
pub(crate) struct Reader {
    decoder: FrameDecoder,
    /// The current frame's raw bytes, to read the version of a reply we cannot decode.
    raw: Vec<u8>,
    /// The raw bytes of the latest completed frame (delimiter excluded).
    last: Vec<u8>,
}

impl Reader {
    /// An empty reader.
    pub fn new() -> Reader {
        Reader {
            decoder: FrameDecoder::new(),
            raw: Vec::with_capacity(MAX_FRAME),
            last: Vec::with_capacity(MAX_FRAME),
        }
    }

    /// Feed one byte; at a frame's end, what it held.
    pub fn push(&mut self, b: u8) -> Option<Incoming> {
        if b != 0 && self.raw.len() < MAX_FRAME {
            self.raw.push(b);
        }
        let result = self.decoder.push::<RobotMsg>(b);
        if b == 0 {
            std::mem::swap(&mut self.last, &mut self.raw);
            self.raw.clear();
        }
        let frame = &self.last;
        match result? {
            Ok(msg) => Some(Incoming::Msg(msg)),
            Err(error) => {
                // CRC good but not a message of ours: another protocol version?
                let foreign_hello =
                    if matches!(error, DecodeError::Message | DecodeError::TrailingBytes) {
                        frame_payload(frame).and_then(|p| peek_hello_version(&p))
                    } else {
                        None
                    };
                Some(Incoming::Rejected {
                    error,
                    foreign_hello,
                })
            }
        }
    }

    /// The raw (COBS-encoded) bytes of the latest frame completed, delimiter excluded.
    pub fn last_frame(&self) -> &[u8] {
        &self.last
    }
}

/// One host frame on the wire, delimiter included.
pub(crate) fn encode(frame: &HostFrame) -> Result<Vec<u8>, pushbot_protocol::EncodeError> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_frame(frame, &mut buf)?;
    Ok(buf[..n].to_vec())
}

/// The protocol version in a serialised `HelloReply` of any protocol version: the crate docs
/// promise it is variant 0 of the robot's messages and its first field, a postcard varint.
pub(crate) fn peek_hello_version(payload: &[u8]) -> Option<u16> {
    let (&variant, rest) = payload.split_first()?;
    if variant != 0 {
        return None;
    }
    let mut value: u32 = 0;
    for (i, &b) in rest.iter().take(3).enumerate() {
        value |= u32::from(b & 0x7f) << (7 * i);
        if b & 0x80 == 0 {
            return u16::try_from(value).ok();
        }
    }
    None
}

/// The message bytes of a frame (COBS decoded, CRC stripped; the decoder checked the CRC).
fn frame_payload(encoded: &[u8]) -> Option<Vec<u8>> {
    let mut buf = encoded.to_vec();
    let n = cobs::decode_in_place(&mut buf).ok()?;
    buf.truncate(n.checked_sub(pushbot_protocol::CRC_LEN)?);
    Some(buf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_protocol::HelloReply;

    #[test]
    fn hello_version_is_read_from_any_hello_reply() {
        // Our own HelloReply, serialised: its version is where every version keeps it.
        let mut frame = [0u8; MAX_FRAME];
        for version in [0u16, 1, 127, 128, 300, u16::MAX] {
            let msg = RobotMsg::HelloReply(HelloReply {
                protocol: version,
                accepted: false,
                firmware: pushbot_protocol::FirmwareVersion {
                    major: 1,
                    minor: 2,
                    patch: 3,
                },
                geometry: pushbot_protocol::Geometry {
                    wheel_base: 0.1,
                    wheel_radius: 0.02,
                    bumper_radius: 0.05,
                    encoder_cpr: 1000,
                    control_hz: 1000,
                },
            });
            let n = encode_frame(&msg, &mut frame).unwrap();
            let payload = frame_payload(&frame[..n - 1]).unwrap();
            assert_eq!(peek_hello_version(&payload), Some(version));
        }
        // Other messages are not hellos.
        let n = encode_frame(&RobotMsg::Ack { seq: 0 }, &mut frame).unwrap();
        assert_eq!(
            peek_hello_version(&frame_payload(&frame[..n - 1]).unwrap()),
            None
        );
        assert_eq!(peek_hello_version(&[]), None);
        assert_eq!(peek_hello_version(&[0, 0xff, 0xff, 0xff]), None);
    }
}
