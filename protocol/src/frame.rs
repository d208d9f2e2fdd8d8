//! Framing: postcard bytes + CRC-32C, COBS-encoded, zero-delimited (see the crate docs).

use core::fmt;

use serde::{Serialize, de::DeserializeOwned};

/// Largest serialised message, bytes (before CRC and COBS).
pub const MAX_PAYLOAD: usize = 120;
/// Length of the CRC that follows the message, bytes.
pub const CRC_LEN: usize = 4;
/// Largest frame on the wire, the zero delimiter included, bytes.
pub const MAX_FRAME: usize = cobs::max_encoding_length(MAX_PAYLOAD + CRC_LEN) + 1;

/// CRC-32C (Castagnoli): Hamming distance 6 up to well past our frame length.
const CRC32C: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

/// Why a message could not be framed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The serialised message exceeds [`MAX_PAYLOAD`].
    TooLarge,
    /// The output buffer is shorter than the frame (give it [`MAX_FRAME`] bytes).
    BufferTooSmall,
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EncodeError::TooLarge => write!(f, "message longer than {MAX_PAYLOAD} bytes"),
            EncodeError::BufferTooSmall => write!(f, "output buffer shorter than the frame"),
        }
    }
}

/// Why received bytes did not make a message. Each error consumed exactly one frame (up to
/// and including its delimiter); the decoder is ready for the next one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// More than [`MAX_FRAME`] bytes arrived without a delimiter; they were dropped.
    Overflow,
    /// The bytes are not valid COBS.
    Cobs,
    /// Too short to hold a message and its CRC.
    TooShort,
    /// The CRC does not match: the frame was corrupted.
    Crc,
    /// The CRC matched but the bytes are not a message of this protocol version.
    Message,
    /// A message was decoded but bytes were left over.
    TrailingBytes,
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            DecodeError::Overflow => "frame longer than the maximum, dropped",
            DecodeError::Cobs => "invalid COBS encoding",
            DecodeError::TooShort => "frame too short",
            DecodeError::Crc => "CRC mismatch",
            DecodeError::Message => "not a message of this protocol version",
            DecodeError::TrailingBytes => "bytes left over after the message",
        };
        f.write_str(s)
    }
}

/// Frame `msg` into `out`, delimiter included; returns the frame's length.
pub fn encode_frame<T: Serialize>(msg: &T, out: &mut [u8]) -> Result<usize, EncodeError> {
    let mut raw = [0u8; MAX_PAYLOAD + CRC_LEN];
    let n = postcard::to_slice(msg, &mut raw[..MAX_PAYLOAD])
        .map_err(|_| EncodeError::TooLarge)?
        .len();
    let crc = CRC32C.checksum(&raw[..n]);
    raw[n..n + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
    let m = cobs::try_encode(&raw[..n + CRC_LEN], out).map_err(|_| EncodeError::BufferTooSmall)?;
    let delimiter = out.get_mut(m).ok_or(EncodeError::BufferTooSmall)?;
    *delimiter = 0;
    Ok(m + 1)
}

/// Decode one serialised message (no CRC, no COBS), requiring that it uses every byte.
pub fn decode_payload<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, DecodeError> {
    let (msg, rest) = postcard::take_from_bytes(bytes).map_err(|_| DecodeError::Message)?;
    if rest.is_empty() {
        Ok(msg)
    } else {
        Err(DecodeError::TrailingBytes)
    }
}

/// Check and decode one COBS-encoded frame whose delimiter has been stripped.
fn decode_cobs_frame<T: DeserializeOwned>(encoded: &mut [u8]) -> Result<T, DecodeError> {
    let n = cobs::decode_in_place(encoded).map_err(|_| DecodeError::Cobs)?;
    if n <= CRC_LEN {
        return Err(DecodeError::TooShort);
    }
    let (payload, crc) = encoded[..n].split_at(n - CRC_LEN);
    let mut crc_bytes = [0u8; CRC_LEN];
    crc_bytes.copy_from_slice(crc);
    if CRC32C.checksum(payload) != u32::from_le_bytes(crc_bytes) {
        return Err(DecodeError::Crc);
    }
    decode_payload(payload)
}

/// Streaming frame decoder for a byte stream: fixed buffer, no allocation, never panics.
///
/// Feed it bytes as they arrive; at every delimiter it yields the decoded message or the reason
/// the frame was rejected, and starts afresh, so it resynchronises at the next frame whatever
/// came before. Empty frames (repeated delimiters) are skipped silently.
#[derive(Clone)]
pub struct FrameDecoder {
    buf: [u8; MAX_FRAME - 1],
    len: usize,
    overflowed: bool,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; MAX_FRAME - 1],
            len: 0,
            overflowed: false,
        }
    }

    /// Forget a partly received frame.
    pub fn reset(&mut self) {
        self.len = 0;
        self.overflowed = false;
    }

    /// Feed one byte; at a delimiter, returns what the frame held.
    pub fn push<T: DeserializeOwned>(&mut self, byte: u8) -> Option<Result<T, DecodeError>> {
        if byte != 0 {
            match self.buf.get_mut(self.len) {
                Some(slot) => {
                    *slot = byte;
                    self.len += 1;
                }
                None => self.overflowed = true,
            }
            return None;
        }
        let len = core::mem::replace(&mut self.len, 0);
        if core::mem::replace(&mut self.overflowed, false) {
            return Some(Err(DecodeError::Overflow));
        }
        if len == 0 {
            return None;
        }
        Some(decode_cobs_frame(&mut self.buf[..len]))
    }

    /// Feed a slice of bytes, calling `on_frame` for every frame it completes.
    pub fn feed<T: DeserializeOwned>(
        &mut self,
        bytes: &[u8],
        mut on_frame: impl FnMut(Result<T, DecodeError>),
    ) {
        for &b in bytes {
            if let Some(r) = self.push(b) {
                on_frame(r);
            }
        }
    }
}
