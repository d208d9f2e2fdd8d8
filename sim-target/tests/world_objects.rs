//! The robot pushing objects in the world: quasi-static pushing, walls and obstacles stop
//! objects and then the robot, nothing ever interpenetrates.

use pushbot_sim::pushing::{Slider, SupportShape, friction_centre};
use pushbot_sim::robot::switch;
use pushbot_sim::scene::placed;
use pushbot_sim::world::polygons_overlap;
use pushbot_sim::{Body, Hardware, Pose, Scene, World};

const DT: f64 = 1e-3;

fn exact() -> Hardware {
    Hardware {
        motor_gain_spread: 0.0,
        slip_noise: 0.0,
        encoder_jitter: 0.0,
        bounce_us: 0,
        ..Hardware::default()
    }
}

fn body() -> Body {
    pushbot_sim::world::body_from_geometry(&pushbot_firmware::RobotParams::default().geometry)
}

fn box_at(x: f64, y: f64, side: f64) -> Slider {
    let h = side / 2.0;
    let outline = vec![[-h, -h], [h, -h], [h, h], [-h, h]];
    let (cof, c) = friction_centre(&SupportShape::Uniform(&outline));
    Slider {
        outline,
        cof,
        c,
        mu: 0.5,
        pose: Pose::new(x, y, 0.0),
    }
}

/// The robot's bumper and every object stay apart, and objects stay on the table.
fn assert_no_overlap(w: &World) {
    let p = w.pose();
    let r = w.body().bumper_radius;
    let (tw, th) = w.table();
    for (id, s) in w.objects() {
        assert!(
            s.gap([p.x, p.y], r) >= -1e-9,
            "robot inside {id}: {}",
            s.gap([p.x, p.y], r)
        );
        for v in placed(&s.outline, &s.pose) {
            assert!(
                v[0] >= 0.0 && v[0] <= tw && v[1] >= 0.0 && v[1] <= th,
                "{id} off the table"
            );
        }
        for o in w.obstacles() {
            assert!(
                !polygons_overlap(o, &placed(&s.outline, &s.pose)),
                "{id} in an obstacle"
            );
        }
    }
}

#[test]
fn pushing_through_the_centre_translates_the_box() {
    let mut w = World::new((1.2, 0.9), Pose::new(0.2, 0.45, 0.0), body(), exact(), 1).unwrap();
    w.add_object("box", box_at(0.35, 0.45, 0.08)).unwrap();
    let mut pushed = false;
    for _ in 0..2000 {
        w.step([0.3, 0.3], DT);
        assert_no_overlap(&w);
        if w.objects()[0].1.pose.x > 0.3501 {
            pushed = true;
            assert_eq!(w.pressed(), switch::CENTRE);
        }
    }
    assert!(pushed);
    let s = &w.objects()[0].1;
    assert!(s.pose.x > 0.5, "pushed along: {:?}", s.pose);
    assert!(
        s.pose.theta.abs() < 1e-9 && (s.pose.y - 0.45).abs() < 1e-9,
        "{:?}",
        s.pose
    );
    // The box stays just ahead of the bumper.
    let gap = s.gap([w.pose().x, w.pose().y], w.body().bumper_radius);
    assert!(gap.abs() < 1e-3, "gap {gap}");
}

/// Mason's rule for a push along +x below the COF: the box turns counter-clockwise.
#[test]
fn off_centre_push_turns_the_box() {
    let mut w = World::new((1.2, 0.9), Pose::new(0.2, 0.45, 0.0), body(), exact(), 1).unwrap();
    w.add_object("box", box_at(0.35, 0.475, 0.08)).unwrap();
    for _ in 0..1500 {
        w.step([0.3, 0.3], DT);
        assert_no_overlap(&w);
    }
    let s = &w.objects()[0].1;
    assert!(
        s.pose.theta > 0.05,
        "turned counter-clockwise: {:?}",
        s.pose
    );
}

/// A box pushed into a wall stops at the wall; the robot then stalls behind it.
#[test]
fn box_against_a_wall_stops_the_robot() {
    let mut w = World::new((1.2, 0.9), Pose::new(0.9, 0.45, 0.0), body(), exact(), 1).unwrap();
    w.add_object("box", box_at(1.05, 0.45, 0.08)).unwrap();
    for _ in 0..4000 {
        w.step([0.5, 0.5], DT);
        assert_no_overlap(&w);
    }
    let s = &w.objects()[0].1;
    let right = placed(&s.outline, &s.pose)
        .iter()
        .map(|v| v[0])
        .fold(f64::MIN, f64::max);
    assert!(
        right <= 1.2 && right > 1.2 - 0.002,
        "box at the wall: {right}"
    );
    let speeds = w.wheel_speeds();
    assert!(
        speeds[0].abs() < 1e-6 && speeds[1].abs() < 1e-6,
        "stalled: {speeds:?}"
    );
    assert_eq!(w.pressed(), switch::CENTRE);
}

/// An object nobody touches never moves; an obstacle stops the robot and closes the bumper.
#[test]
fn untouched_objects_stay_and_obstacles_block() {
    let mut w = World::new((1.2, 0.9), Pose::new(0.2, 0.3, 0.0), body(), exact(), 1).unwrap();
    w.add_object("aside", box_at(0.5, 0.5, 0.08)).unwrap();
    w.add_obstacle(vec![[0.8, 0.0], [0.9, 0.0], [0.9, 0.6], [0.8, 0.6]])
        .unwrap();
    let before = w.objects()[0].1.pose;
    for _ in 0..5000 {
        w.step([0.5, 0.5], DT);
        assert_no_overlap(&w);
        assert!(
            w.pose().x <= 0.8 - w.body().bumper_radius + 1e-9,
            "robot in the obstacle"
        );
    }
    assert_eq!(w.objects()[0].1.pose, before);
    assert!((w.pose().x - (0.8 - w.body().bumper_radius)).abs() < 1e-6);
    assert_eq!(w.pressed(), switch::CENTRE);
}

/// Every preset builds a world (objects placed legally) and survives a random drive.
#[test]
fn presets_build_worlds() {
    for name in pushbot_sim::scene::PRESETS {
        let scene = Scene::preset(name).unwrap();
        let mut w = World::from_scene(&scene, body(), Hardware::default(), 3)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        for k in 0..3000 {
            let d = if k < 1500 { [0.6, 0.55] } else { [0.5, -0.2] };
            w.step(d, DT);
        }
        assert_no_overlap(&w);
    }
}

/// Two boxes in a line: the robot pushes A, A pushes B, and they move on together, without
/// overlapping, until B reaches the wall; then everything stops.
#[test]
fn two_boxes_pushed_in_a_line_move_together() {
    let mut w = World::new((1.2, 0.9), Pose::new(0.2, 0.45, 0.0), body(), exact(), 1).unwrap();
    w.add_object("a", box_at(0.35, 0.45, 0.08)).unwrap();
    w.add_object("b", box_at(0.5, 0.45, 0.08)).unwrap();
    let b0 = w.objects()[1].1.pose;
    for _ in 0..2500 {
        w.step([0.3, 0.3], DT);
        assert_no_overlap(&w);
        let (a, b) = (&w.objects()[0].1, &w.objects()[1].1);
        let pa = placed(&a.outline, &a.pose);
        // Touching is fine; crossing by more than rounding is not.
        let depth = pa
            .iter()
            .filter(|v| pushbot_sim::pushing::point_in_polygon(b.to_local(**v), &b.outline))
            .map(|v| pushbot_sim::pushing::closest_boundary_point(b.to_local(*v), &b.outline).1)
            .fold(0.0, f64::max);
        assert!(depth < 1e-6, "a inside b by {depth}");
    }
    let (a, b) = (w.objects()[0].1.pose, w.objects()[1].1.pose);
    assert!(b.x > b0.x + 0.1, "b was pushed along: {b:?}");
    assert!((b.x - a.x - 0.08).abs() < 2e-3, "together: {a:?} {b:?}");
    assert!(a.theta.abs() < 1e-6 && b.theta.abs() < 1e-6 && (b.y - 0.45).abs() < 1e-6);
    // Into the wall: B stops at it, A behind B, the robot stalls.
    for _ in 0..4000 {
        w.step([0.5, 0.5], DT);
        assert_no_overlap(&w);
    }
    let b = &w.objects()[1].1;
    let right = placed(&b.outline, &b.pose)
        .iter()
        .map(|v| v[0])
        .fold(f64::MIN, f64::max);
    assert!(right <= 1.2 && right > 1.19, "b at the wall: {right}");
    let s = w.wheel_speeds();
    assert!(s[0].abs() < 1e-6 && s[1].abs() < 1e-6, "stalled: {s:?}");
}
