//! Recordings of runs that roboticists' tools open: MCAP files whose channels use Foxglove's
//! well-known schemas (camera image, calibration, image annotations, frame transforms, scene
//! entities, paths as line primitives, logs) and pushbot's own JSON schemas (telemetry, link
//! events, tracked poses, sessions, trace points), time-stamped in robot time.
//!
//! - [`schema`]: the JSON schemas;
//! - [`foxglove`]: pushbot's types as messages of those schemas (pure);
//! - [`writer`]: the MCAP file being written, flushed after every camera look so a killed run
//!   leaves a readable file, and the handle the parts of a run share;
//! - [`live`]: what a robot seen by a camera records at every look;
//! - [`reader`]: a recording read back, a cut one up to its last whole chunk;
//! - [`replay`]: tracking re-run from a recording, compared with the live run's poses;
//! - [`report`]: the report of a replay;
//! - [`ws`]: the same channels served live to Foxglove over its WebSocket protocol.

pub mod foxglove;
pub mod live;
pub mod reader;
pub mod replay;
pub mod report;
pub mod schema;
pub mod writer;
pub mod ws;

pub use writer::{Recording, RecordingHandle};
