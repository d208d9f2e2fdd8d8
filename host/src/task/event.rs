//! What a running task tells the world, as data: every look, plan, re-plan, recovery, stall,
//! loss of sight and its end. The CLI prints these, the console streams them to the browser,
//! the run's log keeps them; none of them runs a loop of its own.

use std::sync::Arc;

/// One thing that happened in a task.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TaskEvent {
    /// The task started.
    Started {
        /// Which task (`deliver`, `rearrange`, `stable`, `collect`).
        task: String,
        /// What it was asked, in words.
        summary: String,
    },
    /// The camera looked after a primitive: where the robot and the object are.
    Look {
        /// Mission time, s.
        t: f64,
        /// The robot's pose (x, y m; heading rad).
        robot: [f64; 3],
        /// The pushed object's marker pose, when the task pushes one.
        object: Option<[f64; 3]>,
    },
    /// A plan, to draw over the table: each path a polyline in table metres.
    Plan {
        /// The paths (the object's, or each box's).
        paths: Vec<Vec<[f64; 2]>>,
        /// What was planned, in words.
        note: String,
    },
    /// The task planned again from what it saw.
    Replan {
        /// Why.
        note: String,
    },
    /// A primitive sent to the robot.
    Primitive {
        /// `spin`, `forward` or `drive`.
        what: String,
        /// Its size: rad, m, or s.
        amount: f64,
    },
    /// The link broke and was recovered.
    Recovery {
        /// Recoveries so far.
        count: usize,
    },
    /// A push did not move what it should have.
    Stall {
        /// What stalled.
        note: String,
    },
    /// The camera lost a body.
    Lost {
        /// Which, and for how long.
        note: String,
    },
    /// Progress of a long task (collection: samples and streak).
    Progress {
        /// What was done so far, in words.
        note: String,
        /// Samples of the strategy so far (collection).
        samples: Option<usize>,
        /// Straight successful deliveries (collection's evaluation).
        streak: Option<usize>,
    },
    /// Paused before the next primitive.
    Paused,
    /// Going on after a pause.
    Resumed,
    /// The task ended.
    Done {
        /// It reached its goal.
        success: bool,
        /// How it ended, in words.
        message: String,
    },
}

/// Where a task's events go: a function called on the task's thread, in order.
pub type EventSink = Arc<dyn Fn(&TaskEvent) + Send + Sync>;

/// A sink that drops every event.
pub fn no_events() -> EventSink {
    Arc::new(|_| {})
}
