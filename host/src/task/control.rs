//! Starting, pausing and stopping a task from outside it. A [`Control`] is shared between the
//! task's thread and whoever started it (the CLI's Ctrl-C handler, the console's buttons);
//! [`Controlled`] puts it between the task's executor and the robot: before every primitive it
//! waits out a pause and refuses to go on after a stop, so a task is cancellable between any two
//! primitives without the executors knowing. Stopping *at once* — mid-primitive — goes to the
//! robot itself ([`crate::exec::live::Stopper`]), and sets the same flag here.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};

use anyhow::Result;
use pushbot_world::Pose;

use super::event::{EventSink, TaskEvent};
use crate::exec::io::{RobotIo, Workspace};

/// Why a task was stopped from outside.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Stopped {
    /// Stop: the task ends before its next primitive.
    #[error("stopped by the operator")]
    Cancelled,
    /// Emergency stop: the motors were cut.
    #[error("emergency stop")]
    Emergency,
}

#[derive(Debug, Default)]
struct Flags {
    cancelled: AtomicBool,
    emergency: AtomicBool,
    paused: Mutex<bool>,
    resumed: Condvar,
}

/// The shared switches of one running task.
#[derive(Debug, Clone, Default)]
pub struct Control(Arc<Flags>);

impl Control {
    /// A control with nothing pressed.
    pub fn new() -> Control {
        Control::default()
    }

    /// End the task before its next primitive.
    pub fn cancel(&self) {
        self.0.cancelled.store(true, Ordering::SeqCst);
        self.0.resumed.notify_all();
    }

    /// Mark an emergency stop (the caller has cut the motors).
    pub fn emergency(&self) {
        self.0.emergency.store(true, Ordering::SeqCst);
        self.cancel();
    }

    /// Pause (`true`) before the next primitive, or go on (`false`).
    pub fn set_paused(&self, paused: bool) {
        *self
            .0
            .paused
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = paused;
        self.0.resumed.notify_all();
    }

    /// Whether the task is paused.
    pub fn paused(&self) -> bool {
        *self
            .0
            .paused
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Why the task must stop, if it must.
    pub fn stopped(&self) -> Option<Stopped> {
        if self.0.emergency.load(Ordering::SeqCst) {
            Some(Stopped::Emergency)
        } else if self.0.cancelled.load(Ordering::SeqCst) {
            Some(Stopped::Cancelled)
        } else {
            None
        }
    }

    /// Before a primitive: wait while paused; an error when stopped.
    pub fn gate(&self, events: &EventSink) -> Result<(), Stopped> {
        let mut paused = self
            .0
            .paused
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if *paused && self.stopped().is_none() {
            events(&TaskEvent::Paused);
            while *paused && self.stopped().is_none() {
                paused = self
                    .0
                    .resumed
                    .wait(paused)
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
            }
            if self.stopped().is_none() {
                events(&TaskEvent::Resumed);
            }
        }
        drop(paused);
        match self.stopped() {
            Some(s) => Err(s),
            None => Ok(()),
        }
    }
}

/// A robot whose every primitive passes the task's [`Control`] first and is told as an event,
/// with the look after it.
pub struct Controlled<'a> {
    inner: &'a mut dyn RobotIo,
    control: Control,
    events: EventSink,
    /// Whether the task pushes one object (its pose goes with each look).
    object: bool,
}

impl<'a> Controlled<'a> {
    /// Wrap `inner`.
    pub fn new(
        inner: &'a mut dyn RobotIo,
        control: Control,
        events: EventSink,
        object: bool,
    ) -> Self {
        Controlled {
            inner,
            control,
            events,
            object,
        }
    }

    fn primitive(&mut self, what: &str, amount: f64) -> Result<()> {
        self.control.gate(&self.events)?;
        (self.events)(&TaskEvent::Primitive {
            what: what.into(),
            amount,
        });
        Ok(())
    }

    fn looked(&mut self) {
        let r = self.inner.robot_pose();
        let object = self.object.then(|| {
            let o = self.inner.object_pose();
            [o.x, o.y, o.theta]
        });
        (self.events)(&TaskEvent::Look {
            t: self.inner.time(),
            robot: [r.x, r.y, r.theta],
            object,
        });
    }

    /// The result of a primitive, an emergency stop pressed meanwhile taking over.
    fn after(&mut self, r: Result<()>) -> Result<()> {
        if let Some(s) = self.control.stopped().filter(|s| *s == Stopped::Emergency) {
            return Err(s.into());
        }
        r?;
        self.looked();
        Ok(())
    }
}

impl RobotIo for Controlled<'_> {
    fn spin(&mut self, angle: f64) -> Result<()> {
        self.primitive("spin", angle)?;
        let r = self.inner.spin(angle);
        self.after(r)
    }

    fn forward(&mut self, distance: f64) -> Result<()> {
        self.primitive("forward", distance)?;
        let r = self.inner.forward(distance);
        self.after(r)
    }

    fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()> {
        self.primitive("drive", duration)?;
        let r = self.inner.drive(v, omega, duration);
        self.after(r)
    }

    fn robot_pose(&mut self) -> Pose {
        self.inner.robot_pose()
    }

    fn object_pose(&mut self) -> Pose {
        self.inner.object_pose()
    }

    fn body_pose(&mut self, id: &str) -> Option<Pose> {
        self.inner.body_pose(id)
    }

    fn time(&self) -> f64 {
        self.inner.time()
    }

    fn workspace(&self) -> Workspace {
        self.inner.workspace()
    }

    fn object_outline(&self) -> Vec<[f64; 2]> {
        self.inner.object_outline()
    }

    fn show_path(&mut self, path: &[[f64; 2]]) {
        (self.events)(&TaskEvent::Plan {
            paths: vec![path.to_vec()],
            note: "the object's path from where it is".into(),
        });
        self.inner.show_path(path);
    }
}

/// Whether `e` is (or was caused by) a stop from outside the task.
pub fn stopped_by(e: &anyhow::Error) -> Option<Stopped> {
    e.chain().find_map(|c| c.downcast_ref::<Stopped>().copied())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cancel_ends_a_pause_and_the_task() {
        let c = Control::new();
        c.set_paused(true);
        let c2 = c.clone();
        let waiter = std::thread::spawn(move || c2.gate(&super::super::event::no_events()));
        std::thread::sleep(std::time::Duration::from_millis(20));
        assert!(!waiter.is_finished(), "a paused gate waits");
        c.cancel();
        assert_eq!(waiter.join().unwrap(), Err(Stopped::Cancelled));
    }

    #[test]
    fn an_emergency_stop_outranks_a_cancel() {
        let c = Control::new();
        assert_eq!(c.gate(&super::super::event::no_events()), Ok(()));
        c.cancel();
        c.emergency();
        assert_eq!(c.stopped(), Some(Stopped::Emergency));
        let e: anyhow::Error = Stopped::Emergency.into();
        assert_eq!(stopped_by(&e.context("spin")), Some(Stopped::Emergency));
    }
}
