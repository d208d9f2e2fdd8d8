//! Fuzz the host's link client through its real byte input (`Client::handle_bytes`), with a
//! fake clock: after a `Hello` and a motion, the input is cut into chunks, each led by a control
//! byte (chunk length, whether time passes and timers run, whether a new command goes out). The
//! client must never panic, answer events only for commands it issued (each at most once), and
//! count at most one frame per delimiter received.
#![no_main]

use std::collections::HashSet;
use std::time::Duration;

use libfuzzer_sys::fuzz_target;
use pushbot::link::{Client, ClientOptions, Event, HostTime};
use pushbot_protocol::Command;

fuzz_target!(|data: &[u8]| {
    let mut now = HostTime::from_micros(0);
    let mut c = Client::new(now, ClientOptions::default());
    let mut issued = HashSet::new();
    issued.insert(c.hello(now));
    let motion = Command::Move {
        distance: 0.1,
        speed: 0.1,
        stop_on_contact: false,
    };
    issued.insert(c.motion(now, motion, 1_000_000));
    let mut answered = HashSet::new();
    let mut known_next = c.next_seq();
    let mut zeros = 0u64;
    let mut rest = data;
    while let Some((&ctl, tail)) = rest.split_first() {
        let len = usize::from(ctl & 0x3f).min(tail.len());
        let (chunk, after) = tail.split_at(len);
        rest = after;
        zeros += chunk.iter().filter(|&&b| b == 0).count() as u64;
        c.handle_bytes(now, chunk);
        if ctl & 0x40 != 0 {
            now = now.after(Duration::from_millis(u64::from(ctl & 0x3f) * 10));
            c.handle_timeout(now);
        }
        // Sequence numbers the client took itself (new hello rounds) are issued too.
        while known_next != c.next_seq() {
            issued.insert(known_next);
            known_next = known_next.wrapping_add(1);
        }
        if ctl & 0x80 != 0 {
            issued.insert(c.command(now, Command::Stop));
            known_next = known_next.wrapping_add(1);
            assert_eq!(c.next_seq(), known_next);
        }
        while c.poll_transmit(now).is_some() {}
        while let Some(e) = c.poll_event() {
            if let Event::Ack { seq } | Event::Nack { seq, .. } | Event::GaveUp { seq, .. } = e {
                assert!(issued.contains(&seq), "{e:?} for a command never sent");
                assert!(answered.insert(seq), "{e:?} twice");
            }
        }
        let s = c.stats();
        assert!(s.frames_ok + s.frames_rejected <= zeros);
    }
});
