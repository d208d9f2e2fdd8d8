//! The wire protocol between the pushbot host and the robot.
//!
//! `no_std` and allocation-free, so the firmware and the host share this one crate.
//!
//! # Wire format
//!
//! Every message travels as one **frame**:
//!
//! ```text
//! frame   = cobs( postcard(message) ‖ crc32c_le(postcard(message)) ) ‖ 0x00
//! ```
//!
//! * the message is a [`HostFrame`] (host → robot) or a [`RobotMsg`] (robot → host),
//!   serialised with [`postcard`];
//! * a CRC-32C (Castagnoli) of the serialised bytes follows, little endian;
//! * the whole is COBS-encoded, so the only zero byte on the wire is the frame delimiter,
//!   and a receiver that starts mid-stream or loses bytes resynchronises at the next zero.
//!
//! A serialised message is at most [`MAX_PAYLOAD`] bytes; a frame on the wire, delimiter
//! included, is at most [`MAX_FRAME`] bytes. Longer runs of bytes without a delimiter are
//! discarded by [`FrameDecoder`].
//!
//! # Versioning
//!
//! [`PROTOCOL_VERSION`] is exchanged in the handshake ([`Command::Hello`] →
//! [`RobotMsg::HelloReply`]); a robot refuses every other command until a host with the
//! same version has said hello, and the host refuses a robot with another version. To keep the
//! handshake readable across versions, `Hello` and `HelloReply` are variant 0 of their enums
//! and their first field is the protocol version: those three facts never change.
//!
//! # Sequencing
//!
//! Every [`HostFrame`] carries a sequence number. The robot acknowledges each command
//! ([`RobotMsg::Ack`] or [`RobotMsg::Nack`]) with that number; a frame that repeats the
//! sequence number of the last command is a retry: the robot repeats its answer and does not
//! execute the command again. Heartbeats are not acknowledged and do not take part in this.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod frame;
mod messages;

pub use frame::{
    CRC_LEN, DecodeError, EncodeError, FrameDecoder, MAX_FRAME, MAX_PAYLOAD, decode_payload,
    encode_frame,
};
pub use messages::*;

/// Version of this protocol. Bump on any change to the messages or the framing.
pub const PROTOCOL_VERSION: u16 = 1;
