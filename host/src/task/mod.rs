//! Tasks: the one interface through which anything moves the robot. A task is built from a goal
//! the operator chose (checked against the scene before anything moves, [`goal`]), starts from
//! the *observed* table — the camera's poses, not the scene file's starts — runs on a
//! [`session::Session`] (a real robot or the built-in simulated target, alike), reports what
//! happens as [`event::TaskEvent`]s, and can be paused, cancelled between primitives or
//! stopped at once ([`control`]). The CLI (`pushbot run …`, `pushbot collect`), the console and
//! the recordings all start and read these tasks; none runs a pipeline of its own.
//!
//! | task | paper | executor |
//! |---|---|---|
//! | [`deliver`] | Lau, Mitani & Igarashi §III-E (Algorithm 2), the dipole field baseline | [`crate::exec::deliver_path`], [`crate::exec::deliver`] |
//! | [`rearrange`] | Ben-Shahar & Rivlin §IV–V (cost map, restoration; the practical mode) | [`crate::exec::rearrange`] |
//! | `stable` | Lynch & Mason §4 (stable pushes), driven closed loop | [`crate::exec::stable_feedback`] |
//! | [`collect`] | Lau, Mitani & Igarashi §III-C/D (Algorithm 1) | [`crate::exec::collect`] |

pub mod collect;
pub mod control;
pub mod deliver;
pub mod event;
pub mod folder;
pub mod goal;
pub mod rearrange;
pub mod session;
#[cfg(feature = "sim")]
pub mod stable;

use anyhow::Result;

use crate::exec::record::{Recorder, TracePoint, TruthProbe};
use crate::report::StageReport;
use crate::strategy::sample::Pose2;
pub use control::{Control, Controlled, Stopped};
pub use event::{EventSink, TaskEvent};
pub use session::{Session, Where};

/// A task, ready to run.
#[derive(Debug, Clone)]
pub enum Task {
    /// Deliver one object to a position.
    Deliver(deliver::Deliver),
    /// Rearrange the boxes into a goal arrangement.
    Rearrange(rearrange::Rearrange),
    /// Push the slider with stable pushes to a goal pose.
    #[cfg(feature = "sim")]
    Stable(Box<stable::Stable>),
    /// Collect a pushing strategy for an object.
    Collect(collect::Collect),
}

impl Task {
    /// Its name: `deliver`, `rearrange`, `stable`, `collect`.
    pub fn name(&self) -> &'static str {
        match self {
            Task::Deliver(_) => "deliver",
            Task::Rearrange(_) => "rearrange",
            #[cfg(feature = "sim")]
            Task::Stable(_) => "stable",
            Task::Collect(_) => "collect",
        }
    }

    /// What it was asked, in words.
    pub fn summary(&self) -> String {
        match self {
            Task::Deliver(d) => d.summary(),
            Task::Rearrange(r) => r.summary(),
            #[cfg(feature = "sim")]
            Task::Stable(s) => s.summary(),
            Task::Collect(c) => c.summary(),
        }
    }

    /// Plan from the observed table without moving: the paths to draw.
    pub fn plan(&self, session: &mut Session) -> Result<event::TaskEvent> {
        match self {
            Task::Deliver(d) => d.plan(session),
            Task::Rearrange(r) => r.plan(session),
            #[cfg(feature = "sim")]
            Task::Stable(s) => s.plan(session),
            Task::Collect(c) => c.plan(session),
        }
    }

    /// Run it on `session` to its end, a stop, or an error.
    pub fn run(&self, session: &mut Session, control: &Control, events: &EventSink) -> Outcome {
        events(&TaskEvent::Started {
            task: self.name().into(),
            summary: self.summary(),
        });
        let started = std::time::Instant::now();
        let t0 = crate::exec::io::RobotIo::time(&session.live);
        let result = match self {
            Task::Deliver(d) => d.run(session, control, events),
            Task::Rearrange(r) => r.run(session, control, events),
            #[cfg(feature = "sim")]
            Task::Stable(s) => s.run(session, control, events),
            Task::Collect(c) => c.run(session, control, events),
        };
        let mut out = match result {
            Ok(o) => o,
            Err((e, trace)) => {
                let message = match control::stopped_by(&e) {
                    Some(s) => format!("{s}: {e:#}"),
                    None => format!("{e:#}"),
                };
                let mut report = StageReport::new(self.name(), &self.summary(), "");
                report.notes.push(message.clone());
                Outcome {
                    success: false,
                    stopped: control::stopped_by(&e),
                    message,
                    report,
                    trace,
                    summary: serde_json::json!({}),
                }
            }
        };
        out.report.wall_s = started.elapsed().as_secs_f64();
        out.report.mission_s = crate::exec::io::RobotIo::time(&session.live) - t0;
        events(&TaskEvent::Done {
            success: out.success,
            message: out.message.clone(),
        });
        out
    }
}

/// How a task ended.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// It reached its goal (by the simulator's truth on the built-in target).
    pub success: bool,
    /// It was stopped from outside.
    pub stopped: Option<Stopped>,
    /// How it ended, in words.
    pub message: String,
    /// Its section of the run's report (numbers with units, notes).
    pub report: StageReport,
    /// What the camera (and the simulator) saw after every primitive.
    pub trace: Vec<TracePoint>,
    /// The task's own numbers, for `summary.json` and `--json`.
    pub summary: serde_json::Value,
}

/// A task's run that failed: the error and what was traced until then.
pub type Failed = (anyhow::Error, Vec<TracePoint>);

/// Run `f` on the session's robot as the tasks do: recorded after every primitive (with the
/// truth on the built-in target), every primitive passing `control` and told to `events`.
pub(crate) fn drive<T>(
    session: &mut Session,
    ids: &[String],
    object: bool,
    control: &Control,
    events: &EventSink,
    f: impl FnOnce(&mut dyn crate::exec::io::RobotIo) -> Result<T>,
) -> Result<(T, Vec<TracePoint>), Failed> {
    let target = session.target();
    let probe: Option<TruthProbe<'_>> = target.map(|t| -> TruthProbe<'_> {
        Box::new(move || {
            let truth = t.truth();
            let p = |q: [f64; 3]| Pose2::new(q[0], q[1], q[2]);
            truth.map_or(
                (Pose2::new(f64::NAN, f64::NAN, f64::NAN), Vec::new()),
                |t| {
                    (
                        p(t.robot),
                        t.objects.into_iter().map(|(id, q)| (id, p(q))).collect(),
                    )
                },
            )
        })
    });
    let recording = session.live.recording_handle();
    let mut rec = Recorder::new(&mut session.live, ids, probe).with_recording(recording);
    let out = {
        let mut io = Controlled::new(&mut rec, control.clone(), events.clone(), object);
        f(&mut io)
    };
    let trace = rec.into_trace();
    match out {
        Ok(v) => Ok((v, trace)),
        Err(e) => Err((e, trace)),
    }
}

/// Where the object's marker truly ends, from the last traced truth.
pub(crate) fn marker_truth(
    scene: &pushbot_world::Scene,
    id: &str,
    trace: &[TracePoint],
) -> Option<[f64; 2]> {
    let object = scene.object(id)?;
    let (_, truth) = trace.last()?.truth.as_ref()?;
    let (_, p) = truth.iter().find(|(o, _)| o == id)?;
    let m = object.marker.map_or([0.0, 0.0], |m| [m.x, m.y]);
    let (s, c) = p.theta.sin_cos();
    Some([p.x + c * m[0] - s * m[1], p.y + s * m[0] + c * m[1]])
}
