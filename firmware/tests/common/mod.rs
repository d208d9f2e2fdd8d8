//! The test bench shared by the core's test files: the core driven through its public
//! contract, a small first-order motor model closing the loop, replies decoded with the
//! protocol's own `FrameDecoder`; and a tiny deterministic generator.

#![allow(dead_code)]

use pushbot_firmware::{Core, Inputs, Outputs, RobotParams};
use pushbot_protocol::{
    Command, Done, FrameDecoder, HelloReply, HostFrame, PROTOCOL_VERSION, RobotMsg, encode_frame,
};

/// One wheel: ω' = (K·u − ω)/τ; the encoder counts the angle.
#[derive(Clone, Copy)]
pub struct Motor {
    pub w: f32,
    pub angle: f64,
}

/// The robot in its world for the test: two motors, an optional wall, a bumper.
pub struct Bench {
    pub core: Core,
    pub now: u64,
    pub motors: [Motor; 2],
    /// rad/s per unit duty.
    pub k: f32,
    pub tau: f32,
    /// Encoders stop counting (motors absent).
    pub frozen: bool,
    /// Forward travel (m) at which the bumper touches a wall and the wheels block.
    pub wall: Option<f32>,
    /// Raw bumper bits forced on top of the wall contact.
    pub bumper_raw: u8,
    /// Heartbeat every this many µs (None: silent host).
    pub heartbeat_us: Option<u64>,
    pub last_heartbeat: u64,
    pub seq: u16,
    pub rx: FrameDecoder,
    pub msgs: Vec<(u64, RobotMsg)>,
    pub duties: Vec<(u64, Outputs)>,
    /// True body speed of the model after each tick, m/s.
    pub speeds: Vec<f32>,
    pub params: RobotParams,
}

impl Bench {
    pub fn new() -> Self {
        let params = RobotParams::default();
        Bench {
            core: Core::new(params),
            now: 0,
            motors: [Motor { w: 0.0, angle: 0.0 }; 2],
            k: 32.0,
            tau: 0.02,
            frozen: false,
            wall: None,
            bumper_raw: 0,
            heartbeat_us: Some(50_000),
            last_heartbeat: 0,
            seq: 0,
            rx: FrameDecoder::new(),
            msgs: Vec::new(),
            duties: Vec::new(),
            speeds: Vec::new(),
            params,
        }
    }

    /// A bench with an open session.
    pub fn connected() -> Self {
        let mut b = Bench::new();
        b.tick();
        b.send(Command::Hello {
            protocol: PROTOCOL_VERSION,
        });
        b.tick();
        assert!(b.hello_reply().is_some_and(|r| r.accepted));
        b
    }

    pub fn hello_reply(&self) -> Option<HelloReply> {
        self.msgs.iter().rev().find_map(|(_, m)| match m {
            RobotMsg::HelloReply(r) => Some(*r),
            _ => None,
        })
    }

    pub fn send_frame(&mut self, frame: HostFrame) {
        let mut buf = [0u8; 256];
        let n = encode_frame(&frame, &mut buf).expect("encode");
        self.core.receive(self.now, &buf[..n]);
    }

    /// Send a command under a fresh sequence number; returns it.
    pub fn send(&mut self, cmd: Command) -> u16 {
        self.seq = self.seq.wrapping_add(1);
        self.send_frame(HostFrame { seq: self.seq, cmd });
        self.seq
    }

    pub fn travel(&self) -> f32 {
        let r = self.params.geometry.wheel_radius as f64;
        (0.5 * (self.motors[0].angle + self.motors[1].angle) * r) as f32
    }

    pub fn encoder(&self) -> [i32; 2] {
        let cpr = self.params.geometry.encoder_cpr as f64;
        self.motors
            .map(|m| (m.angle * cpr / (2.0 * std::f64::consts::PI)).floor() as i64 as i32)
    }

    /// One control period: step the core, move the motors, collect what the core sent.
    pub fn tick(&mut self) -> Outputs {
        if let Some(h) = self.heartbeat_us
            && self.now >= self.last_heartbeat + h
        {
            self.last_heartbeat = self.now;
            self.send_frame(HostFrame {
                seq: 0,
                cmd: Command::Heartbeat,
            });
        }
        let at_wall = self.wall.is_some_and(|w| self.travel() >= w);
        let bumper = self.bumper_raw | if at_wall { 0b010 } else { 0 };
        let encoder = self.encoder();
        let out = self.core.step(self.now, &Inputs { encoder, bumper });
        for d in out.duty {
            assert!((-1.0..=1.0).contains(&d), "duty {d}");
        }
        self.duties.push((self.now, out));
        let dt_us = self.core.tick_period_us() as u64;
        let dt = dt_us as f32 * 1e-6;
        for (m, u) in self.motors.iter_mut().zip(out.duty) {
            m.w += (self.k * u - m.w) / self.tau * dt;
            if at_wall && m.w > 0.0 {
                m.w = 0.0; // the wall blocks forward motion
            }
            if !self.frozen {
                m.angle += (m.w * dt) as f64;
            }
        }
        self.now += dt_us;
        let r = self.params.geometry.wheel_radius;
        self.speeds
            .push(0.5 * (self.motors[0].w + self.motors[1].w) * r);
        let mut buf = [0u8; 64];
        loop {
            let n = self.core.transmit(&mut buf);
            if n == 0 {
                break;
            }
            let now = self.now;
            let msgs = &mut self.msgs;
            self.rx.feed::<RobotMsg>(&buf[..n], |r| {
                msgs.push((now, r.expect("robot frames are valid")))
            });
        }
        out
    }

    pub fn run_ms(&mut self, ms: u64) {
        for _ in 0..ms * 1000 / self.core.tick_period_us() as u64 {
            self.tick();
        }
    }

    /// Tick until `done(seq)` arrives or `max_ms` passes.
    pub fn run_until_done(&mut self, seq: u16, max_ms: u64) -> Option<Done> {
        let end = self.now + max_ms * 1000;
        while self.now < end {
            self.tick();
            if let Some(d) = self.done(seq) {
                return Some(d);
            }
        }
        None
    }

    pub fn done(&self, seq: u16) -> Option<Done> {
        self.msgs.iter().find_map(|(_, m)| match m {
            RobotMsg::Done(d) if d.seq == seq => Some(*d),
            _ => None,
        })
    }

    pub fn dones(&self, seq: u16) -> usize {
        self.msgs
            .iter()
            .filter(|(_, m)| matches!(m, RobotMsg::Done(d) if d.seq == seq))
            .count()
    }

    /// The (first) answer to command `seq`.
    pub fn reply(&self, seq: u16) -> Option<RobotMsg> {
        self.msgs.iter().find_map(|(_, m)| match m {
            RobotMsg::Ack { seq: s } | RobotMsg::Nack { seq: s, .. } if *s == seq => Some(*m),
            _ => None,
        })
    }

    pub fn acked(&self, seq: u16) -> bool {
        matches!(self.reply(seq), Some(RobotMsg::Ack { .. }))
    }

    pub fn any_motion(&self) -> bool {
        self.duties.iter().any(|(_, o)| o.duty != [0.0, 0.0])
    }
}

/// A tiny deterministic generator for garbage.
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> u8 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 56) as u8
    }
}
