//! The flat front plate: line contact with pushed objects (Lynch & Mason's stable pushing),
//! switches by where the plate is pressed, walls and obstacles stop it.

use pushbot_sim::pushing::{Slider, SupportShape, friction_centre};
use pushbot_sim::robot::switch;
use pushbot_sim::scene::placed;
use pushbot_sim::world::FrontPlate;
use pushbot_sim::{Body, Hardware, Pose, Scene, World};

const DT: f64 = 1e-3;
const PLATE: FrontPlate = FrontPlate {
    width: 0.12,
    offset: 0.06,
};

fn exact() -> Hardware {
    Hardware {
        motor_gain_spread: 0.0,
        slip_noise: 0.0,
        encoder_jitter: 0.0,
        bounce_us: 0,
        ..Hardware::default()
    }
}

fn plated() -> Body {
    Body {
        front_plate: Some(PLATE),
        ..pushbot_sim::world::body_from_geometry(&pushbot_firmware::RobotParams::default().geometry)
    }
}

fn box_at(x: f64, y: f64, side: f64, mu: f64) -> Slider {
    let h = side / 2.0;
    let outline = vec![[-h, -h], [h, -h], [h, h], [-h, h]];
    let (cof, c) = friction_centre(&SupportShape::Uniform(&outline));
    Slider {
        outline,
        cof,
        c,
        mu,
        pose: Pose::new(x, y, 0.0),
    }
}

/// The box's left face: x of its leftmost vertices, and how far the plate's face is from it.
fn face_gap(w: &World) -> f64 {
    let s = &w.objects()[0].1;
    let left = placed(&s.outline, &s.pose)
        .iter()
        .map(|v| v[0])
        .fold(f64::MAX, f64::min);
    left - (w.pose().x + PLATE.offset)
}

/// A square pushed squarely by the plate translates without rotating and stays flush against
/// it; with a point (round) bumper the same push off the box's centre line turns the box, with
/// the plate's line contact it does not (the COF's line of pushing falls inside the contact).
#[test]
fn square_pushed_squarely_by_the_plate_translates_flush() {
    for (dy, name) in [(0.0, "centred"), (0.02, "off-centre")] {
        let mut w =
            World::new((1.2, 0.9), Pose::new(0.2, 0.45, 0.0), plated(), exact(), 1).unwrap();
        w.add_object("box", box_at(0.33, 0.45 + dy, 0.08, 0.5))
            .unwrap();
        let mut touched = false;
        for _ in 0..2500 {
            w.step([0.3, 0.3], DT);
            assert!(
                w.max_penetration() < 1e-9,
                "{name}: {}",
                w.max_penetration()
            );
            if w.objects()[0].1.pose.x > 0.3301 {
                touched = true;
                assert!(
                    face_gap(&w).abs() < 2e-6,
                    "{name}: flush, gap {}",
                    face_gap(&w)
                );
                assert_ne!(
                    w.pressed() & switch::CENTRE,
                    0,
                    "{name}: {:03b}",
                    w.pressed()
                );
            }
        }
        assert!(touched, "{name}");
        let s = &w.objects()[0].1;
        assert!(s.pose.x > 0.5, "{name}: pushed along: {:?}", s.pose);
        assert!(s.pose.theta.abs() < 1e-7, "{name}: turned {}", s.pose.theta);
        assert!((s.pose.y - 0.45 - dy).abs() < 1e-7, "{name}: {:?}", s.pose);
        assert!(w.pose().theta.abs() < 1e-7);
    }
    // The same off-centre push with the round bumper turns the box (so the test can fail).
    let round =
        pushbot_sim::world::body_from_geometry(&pushbot_firmware::RobotParams::default().geometry);
    let mut w = World::new((1.2, 0.9), Pose::new(0.2, 0.45, 0.0), round, exact(), 1).unwrap();
    w.add_object("box", box_at(0.31, 0.47, 0.08, 0.5)).unwrap();
    for _ in 0..2500 {
        w.step([0.3, 0.3], DT);
    }
    assert!(
        w.objects()[0].1.pose.theta > 0.05,
        "{:?}",
        w.objects()[0].1.pose
    );
}

/// A flush box spanning the plate presses all three switches; a small box at the plate's
/// left end presses the left switch only; the round body's sides still use the angle rule.
#[test]
fn plate_switches_by_where_it_is_pressed() {
    let cases = [
        (0.0, 0.12, switch::LEFT | switch::CENTRE | switch::RIGHT),
        (0.047, 0.03, switch::LEFT),
        (-0.047, 0.03, switch::RIGHT),
        (0.0, 0.02, switch::CENTRE),
    ];
    for (dy, side, want) in cases {
        let mut w =
            World::new((1.2, 0.9), Pose::new(0.2, 0.45, 0.0), plated(), exact(), 1).unwrap();
        w.add_object("box", box_at(0.27 + side / 2.0, 0.45 + dy, side, 0.5))
            .unwrap();
        let mut seen = 0;
        for _ in 0..1500 {
            w.step([0.3, 0.3], DT);
            if w.objects()[0].1.pose.x > 0.28 + side / 2.0 {
                seen = w.pressed();
            }
        }
        assert_eq!(seen, want, "box at {dy} of side {side}: {seen:03b}");
    }
}

/// Driving into a wall stops the robot with the plate's face on the wall (the round body
/// alone would get closer), and the robot stalls; an obstacle stops it the same way.
#[test]
fn walls_and_obstacles_stop_the_plate() {
    let mut w = World::new((1.2, 0.9), Pose::new(0.9, 0.45, 0.0), plated(), exact(), 1).unwrap();
    for _ in 0..3000 {
        w.step([0.5, 0.5], DT);
        assert!(w.max_penetration() < 1e-9);
    }
    assert!(
        (w.pose().x + PLATE.offset - 1.2).abs() < 2e-6,
        "{:?}",
        w.pose()
    );
    let s = w.wheel_speeds();
    assert!(s[0].abs() < 1e-6 && s[1].abs() < 1e-6, "stalled: {s:?}");
    assert_eq!(w.pressed(), switch::LEFT | switch::CENTRE | switch::RIGHT);

    // Turning in place next to an obstacle: the plate's corner hits it.
    let mut w = World::new((1.2, 0.9), Pose::new(0.5, 0.45, 0.0), plated(), exact(), 1).unwrap();
    w.add_obstacle(vec![[0.5, 0.53], [0.7, 0.53], [0.7, 0.6], [0.5, 0.6]])
        .unwrap();
    for _ in 0..3000 {
        w.step([-0.4, 0.4], DT);
        assert!(w.max_penetration() < 1e-9);
    }
    assert!(
        w.pose().theta > 0.1 && w.pose().theta < 1.2,
        "{:?}",
        w.pose()
    );
}

/// The scene format takes the plate in `[robot]`; a plate sticking off the table is refused.
#[test]
fn scenes_fit_the_plate() {
    let text = r#"
        [table]
        width = 1.0
        height = 0.8
        [robot]
        start = { x = 0.3, y = 0.4, theta = 0.0 }
        front_plate = { width = 0.12, offset = 0.06 }
    "#;
    let scene = Scene::from_toml(text, "plate.toml").unwrap();
    assert_eq!(scene.robot.front_plate, Some(PLATE));
    let w = World::from_scene(
        &scene,
        pushbot_sim::world::body_from_geometry(&pushbot_firmware::RobotParams::default().geometry),
        exact(),
        1,
    )
    .unwrap();
    assert_eq!(w.body().front_plate, Some(PLATE));
    let round = Scene::from_toml(
        &text.replace("front_plate = { width = 0.12, offset = 0.06 }", ""),
        "round.toml",
    )
    .unwrap();
    assert_eq!(round.robot.front_plate, None);
    let off = text.replace("x = 0.3,", "x = 0.95,");
    assert!(
        World::from_scene(
            &Scene::from_toml(&off, "x").unwrap_or(scene.clone()),
            pushbot_sim::world::body_from_geometry(
                &pushbot_firmware::RobotParams::default().geometry
            ),
            exact(),
            1
        )
        .is_err()
            || Scene::from_toml(&off, "x").is_err()
    );
}
