//! The emergency stop's precedence over everything else on the link: it does not queue behind
//! a command in flight, and nothing withdrawn for it is ever resent.

use pushbot_protocol::Command;

use super::{Answer, Client, HostTime};

impl Client {
    /// Send `EmergencyStop` at once, even with other commands in flight: the commands awaiting
    /// an answer are withdrawn (their answer is [`Answer::Preempted`]; they are never resent,
    /// so the robot cannot run one of them again after its stop), frames not yet written are
    /// dropped, and the stop is the next frame out. Its own answer is [`Client::take_answer`].
    pub fn emergency_stop(&mut self, now: HostTime) -> u16 {
        let hello = self.hello.map(|h| h.seq);
        let mut withdrawn = Vec::new();
        self.pending.retain(|p| {
            let keep = Some(p.frame.seq) == hello;
            if !keep {
                withdrawn.push(p.frame.seq);
            }
            keep
        });
        self.transmits.clear();
        let seq = self.command(now, Command::EmergencyStop);
        for s in withdrawn {
            self.watched.retain(|w| w.seq != s);
            self.answer(s, Answer::Preempted);
        }
        seq
    }
}
