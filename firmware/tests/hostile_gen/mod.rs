//! Hostile bytes: framing written apart from the protocol crate (CRC-32C, COBS), and the
//! mutations the hostile tests apply to valid frames: bit flips, inserted and deleted bytes,
//! truncation, splices of two frames, duplicates, runs of zeros, runs without a delimiter
//! longer than a frame, a wrong CRC, and a right CRC over bytes that are no message.
//!
//! Shared by `firmware/tests/hostile.rs` and `host/tests/hostile_link.rs` (which includes this
//! file by path), so both ends of the link meet the same hostile wire.

#![allow(dead_code)]

use pushbot_protocol::{MAX_FRAME, MAX_PAYLOAD};
use rand::Rng;

/// CRC-32C (Castagnoli, reflected, as the protocol uses it), bit by bit.
pub fn crc32c(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0x82F6_3B78
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// COBS encoding of `data` (no delimiter).
pub fn cobs_encode(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0];
    let mut code_at = 0;
    let mut code = 1u8;
    for &b in data {
        if b == 0 {
            out[code_at] = code;
            code_at = out.len();
            out.push(0);
            code = 1;
        } else {
            out.push(b);
            code += 1;
            if code == 0xff {
                out[code_at] = code;
                code_at = out.len();
                out.push(0);
                code = 1;
            }
        }
    }
    out[code_at] = code;
    out
}

/// COBS decoding of one frame without its delimiter; `None` if it is not valid COBS.
pub fn cobs_decode(enc: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < enc.len() {
        let code = usize::from(enc[i]);
        let end = i + code;
        if code == 0 || end > enc.len() {
            return None;
        }
        out.extend_from_slice(&enc[i + 1..end]);
        i = end;
        if code < 0xff && i < enc.len() {
            out.push(0);
        }
    }
    Some(out)
}

/// A frame on the wire, delimiter included, for `payload` under the given CRC.
pub fn frame_with_crc(payload: &[u8], crc: u32) -> Vec<u8> {
    let mut raw = payload.to_vec();
    raw.extend_from_slice(&crc.to_le_bytes());
    let mut out = cobs_encode(&raw);
    out.push(0);
    out
}

/// The serialised message inside a well-formed frame (delimiter included).
pub fn payload_of(frame: &[u8]) -> Vec<u8> {
    let raw = cobs_decode(&frame[..frame.len() - 1]).expect("a well-formed frame");
    raw[..raw.len() - 4].to_vec()
}

/// Whether `frame` (delimiter included) may arrive whole from `piece`: as a segment that
/// starts at the beginning of `piece` or after a zero, and ends at a zero or at the end of
/// `piece` (where the next piece may bring the delimiter).
pub fn delivers(piece: &[u8], frame: &[u8]) -> bool {
    let body = &frame[..frame.len() - 1];
    piece.split(|&b| b == 0).any(|s| s == body)
}

/// What a mutation produced.
#[derive(Default)]
pub struct Mutated {
    /// Serialised messages whose CRC-valid frames may arrive whole (the caller decides what
    /// they are): the frame itself when it survived, a splice partner that survived, the
    /// garbage under a correct CRC.
    pub valid: Vec<Vec<u8>>,
    /// Frames that are certainly rejected (delimited on both sides, wrong CRC or no message).
    pub known_bad: u32,
    /// Which mutation, for the tallies (index into [`MUTATIONS`]).
    pub kind: usize,
}

/// Names of the mutations, in the order of [`Mutated::kind`].
pub const MUTATIONS: [&str; 11] = [
    "intact",
    "bit flips",
    "inserted bytes",
    "deleted bytes",
    "truncated",
    "spliced",
    "duplicated",
    "zero runs",
    "long run without delimiter",
    "wrong CRC",
    "garbage under a right CRC",
];

fn nonzero(rng: &mut impl Rng) -> u8 {
    rng.random_range(1..=255)
}

/// Append `frame` (a valid frame, delimiter included), mutated or not, to `out`; `other` is a
/// second valid frame for splices.
pub fn mutate(rng: &mut impl Rng, frame: &[u8], other: &[u8], out: &mut Vec<u8>) -> Mutated {
    let mut m = Mutated::default();
    let start = out.len();
    let len = frame.len();
    let roll = rng.random_range(0..20);
    m.kind = match roll {
        0..=6 => 0,
        7..=8 => 1,
        9 => 2,
        10 => 3,
        11 => 4,
        12 => 5,
        13 => 6,
        14 => 7,
        15 => 8,
        16..=17 => 9,
        _ => 10,
    };
    match m.kind {
        0 => out.extend_from_slice(frame),
        1 => {
            let mut b = frame.to_vec();
            for _ in 0..rng.random_range(1..=3) {
                let i = rng.random_range(0..len);
                b[i] ^= 1 << rng.random_range(0..8);
            }
            out.extend_from_slice(&b);
        }
        2 => {
            let mut b = frame.to_vec();
            for _ in 0..rng.random_range(1..=4) {
                let i = rng.random_range(0..=b.len());
                b.insert(i, rng.random());
            }
            out.extend_from_slice(&b);
        }
        3 => {
            let mut b = frame.to_vec();
            for _ in 0..rng.random_range(1..=4.min(b.len())) {
                let i = rng.random_range(0..b.len());
                b.remove(i);
            }
            out.extend_from_slice(&b);
        }
        4 => out.extend_from_slice(&frame[..rng.random_range(0..len - 1)]),
        5 => {
            out.extend_from_slice(&frame[..rng.random_range(1..len)]);
            out.extend_from_slice(&other[rng.random_range(1..other.len())..]);
        }
        6 => {
            out.extend_from_slice(frame);
            out.extend_from_slice(frame);
        }
        7 => {
            let before = rng.random_range(0..=40);
            out.resize(out.len() + before, 0);
            out.extend_from_slice(frame);
            let after = rng.random_range(0..=40);
            out.resize(out.len() + after, 0);
        }
        8 => {
            for _ in 0..rng.random_range(MAX_FRAME..=3 * MAX_FRAME) {
                out.push(nonzero(rng));
            }
            if rng.random_bool(0.5) {
                out.push(0); // ends the run: one oversized frame
            }
            out.extend_from_slice(frame); // otherwise the frame is swallowed by the run
        }
        9 => {
            let p = payload_of(frame);
            let crc = crc32c(&p) ^ rng.random_range(1..=u32::MAX);
            out.push(0);
            out.extend_from_slice(&frame_with_crc(&p, crc));
            m.known_bad += 1;
        }
        _ => {
            let mut p = payload_of(frame);
            match rng.random_range(0..4) {
                0 => {
                    let n = rng.random_range(1..=MAX_PAYLOAD);
                    p = (0..n).map(|_| rng.random()).collect();
                }
                1 => {
                    let i = rng.random_range(0..p.len());
                    p[i] = rng.random();
                }
                2 => p.truncate(rng.random_range(1..=p.len())),
                _ => p.push(rng.random()),
            }
            out.push(0);
            out.extend_from_slice(&frame_with_crc(&p, crc32c(&p)));
            m.valid.push(p);
        }
    }
    let piece = &out[start..];
    if delivers(piece, frame) {
        m.valid.push(payload_of(frame));
    }
    if m.kind == 5 && delivers(piece, other) {
        m.valid.push(payload_of(other));
    }
    m
}

/// Cut `len` bytes into random chunks of 1..=`max` bytes; returns the chunk ends.
pub fn chunks(rng: &mut impl Rng, len: usize, max: usize) -> Vec<usize> {
    let mut ends = Vec::new();
    let mut at = 0;
    while at < len {
        at = (at + rng.random_range(1..=max)).min(len);
        ends.push(at);
    }
    ends
}
