//! Collect a pushing strategy for an object on the robot itself: Lau, Mitani & Igarashi's
//! Algorithm 1 (§III-C/D) — random pushes, then deliveries to random goals until a streak of
//! successes — every sample written to the strategy file as it is made, so a stopped collection
//! goes on from where it stopped when started again with the same file.

use std::path::PathBuf;

use anyhow::Result;

use super::goal::GoalError;
use super::{Control, EventSink, Failed, Outcome, Session, TaskEvent, drive};
use crate::exec::collect::{CollectParams, collect};
use crate::report::StageReport;
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::Sample;
use crate::strategy::store::StrategyWriter;

/// A collection.
#[derive(Debug, Clone)]
pub struct Collect {
    /// The object's id in the scene.
    pub object: String,
    /// The strategy file (appended to; an existing one is resumed).
    pub out: PathBuf,
    /// Algorithm 1's parameters.
    pub params: CollectParams,
}

impl Collect {
    /// A collection for `object` of `scene` into `out`.
    pub fn new(
        scene: &pushbot_world::Scene,
        object: &str,
        out: PathBuf,
        params: CollectParams,
    ) -> Result<Collect, GoalError> {
        match scene.object(object) {
            Some(o) if o.marker.is_some() => Ok(Collect {
                object: object.into(),
                out,
                params,
            }),
            Some(_) => Err(GoalError(format!(
                "{object} has no marker: the camera cannot follow it"
            ))),
            None => Err(GoalError(format!(
                "the scene {} has no object {object:?}",
                scene.name
            ))),
        }
    }

    /// In words.
    pub fn summary(&self) -> String {
        format!(
            "collect a pushing strategy for {} into {}",
            self.object,
            self.out.display()
        )
    }

    /// Nothing to plan: the pushes are random.
    pub fn plan(&self, _: &mut Session) -> Result<TaskEvent> {
        Ok(TaskEvent::Plan {
            paths: Vec::new(),
            note: format!(
                "{} random pushes of {}, then deliveries to random goals until {} in a row succeed",
                self.params.initial, self.object, self.params.streak
            ),
        })
    }

    /// Collect.
    pub fn run(
        &self,
        session: &mut Session,
        control: &Control,
        events: &EventSink,
    ) -> Result<Outcome, Failed> {
        let fail = |e: anyhow::Error| (e, Vec::new());
        session.live.set_object(&self.object).map_err(fail)?;
        let (mut writer, existing) = StrategyWriter::open(&self.out, &self.object)
            .map_err(|e| fail(anyhow::anyhow!("{e}")))?;
        let resumed = existing.len();
        events(&TaskEvent::Progress {
            note: format!("{resumed} samples in {} already", self.out.display()),
            samples: Some(resumed),
            streak: None,
        });
        let mut strategy = PushStrategy::new(existing, KernelParams::default());
        let pb = indicatif::ProgressBar::hidden();
        let ids = vec![self.object.clone()];
        let mut count = resumed;
        let (rep, trace) = drive(session, &ids, true, control, events, |io| {
            let mut sink = |s: &Sample| -> Result<()> {
                writer.append(s)?;
                count += 1;
                events(&TaskEvent::Progress {
                    note: pb.message(),
                    samples: Some(count),
                    streak: None,
                });
                Ok(())
            };
            collect(io, &mut strategy, &self.params, &mut sink, &pb)
        })?;
        let mut st = StageReport::new(
            "collect",
            &format!("Collect a pushing strategy for {}", self.object),
            "Lau, Mitani & Igarashi §III-C/D (Algorithm 1)",
        );
        // A streak of 0 asks for no evaluation: the collection is done when its samples are.
        let done = rep.streak_reached || self.params.streak == 0;
        st.success = done;
        st.number("Samples", rep.total_samples);
        st.number("Samples resumed from the file", resumed);
        st.number("Goal queries", rep.queries);
        st.number("Successful queries", rep.successes);
        st.number(
            "Minutes of collection",
            super::deliver::round1(rep.total_minutes),
        );
        let message = if self.params.streak == 0 {
            format!("{} samples (no evaluation streak asked)", rep.total_samples)
        } else if rep.streak_reached {
            format!(
                "{} samples; the last {} deliveries succeeded",
                rep.total_samples, self.params.streak
            )
        } else {
            format!(
                "{} samples; the streak of {} was not reached in {} queries",
                rep.total_samples, self.params.streak, rep.queries
            )
        };
        events(&TaskEvent::Progress {
            note: message.clone(),
            samples: Some(rep.total_samples),
            streak: Some(if rep.streak_reached {
                self.params.streak
            } else {
                0
            }),
        });
        st.notes.push(message.clone());
        Ok(Outcome {
            success: done,
            stopped: None,
            message,
            summary: serde_json::to_value(&rep).unwrap_or_default(),
            report: st,
            trace,
        })
    }
}
