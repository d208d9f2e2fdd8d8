//! How the live robot looks: fresh frames through the vision pipeline after every primitive,
//! and, for a body a look did not show, the wait and the look-again moves of
//! [`occlusion`] (the robot may hide a thin object's marker itself).

use anyhow::Result;

use super::LiveRobot;
use crate::exec::occlusion::{self, Looking};
use crate::strategy::sample::Pose2;

impl LiveRobot {
    /// Look now: process fresh frames (taken after this call) and update every body's pose.
    pub fn look(&mut self) -> Result<()> {
        let (wall, t0) = (std::time::Instant::now(), self.robot_clock());
        // The frame being rendered or exposed right now may show the past: skip it.
        let mut after = self.grabber.count() + 1;
        for k in 0..self.opts.frames_per_look.max(1) {
            let time;
            (after, time) = self.process_next(after)?;
            if k == 0 {
                self.look_from = time;
            }
        }
        self.fresh = true;
        tracing::debug!(
            "look: {:.0} ms wall, {:.2} s robot time",
            wall.elapsed().as_secs_f64() * 1e3,
            self.robot_clock() - t0
        );
        Ok(())
    }

    /// Process the first frame after frame number `after`; its number and time.
    fn process_next(&mut self, after: u64) -> Result<(u64, f64)> {
        let (n, frame) = self.grabber.next_after(after, self.opts.frame_timeout)?;
        // The robot stands still while the host looks: its odometry now is its odometry when
        // the frame was taken, and the tracker predicts the primitive's motion from it.
        let odometry = self.robot().telemetry().map(|t| {
            let p = t.pose;
            [f64::from(p.x), f64::from(p.y), f64::from(p.theta)]
        });
        if let Some([x, y, theta]) = odometry {
            self.pipeline.odometry(
                "robot",
                frame.time,
                crate::vision::layout::Pose::new(x, y, theta),
            );
        }
        let r = self.pipeline.process(&frame)?;
        self.frames_seen += 1;
        if let Some(v) = self.view.as_mut()
            && let Err(e) = v.update(&frame, &r, self.pipeline.calibration())
        {
            tracing::warn!("live view: {e:#}");
        }
        if let Some(rec) = &self.recording {
            rec.look(
                &self.robot(),
                &frame,
                &r,
                self.pipeline.calibration(),
                odometry,
            );
        }
        if let Some(w) = &self.watch {
            let plan = self.view.as_ref().map_or(&[][..], |v| &v.plan[..]);
            let overlay =
                crate::exec::view::overlay_svg(&frame, &r, self.pipeline.calibration(), plan);
            w.lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .update(&r, overlay);
        }
        for t in r.tracked.iter().filter(|t| t.seen && !t.rejected) {
            let p = Pose2::new(t.pose.x, t.pose.y, t.pose.theta);
            self.poses.insert(t.body.clone(), (p, t.time));
        }
        Ok((n, frame.time))
    }

    /// Whether the camera has seen `body` since the latest look began.
    fn seen_since_look(&self, body: &str) -> bool {
        self.poses
            .get(body)
            .is_some_and(|(_, t)| *t >= self.look_from)
    }

    /// With the robot still, wait for `body` up to `reacquire_frames` frames; whether it was
    /// seen since the latest look.
    pub(super) fn wait_for(&mut self, body: &str) -> Result<bool> {
        Looker(self).wait_for(body, None)
    }

    /// Wait for `body`; unseen, the robot backs away ([`occlusion`]: it may hide the body
    /// itself), looks again and comes back; still unseen, it is lost and the task stops (the
    /// next primitive fails with it) rather than act on an old pose.
    fn make_sure_of(&mut self, body: &str) {
        if self.sight.lost.is_some() || self.camera_error.is_some() {
            return;
        }
        match occlusion::make_sure_of(&mut Looker(self), body) {
            Ok(sure) => self.sight.record(sure),
            Err(e) => self.camera_error = Some(format!("looking for {body}: {e:#}")),
        }
    }

    /// Look once after a motion, and make sure of the robot and the object: every pose
    /// reported is from after any backing away.
    pub(super) fn look_if_stale(&mut self) {
        if self.fresh || self.camera_error.is_some() || self.sight.lost.is_some() {
            return;
        }
        if let Err(e) = self.look() {
            tracing::warn!("camera: {e:#}");
            self.camera_error = Some(format!("{e:#}"));
            return;
        }
        self.make_sure_of("robot");
        if let Some(object) = self.object.clone() {
            self.make_sure_of(&object);
        }
    }

    pub(super) fn pose_of(&mut self, body: &str) -> Pose2 {
        self.look_if_stale();
        if !self.seen_since_look(body) {
            self.make_sure_of(body);
        }
        self.poses
            .get(body)
            .map_or(Pose2::new(f64::NAN, f64::NAN, f64::NAN), |(p, _)| *p)
    }
}

/// The live robot as [`occlusion`] sees it: looks at fresh frames, waits up to
/// `reacquire_frames` frames, and moves at `look_again_speed`.
struct Looker<'a>(&'a mut LiveRobot);

impl Looking for Looker<'_> {
    fn last_seen(&self, body: &str) -> Option<Pose2> {
        self.0.poses.get(body).map(|(p, _)| *p)
    }

    fn seen_since_look(&self, body: &str) -> bool {
        self.0.seen_since_look(body)
    }

    fn look(&mut self) -> Result<f64> {
        self.0.look()?;
        Ok(self.0.look_from)
    }

    fn look_from(&mut self, t: f64) {
        self.0.look_from = t;
    }

    /// The robot stands still between primitives: frame by frame, up to `reacquire_frames`
    /// unless told.
    fn wait_for(&mut self, body: &str, frames: Option<usize>) -> Result<bool> {
        let r = &mut *self.0;
        let mut after = r.grabber.count();
        for k in 0..frames.unwrap_or(r.opts.reacquire_frames) {
            if r.seen_since_look(body) {
                tracing::info!("{body} seen again after {k} frame(s)");
                return Ok(true);
            }
            (after, _) = r.process_next(after)?;
        }
        Ok(r.seen_since_look(body))
    }

    fn sight(&mut self) -> &mut occlusion::Sight {
        &mut self.0.sight
    }

    fn straight(&mut self, d: f64) -> Result<()> {
        let speed = self.0.opts.look_again_speed as f32;
        self.0.motion(super::Motion::Move, |r| {
            Ok(r.move_distance(d as f32, speed, false)?.outcome)
        })
    }
}
