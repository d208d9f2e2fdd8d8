//! When the robot hides a marker. A body the camera has not seen since the robot stopped may
//! be lost under the robot itself: a thin object's marker overhangs its body (Lau et al.'s wire
//! cutter and snake are narrower than their 5 cm markers), and with the robot standing against
//! it the robot's own marker covers the overhang. Waiting does not help; moving does. Before a
//! body counts as lost, the robot moves [`BACK_OFF`] along its own axis, the way that takes its
//! marker further from where the body may be ([`back_offs`]: where it was last seen, or carried
//! along by a push since), the camera looks again, and the robot drives back to where it stood
//! (the body did not move meanwhile, and the push the executor is about to make starts there).
//! When the first way does not show the body the robot tries the other. A round robot that has
//! only turned on the spot since the body was seen has not moved it ([`Since`]): the body's
//! last pose stands, and the robot does not move to look. The simulated robot with the
//! rendered camera (`crate::sim::robot::SimRobot`) and the live one ([`crate::exec::LiveRobot`])
//! both run [`make_sure_of`], so they behave alike.

use nalgebra::Vector2;

use crate::strategy::sample::Pose2;

/// How far the robot backs away from a body it hides before looking again, m: two of the
/// default 5 cm markers with their quiet zones lie clear of each other once their centres are
/// this much further apart.
pub const BACK_OFF: f64 = 0.08;

/// Speed of those moves, m/s: nothing is pushed on them, so the robot goes faster than it
/// pushes (below the firmware's 0.3 m/s limit).
pub const BACK_OFF_SPEED: f64 = 0.25;

/// How near the robot's marker must have been to where a body's marker was last seen for the
/// robot to hide it, m: two 5 cm markers with their quiet zones overlap up to about 9 cm.
pub const HIDING_REACH: f64 = 0.1;

/// Frames the camera is given to show a body after the robot moved to look for it: the
/// robot and the body stand still, so a body still unseen then is not shown from there.
pub const LOOK_AGAIN_FRAMES: usize = 3;

/// What the robot did since each body was last seen. A round robot that only turned on the
/// spot cannot have moved a body it now hides (its bumper turns in place and presses on
/// nothing), so that body is where it was last seen, and the robot need not move to look.
/// A robot with a front plate sweeps the plate's corners as it turns: for it every motion
/// counts.
#[derive(Debug, Clone, Default)]
pub struct Since {
    round: bool,
    translations: u64,
    /// Per body: the motions counted when it was last seen, and where the robot was then.
    seen_at: std::collections::HashMap<String, (u64, Option<Pose2>)>,
}

impl Since {
    /// For a robot that is `round` (no front plate) or not.
    pub fn new(round: bool) -> Since {
        Since {
            round,
            ..Since::default()
        }
    }

    /// The robot is about to run a motion; `turn_in_place` when it only turns on the spot.
    pub fn motion(&mut self, turn_in_place: bool) {
        if !(turn_in_place && self.round) {
            self.translations += 1;
        }
    }

    /// `body` was seen now, with the robot at `robot`.
    pub fn seen(&mut self, body: &str, robot: Option<Pose2>) {
        self.seen_at
            .insert(body.to_owned(), (self.translations, robot));
    }

    /// Whether the robot has only turned on the spot since `body` was last seen.
    pub fn only_turned(&self, body: &str) -> bool {
        self.seen_at
            .get(body)
            .is_some_and(|(n, _)| *n == self.translations)
    }

    /// Where the robot was when `body` was last seen.
    pub fn robot_when_seen(&self, body: &str) -> Option<Pose2> {
        self.seen_at.get(body).and_then(|(_, r)| *r)
    }
}

/// What a robot keeps of the look-again rule: what it did since each body was seen, how
/// often it moved to look, and the body it lost (every motion after fails with it).
#[derive(Debug, Clone, Default)]
pub struct Sight {
    /// Where the robot's marker sits on the robot (robot frame, m): the moves to look again
    /// take the marker, not the robot's middle, away from a hidden body.
    pub marker: Vector2<f64>,
    /// What the robot did since each body was last seen.
    pub since: Since,
    /// Bodies seen again after the robot moved away from them.
    pub relooks: usize,
    /// The body the camera lost, once it has.
    pub lost: Option<BodyLost>,
}

impl Sight {
    /// For a robot that is `round` (no front plate) or not ([`Since::new`]), with its marker
    /// at `marker` (robot frame).
    pub fn new(round: bool, marker: [f64; 2]) -> Sight {
        Sight {
            marker: Vector2::new(marker[0], marker[1]),
            since: Since::new(round),
            ..Sight::default()
        }
    }

    /// Fold in how [`make_sure_of`] ended.
    pub fn record(&mut self, sure: Sure) {
        match sure {
            Sure::Seen | Sure::Kept => {}
            Sure::SeenAgain => self.relooks += 1,
            Sure::Lost(l) => self.lost = Some(l),
        }
    }
}

/// Whether the robot, last seen at `robot`, may itself hide `body`, last seen at `at`: then
/// waiting for the body is no use and the robot moves at once. The robot never hides itself;
/// a body never seen, or a robot never seen, is waited for first.
pub fn robot_may_hide(body: &str, robot: Option<Pose2>, at: Option<Vector2<f64>>) -> bool {
    match (robot, at) {
        (Some(r), Some(a)) => body != "robot" && (a - r.position()).norm() < HIDING_REACH,
        _ => false,
    }
}

/// The two straight moves to try, in order (signed, along the robot's heading at `robot`;
/// negative is backwards): first the one that takes the robot's marker (at `marker`, robot
/// frame) further from where the hidden body may be (`near`: where it was last seen, and
/// where it is if the robot pushed it along since), then the other. Backwards first when
/// both are alike or the body was never seen.
pub fn back_offs(robot: Pose2, marker: Vector2<f64>, near: &[Vector2<f64>]) -> [f64; 2] {
    let clearance = |d: f64| {
        let m = robot.point_to_world(marker + Vector2::new(d, 0.0));
        near.iter()
            .map(|b| (b - m).norm())
            .fold(f64::INFINITY, f64::min)
    };
    if clearance(-BACK_OFF) >= clearance(BACK_OFF) - 1e-3 {
        [-BACK_OFF, BACK_OFF]
    } else {
        [BACK_OFF, -BACK_OFF]
    }
}

/// What [`make_sure_of`] needs of a robot seen by a camera: the in-process one with the
/// rendered camera and the live one each say how they look, wait and move.
pub trait Looking {
    /// The latest pose of `body` the camera gave, seen in the latest look or before.
    fn last_seen(&self, body: &str) -> Option<Pose2>;
    /// Whether the camera has seen `body` since the latest look began.
    fn seen_since_look(&self, body: &str) -> bool;
    /// Look once now; the time the look began (what [`Looking::seen_since_look`] counts from).
    fn look(&mut self) -> anyhow::Result<f64>;
    /// Count bodies seen from `t` on as seen in the latest look.
    fn look_from(&mut self, t: f64);
    /// With the robot still, wait for `body` frame by frame, up to `frames` more frames
    /// (`None`: the robot's own limit); whether it was seen.
    fn wait_for(&mut self, body: &str, frames: Option<usize>) -> anyhow::Result<bool>;
    /// The robot's look-again state: its marker, what it did since each body was seen.
    fn sight(&mut self) -> &mut Sight;
    /// Drive `d` m straight along the robot's heading (negative: backwards), nothing pushed.
    fn straight(&mut self, d: f64) -> anyhow::Result<()>;
}

/// How [`make_sure_of`] ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Sure {
    /// Seen in the latest look, or after waiting.
    Seen,
    /// Seen after the robot moved away; the robot stands where it stood before.
    SeenAgain,
    /// Hidden by a robot that only turned on the spot since the body was last seen: the
    /// body's last seen pose stands.
    Kept,
    /// Not seen either way, or the robot not seen after it came back.
    Lost(BodyLost),
}

/// Make sure of `body` after a look: wait for it (unless [`robot_may_hide`] it); hidden by a
/// robot that has only turned on the spot since, keep its last pose ([`Since`]); unseen, move
/// away from it ([`back_offs`]), look, and come back to where the robot stood, one way and
/// then the other. Every pose the robot reports afterwards is from after these moves. An
/// error is the camera's or a motion's, and ends the task.
pub fn make_sure_of(robot: &mut impl Looking, body: &str) -> anyhow::Result<Sure> {
    let sure = look_for(robot, body)?;
    if matches!(sure, Sure::Seen | Sure::SeenAgain) {
        let at = robot.last_seen("robot");
        robot.sight().since.seen(body, at);
    }
    Ok(sure)
}

fn look_for(robot: &mut impl Looking, body: &str) -> anyhow::Result<Sure> {
    if robot.seen_since_look(body) {
        return Ok(Sure::Seen);
    }
    let stood = robot.last_seen("robot");
    let body_at = robot.last_seen(body).map(|p| p.position());
    let hides = robot_may_hide(body, stood, body_at);
    if hides && robot.sight().since.only_turned(body) {
        return Ok(Sure::Kept);
    }
    // A body the robot hides does not come back by waiting.
    if !hides && robot.wait_for(body, None)? {
        return Ok(Sure::Seen);
    }
    let lost = |body: &str| {
        tracing::warn!("{body} lost");
        Ok(Sure::Lost(BodyLost {
            body: body.to_owned(),
        }))
    };
    // A robot never seen cannot be moved with any sense.
    let Some(stood) = stood else {
        return lost(body);
    };
    // Where the body may be: where it was seen, or carried along by the robot since.
    let mut near: Vec<Vector2<f64>> = body_at.into_iter().collect();
    if let (Some(b), Some(was)) = (body_at, robot.sight().since.robot_when_seen(body)) {
        // (A push carries it a few cm; a longer way was driven round it, not through it.)
        let moved = stood.position() - was.position();
        if moved.norm() <= HIDING_REACH {
            near.push(b + moved);
        }
    }
    let marker = robot.sight().marker;
    for d in back_offs(stood, marker, &near) {
        tracing::info!(
            "{body} not seen (last seen {}): the robot moves {d:+.2} m and looks again",
            body_at.map_or("never".into(), |b| {
                let rel = stood.point_to_local(b);
                format!("at ({:+.3}, {:+.3}) m in the robot's frame", rel.x, rel.y)
            })
        );
        robot.straight(d)?;
        let away = robot.look()?;
        let seen = robot.wait_for(body, Some(LOOK_AGAIN_FRAMES))?;
        // Come back to where the robot stood (against the object, ready to push): the body
        // did not move while the robot moved away from it.
        robot.straight(-d)?;
        robot.look()?;
        if !robot.wait_for("robot", None)? {
            // Its pose would be from before it came back.
            return lost("robot");
        }
        if seen {
            robot.look_from(away);
            return Ok(Sure::SeenAgain);
        }
    }
    lost(body)
}

/// A body the camera lost: not seen after the robot stopped (waited for, unless the robot may
/// hide it), nor after the robot moved [`BACK_OFF`] away from it either way. Every primitive
/// after it fails with this error, and an evaluation counts the trial as failed
/// ([`crate::exec::deliver::Failure::MarkerLost`]) instead of stopping.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{body} is lost: the camera has not seen its marker since the robot stopped, nor after the \
     robot moved {BACK_OFF} m away from it either way (occluded, out of view, or the marker is \
     gone)"
)]
pub struct BodyLost {
    /// The body's name (`robot`, an object's id).
    pub body: String,
}

/// Whether `e` (or anything it was caused by) is a lost body.
pub fn is_lost(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<BodyLost>())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_robot_takes_its_marker_away_from_where_the_body_may_be() {
        let robot = Pose2::new(0.5, 0.5, std::f64::consts::FRAC_PI_2);
        let middle = Vector2::zeros();
        let away = |body: Vector2<f64>, d: f64| {
            let after = robot.position() + d * Vector2::new(0.0, 1.0);
            (after - body).norm() - (robot.position() - body).norm()
        };
        // Ahead (the robot faces +y), beside, behind: the first move takes it further away.
        for (body, first) in [
            (Vector2::new(0.53, 0.56), -BACK_OFF),
            (Vector2::new(0.56, 0.5), -BACK_OFF),
            (Vector2::new(0.47, 0.44), BACK_OFF),
        ] {
            let moves = back_offs(robot, middle, &[body]);
            assert_eq!(moves, [first, -first], "{body:?}");
            assert!(away(body, moves[0]) > 0.015, "{body:?}");
        }
        // Never seen: backwards first.
        assert_eq!(back_offs(robot, middle, &[]), [-BACK_OFF, BACK_OFF]);
        // Beside and a little behind the middle: forwards, unless the marker sits at the
        // robot's rear, which backing away takes further from the body.
        let beside = Vector2::new(0.55, 0.48);
        assert_eq!(back_offs(robot, middle, &[beside])[0], BACK_OFF);
        let rear = Vector2::new(-0.03, 0.0);
        assert_eq!(back_offs(robot, rear, &[beside])[0], -BACK_OFF);
        // Seen behind before a push that may have carried it ahead: backwards keeps clear of
        // both.
        let pushed = beside + Vector2::new(0.0, 0.04);
        assert_eq!(back_offs(robot, middle, &[beside, pushed])[0], -BACK_OFF);
    }

    #[test]
    fn only_a_body_last_seen_near_the_robot_may_be_hidden_by_it() {
        let robot = Some(Pose2::new(0.5, 0.5, 0.0));
        assert!(robot_may_hide(
            "object",
            robot,
            Some(Vector2::new(0.55, 0.53))
        ));
        assert!(!robot_may_hide(
            "object",
            robot,
            Some(Vector2::new(0.62, 0.5))
        ));
        assert!(!robot_may_hide(
            "robot",
            robot,
            Some(Vector2::new(0.5, 0.5))
        ));
        assert!(!robot_may_hide("object", robot, None));
        assert!(!robot_may_hide(
            "object",
            None,
            Some(Vector2::new(0.5, 0.5))
        ));
    }

    /// A robot on the x axis facing +x and one body on that axis, with a camera that sees
    /// the body when the robot's marker is more than `hides` from it (from `wait_frames`
    /// frames on), and the robot unless `robot_hidden_after` moves were made.
    struct Line {
        robot: f64,
        body: f64,
        last_body: Option<f64>,
        hides: f64,
        body_never_seen: bool,
        robot_hidden_after: usize,
        wait_frames: usize,
        frames: usize,
        look_from: f64,
        seen_at: [Option<f64>; 2],
        moves: Vec<f64>,
        sight: Sight,
    }

    impl Line {
        fn new(robot: f64, body: f64, last_body: Option<f64>) -> Line {
            Line {
                robot,
                body,
                last_body,
                hides: 0.09,
                body_never_seen: false,
                robot_hidden_after: usize::MAX,
                wait_frames: 0,
                frames: 0,
                look_from: 0.0,
                seen_at: [Some(-1.0), last_body.map(|_| -1.0)],
                moves: Vec::new(),
                sight: Sight::new(true, [0.0, 0.0]),
            }
        }

        fn frame(&mut self) {
            self.frames += 1;
            let t = self.frames as f64;
            if self.moves.len() < self.robot_hidden_after {
                self.seen_at[0] = Some(t);
            }
            let visible = (self.body - self.robot).abs() > self.hides
                && !self.body_never_seen
                && self.frames > self.wait_frames;
            if visible {
                self.seen_at[1] = Some(t);
                self.last_body = Some(self.body);
            }
        }
    }

    impl Looking for Line {
        fn last_seen(&self, body: &str) -> Option<Pose2> {
            match body {
                "robot" => self.seen_at[0].map(|_| Pose2::new(self.robot, 0.0, 0.0)),
                _ => self.last_body.map(|x| Pose2::new(x, 0.0, 0.0)),
            }
        }
        fn seen_since_look(&self, body: &str) -> bool {
            let i = usize::from(body != "robot");
            self.seen_at[i].is_some_and(|t| t >= self.look_from)
        }
        fn look(&mut self) -> anyhow::Result<f64> {
            self.look_from = self.frames as f64 + 1.0;
            self.frame();
            Ok(self.look_from)
        }
        fn look_from(&mut self, t: f64) {
            self.look_from = t;
        }
        fn wait_for(&mut self, body: &str, frames: Option<usize>) -> anyhow::Result<bool> {
            for _ in 0..frames.unwrap_or(5) {
                if self.seen_since_look(body) {
                    return Ok(true);
                }
                self.frame();
            }
            Ok(self.seen_since_look(body))
        }
        fn sight(&mut self) -> &mut Sight {
            &mut self.sight
        }
        fn straight(&mut self, d: f64) -> anyhow::Result<()> {
            self.sight.since.motion(false);
            self.robot += d;
            self.moves.push(d);
            Ok(())
        }
    }

    #[test]
    fn a_body_the_robot_hides_is_looked_for_away_from_it_and_the_robot_comes_back() {
        // Against the object, which is ahead and where it was last seen.
        let mut r = Line::new(0.5, 0.55, Some(0.55));
        r.look().unwrap();
        assert!(!r.seen_since_look("object"));
        assert_eq!(make_sure_of(&mut r, "object").unwrap(), Sure::SeenAgain);
        assert_eq!(r.moves, [-BACK_OFF, BACK_OFF]);
        assert!((r.robot - 0.5).abs() < 1e-12);
        assert!(r.seen_since_look("object") && r.seen_since_look("robot"));

        // The push carried the object past where it was last seen, round behind the robot:
        // backing away keeps it hidden, and the other way shows it.
        let mut r = Line::new(0.5, 0.48, Some(0.55));
        r.look().unwrap();
        assert_eq!(make_sure_of(&mut r, "object").unwrap(), Sure::SeenAgain);
        assert_eq!(r.moves, [-BACK_OFF, BACK_OFF, BACK_OFF, -BACK_OFF]);
        assert!((r.robot - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_body_hidden_by_a_round_robot_that_only_turned_keeps_its_pose() {
        for (round, turned_only, sure) in [
            (true, true, Sure::Kept),
            (true, false, Sure::SeenAgain),
            (false, true, Sure::SeenAgain),
        ] {
            // Seen beside the robot, which then turns on the spot (or drives, or has a front
            // plate) and hides it.
            let mut r = Line::new(0.5, 0.595, Some(0.595));
            r.sight = Sight::new(round, [0.0, 0.0]);
            r.look().unwrap();
            assert_eq!(make_sure_of(&mut r, "object").unwrap(), Sure::Seen);
            // (Turned, the robot's marker covers the body's.)
            r.hides = 0.1;
            r.sight.since.motion(turned_only);
            r.look().unwrap();
            assert_eq!(
                make_sure_of(&mut r, "object").unwrap(),
                sure,
                "{round} {turned_only}"
            );
            assert_eq!(r.moves.is_empty(), sure == Sure::Kept);
            // Once seen again, a turn keeps it; a move does not.
            if sure == Sure::SeenAgain && round {
                r.sight.since.motion(true);
                r.look().unwrap();
                assert_eq!(make_sure_of(&mut r, "object").unwrap(), Sure::Kept);
            }
        }
    }

    #[test]
    fn a_body_away_from_the_robot_is_waited_for_without_moving() {
        let mut r = Line::new(0.5, 0.8, Some(0.8));
        r.wait_frames = 3;
        r.look().unwrap();
        assert_eq!(make_sure_of(&mut r, "object").unwrap(), Sure::Seen);
        assert!(r.moves.is_empty());
    }

    #[test]
    fn a_body_seen_neither_way_is_lost_and_so_is_a_robot_not_seen_after_coming_back() {
        let mut r = Line::new(0.5, 0.55, Some(0.55));
        r.body_never_seen = true;
        r.look().unwrap();
        assert_eq!(
            make_sure_of(&mut r, "object").unwrap(),
            Sure::Lost(BodyLost {
                body: "object".into()
            })
        );
        assert_eq!(r.moves.len(), 4);
        assert!((r.robot - 0.5).abs() < 1e-12);

        let mut r = Line::new(0.5, 0.55, Some(0.55));
        r.robot_hidden_after = 1;
        r.look().unwrap();
        assert_eq!(
            make_sure_of(&mut r, "object").unwrap(),
            Sure::Lost(BodyLost {
                body: "robot".into()
            })
        );
        // A robot never seen is not moved.
        let mut r = Line::new(0.5, 0.55, Some(0.55));
        (r.robot_hidden_after, r.seen_at[0]) = (0, None);
        r.look().unwrap();
        assert!(matches!(
            make_sure_of(&mut r, "object").unwrap(),
            Sure::Lost(_)
        ));
        assert!(r.moves.is_empty());
    }

    #[test]
    fn a_lost_body_is_found_behind_the_context_it_is_wrapped_in() {
        let lost = BodyLost {
            body: "object".into(),
        };
        let e = anyhow::Error::new(lost.clone()).context("Move did not end");
        assert!(is_lost(&e));
        assert!(e.chain().any(|c| c.to_string().contains("object is lost")));
        assert!(!is_lost(&anyhow::anyhow!("object is lost, says a string")));
    }
}
