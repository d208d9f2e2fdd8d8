//! A camera as it really is, with the robot moving: the simulator's camera renders a
//! scene frame by frame while the robot follows a scripted motion — a camera tilted 35°, the
//! robot spinning in place at 180°/s, driving fast with its marker smeared over a 1/30 s
//! exposure, a hand over the table — and the whole pipeline (detector, calibration through the
//! lens, tracker) measures it. Each pose the tracker gives is held against the truth of the
//! moment the frame shows; a body it cannot place must be reported lost, never misplaced.
#![cfg(feature = "sim")]

use pushbot::vision::Pipeline;
use pushbot::vision::apriltag::{AprilTagC, AprilTagCConfig};
use pushbot::vision::calibration::Calibration;
use pushbot::vision::detect::Detector;
use pushbot::vision::frame::Frame;
use pushbot::vision::layout::MarkerLayout;
use pushbot::vision::tracking::TrackerParams;
use pushbot_sim::camera::SceneCamera;
use pushbot_world::camera_pose::CameraPlacement;
use pushbot_world::lens::{Distortion, Intrinsics};
use pushbot_world::scene::Occluder;
use pushbot_world::{Pose, Scene, wrap_angle};

fn webcam() -> Intrinsics {
    Intrinsics {
        distortion: Distortion {
            k1: -0.08,
            ..Distortion::NONE
        },
        ..Intrinsics::pinhole(960, 720, 700.0)
    }
}

/// The Lau et al. table with its irregular object, markers at their heights (robot 6 cm,
/// object 3 cm), seen through the webcam lens.
fn scene() -> Scene {
    let mut s = Scene::preset("lau-irregular").expect("preset");
    s.camera.robot_marker.z = 0.06;
    for o in &mut s.objects {
        if let Some(m) = o.marker.as_mut() {
            m.z = 0.03;
        }
    }
    s.camera.lens = Some(webcam());
    s
}

/// What the tracker made of a run.
#[derive(Debug, Default)]
struct Score {
    frames: usize,
    posed: usize,
    lost: usize,
    worst_mm: f64,
    worst_deg: f64,
    errors_mm: Vec<f64>,
    objects_posed: usize,
    objects_unposed: usize,
    objects_worst_mm: f64,
}

/// Render `n` frames at 30 fps of `scene` with the robot where `motion(t)` puts it (pose,
/// twist), calibrate from five still frames first, and score the robot's (and, with
/// `objects`, the objects') tracked poses against the truth.
fn run(scene: &Scene, n: usize, motion: impl Fn(f64) -> (Pose, [f64; 2])) -> Score {
    run_with(scene, n, motion, false)
}

/// As [`run`]; with `odometry`, the tracker also gets the robot's wheel odometry at 100 Hz
/// (its own frame, from where it started, every distance 2 % long as a worn wheel makes it).
fn run_with(
    scene: &Scene,
    n: usize,
    motion: impl Fn(f64) -> (Pose, [f64; 2]),
    odometry: bool,
) -> Score {
    let layout = MarkerLayout::from_scene(scene);
    let mut cam = SceneCamera::new(scene.clone(), 7).expect("camera");
    let lens = scene.camera.optics();
    let frame = |f: pushbot_sim::camera::CameraFrame| Frame {
        seq: f.seq,
        time: f.time,
        width: f.width,
        height: f.height,
        pixels: f.pixels,
    };
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let (start, _) = motion(0.0);
    if let Ok(dir) = std::env::var("PUSHBOT_DUMP_FRAME") {
        let f = cam.capture(-2.0, &start, &[]).unwrap();
        f.write_png(std::path::Path::new(&dir)).unwrap();
    }
    let still: Vec<_> = (0..5)
        .map(|k| {
            let f = frame(cam.capture(-1.0 + k as f64 * 0.1, &start, &[]).unwrap());
            det.detect_fine(&f).unwrap()
        })
        .collect();
    let cal =
        Calibration::fit_through(&still, &layout, [960, 720], lens.as_ref()).expect("calibrates");
    let detector =
        Box::new(AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap());
    let mut p = Pipeline::new(detector, layout, cal, TrackerParams::default());
    let mut score = Score::default();
    for k in 0..n {
        let t = k as f64 / 30.0;
        let (pose, twist) = motion(t);
        if odometry {
            let start = motion(0.0).0;
            for j in 0..4 {
                let ts = t - 0.03 + 0.01 * j as f64;
                let rel = start.inverse().compose(&motion(ts.max(0.0)).0);
                p.odometry(
                    "robot",
                    ts,
                    Pose::new(1.02 * rel.x, 1.02 * rel.y, rel.theta),
                );
            }
        }
        let f = frame(cam.capture_moving(t, &pose, twist, &[]).unwrap());
        let r = p.process(&f).expect("a frame of the calibration's size");
        score.frames += 1;
        // The objects stand still where the scene puts them.
        for o in &scene.objects {
            if o.marker.is_none() {
                continue;
            }
            match r.tracked.iter().find(|b| b.body == o.id && !b.lost) {
                Some(b) => {
                    let e = (b.pose.x - o.pose.x).hypot(b.pose.y - o.pose.y) * 1e3;
                    score.objects_posed += 1;
                    score.objects_worst_mm = score.objects_worst_mm.max(e);
                }
                None => score.objects_unposed += 1,
            }
        }
        let Some(robot) = r.tracked.iter().find(|b| b.body == "robot") else {
            score.lost += 1;
            continue;
        };
        if robot.lost {
            score.lost += 1;
            continue;
        }
        score.posed += 1;
        let e = (robot.pose.x - pose.x).hypot(robot.pose.y - pose.y) * 1e3;
        let d = wrap_angle(robot.pose.theta - pose.theta).abs().to_degrees();
        if std::env::var("PUSHBOT_DEBUG").is_ok() {
            eprintln!(
                "t {t:.3} v {:.3} err {e:.2} mm seen {} rejected {} age {:.3} sigma {:.4} meas {:?}",
                twist[0],
                robot.seen,
                robot.rejected,
                robot.age,
                robot.sigma_m,
                r.measurements.iter().find(|m| m.body == "robot").map(|m| (
                    (m.body_pose.x - pose.x) * 1e3,
                    (m.body_pose.y - pose.y) * 1e3
                ))
            );
        }
        score.worst_mm = score.worst_mm.max(e);
        score.worst_deg = score.worst_deg.max(d);
        score.errors_mm.push(e);
    }
    eprintln!(
        "{} frames: robot posed in {}, lost in {}; worst {:.2} mm, {:.2}°; objects posed {} \
         times, not {} times, worst {:.2} mm",
        score.frames,
        score.posed,
        score.lost,
        score.worst_mm,
        score.worst_deg,
        score.objects_posed,
        score.objects_unposed,
        score.objects_worst_mm
    );
    score
}

/// A robot driving a slow circle about the table's centre.
fn circling(t: f64) -> (Pose, [f64; 2]) {
    let (r, w) = (0.3, 0.4);
    let a = w * t;
    (
        Pose::new(
            0.8 + r * a.cos(),
            0.6 + r * a.sin(),
            wrap_angle(a + std::f64::consts::FRAC_PI_2),
        ),
        [r * w, w],
    )
}

/// A camera standing back from the table's near edge and tilted 35° from straight down, the
/// markers at their heights: the calibration finds the camera's place through the lens and
/// every frame poses the robot within 20 mm.
#[test]
fn a_camera_tilted_35_degrees_poses_every_body() {
    let mut s = scene();
    let (cx, cy) = (s.table.width / 2.0, s.table.height / 2.0);
    let tilt = 35f64.to_radians();
    let dist = 1.35;
    // Far markers are seen small and foreshortened: calibration markers of 8 cm, as a user
    // with a tilted camera prints them.
    let mut fid = s.camera.fiducials_on(s.table.width, s.table.height);
    for m in &mut fid {
        m.size = 0.08;
    }
    s.camera.fiducials = Some(fid);
    s.camera.pose = Some(CameraPlacement {
        eye: [cx, cy - dist * tilt.sin(), dist * tilt.cos()],
        look_at: [cx, cy, 0.0],
    });
    let score = run(&s, 60, circling);
    assert!(
        score.posed as f64 >= 0.9 * score.frames as f64,
        "posed in {} of {} frames",
        score.posed,
        score.frames
    );
    assert!(score.worst_mm <= 20.0, "{score:?}");
    assert!(
        score.objects_posed as f64 >= 0.9 * (score.objects_posed + score.objects_unposed) as f64
            && score.objects_posed > 0,
        "{score:?}"
    );
    assert!(score.objects_worst_mm <= 20.0, "{score:?}");
}

/// The robot turning in place at 180°/s, its marker seen in every frame (an instant
/// exposure): every frame poses it within 2 mm and 2° — the tracker follows the marker it
/// sees rather than its own prediction.
#[test]
fn a_robot_spinning_at_180_degrees_a_second_is_followed_in_every_frame() {
    let s = scene();
    let w = std::f64::consts::PI;
    let score = run(&s, 90, |t| {
        // Still for a second, then spinning up in 0.1 s (31 rad/s², a small robot's) and on.
        let (ramp, s) = (0.1, (t - 1.0).max(0.0));
        let rate = w * (s / ramp).min(1.0);
        let a = if s < ramp {
            0.5 * w / ramp * s * s
        } else {
            0.5 * w * ramp + w * (s - ramp)
        };
        (Pose::new(0.8, 0.6, wrap_angle(0.3 + a)), [0.0, rate])
    });
    assert_eq!(score.posed, score.frames, "{score:?}");
    assert!(score.worst_mm <= 2.0, "{score:?}");
    assert!(score.worst_deg <= 2.0, "{score:?}");
}

/// The robot driving fast (up to 0.6 m/s, 3 m/s²) with the shutter open a whole frame
/// (1/30 s): its marker smears up to 2 cm. From the frames alone, every pose the tracker gives is within 20 mm; where it
/// cannot place the robot it says lost.
#[test]
fn a_smeared_marker_is_never_misplaced() {
    let mut s = scene();
    s.camera.exposure = 1.0 / 30.0;
    let score = run(&s, 90, |t| {
        // Still for half a second, then back and forth across the table's middle, up to
        // 0.6 m/s and 3 m/s² (x = 0.8 − A cos ωt, Aω = 0.6 m/s, Aω² = 3 m/s²).
        let (w, amp) = (5.0, 0.12);
        let s = (t - 0.5).max(0.0);
        (
            Pose::new(0.8 - amp * (w * s).cos(), 0.6, 0.0),
            [amp * w * (w * s).sin(), 0.0],
        )
    });
    assert!(score.worst_mm <= 20.0, "{score:?}");
    assert!(score.posed >= 15, "seen while still: {score:?}");
}

/// A hand over the table hides the robot's marker for a second: no pose is misplaced — the
/// robot is lost while hidden — and it is found again after.
#[test]
fn an_occluded_marker_is_lost_not_misplaced() {
    let mut s = scene();
    s.camera.occluders = vec![Occluder {
        outline: vec![[0.55, 0.45], [0.9, 0.45], [0.9, 0.75], [0.55, 0.75]],
        z: 0.3,
        from: 0.5,
        until: 1.5,
    }];
    let score = run(&s, 75, |t| {
        let x = 0.5 + 0.1 * t;
        (Pose::new(x, 0.6, 0.0), [0.1, 0.0])
    });
    assert!(score.worst_mm <= 20.0, "{score:?}");
    assert!(score.lost >= 10, "hidden for a second: {score:?}");
    assert!(score.posed >= 30, "{score:?}");
}

/// A robot driving fast (0.6 m/s, its marker smeared) or spinning at 360°/s, with its wheel
/// odometry as the tracker's control input: a pose in at least 95 % of frames, none more than
/// 20 mm off.
#[test]
fn with_odometry_a_fast_robot_is_posed_in_nearly_every_frame() {
    let mut s = scene();
    s.camera.exposure = 1.0 / 30.0;
    let (w, amp) = (5.0, 0.12);
    let drive = run_with(
        &s,
        120,
        |t| {
            let s = (t - 0.5).max(0.0);
            (
                Pose::new(0.8 - amp * (w * s).cos(), 0.6, 0.0),
                [amp * w * (w * s).sin(), 0.0],
            )
        },
        true,
    );
    let spin_rate = std::f64::consts::TAU;
    let spin = run_with(
        &s,
        120,
        |t| {
            let (ramp, s) = (0.2, (t - 0.5).max(0.0));
            let rate = spin_rate * (s / ramp).min(1.0);
            let a = if s < ramp {
                0.5 * spin_rate / ramp * s * s
            } else {
                0.5 * spin_rate * ramp + spin_rate * (s - ramp)
            };
            (Pose::new(0.8, 0.6, wrap_angle(0.3 + a)), [0.0, rate])
        },
        true,
    );
    for score in [&drive, &spin] {
        assert!(
            score.posed as f64 >= 0.95 * score.frames as f64,
            "posed in {} of {} frames",
            score.posed,
            score.frames
        );
        assert!(score.worst_mm <= 20.0, "{score:?}");
    }
}
