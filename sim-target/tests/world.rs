//! The world on its own (no firmware): kinematics, walls, bumper, stall and slip, determinism.

use std::f64::consts::PI;

use proptest::prelude::*;
use pushbot_sim::robot::{switch, wrap_angle};
use pushbot_sim::{Body, Hardware, Pose, World};

const DT: f64 = 1e-3;
const TABLE: (f64, f64) = (1.2, 0.9);

fn body() -> Body {
    pushbot_sim::world::body_from_geometry(&pushbot_firmware::RobotParams::default().geometry)
}

/// The physics without any noise.
fn exact() -> Hardware {
    Hardware {
        motor_gain_spread: 0.0,
        slip_noise: 0.0,
        encoder_jitter: 0.0,
        bounce_us: 0,
        ..Hardware::default()
    }
}

fn world(start: Pose, hw: Hardware, seed: u64) -> World {
    World::new(TABLE, start, body(), hw, seed).expect("valid world")
}

/// Every wall keeps the bumper on the table: the centre stays `r` inside every edge.
fn assert_on_table(w: &World) {
    let p = w.pose();
    let r = w.body().bumper_radius;
    let eps = 1e-12;
    assert!(
        p.x >= r - eps && p.x <= TABLE.0 - r + eps && p.y >= r - eps && p.y <= TABLE.1 - r + eps,
        "bumper through a wall at {p:?}"
    );
    assert!(w.wall_clearance() >= -eps);
}

/// Straight ahead: the body moves r·φ along its heading and does not turn.
#[test]
fn drives_straight_by_wheel_rotation() {
    let mut w = world(Pose::new(0.2, 0.45, 0.0), exact(), 1);
    for _ in 0..1500 {
        w.step([0.4, 0.4], DT);
    }
    let p = w.pose();
    let [al, ar] = w.wheel_angles();
    let r = body().wheel_radius;
    assert!(al > 1.0, "the wheels turned: {al}");
    assert!((al - ar).abs() < 1e-12);
    assert!(
        (p.x - 0.2 - r * al).abs() < 1e-9,
        "x {} vs r·φ {}",
        p.x - 0.2,
        r * al
    );
    assert!((p.y - 0.45).abs() < 1e-12 && p.theta.abs() < 1e-12);
    // The speed settled at the motor's steady state: ke·(V·d − ke·ω)/R = Coulomb friction.
    let m = Hardware::default().motor;
    let steady = (0.4 * m.supply_v - m.coulomb_nm * m.resistance_ohm / m.ke) / m.ke;
    let [wl, _] = w.wheel_speeds();
    assert!((wl - steady).abs() / steady < 1e-3, "{wl} vs {steady}");
}

/// Wheels in opposite directions: a spin on the spot by r(φr − φl)/b.
#[test]
fn spins_on_the_spot() {
    let mut w = world(Pose::new(0.6, 0.45, 0.5), exact(), 1);
    for _ in 0..700 {
        w.step([-0.3, 0.3], DT);
    }
    let p = w.pose();
    let [al, ar] = w.wheel_angles();
    let b = body();
    let turned = b.wheel_radius * (ar - al) / b.wheel_base;
    assert!(turned > 1.0, "it turned: {turned}");
    assert!((p.x - 0.6).abs() < 1e-12 && (p.y - 0.45).abs() < 1e-12);
    assert!(wrap_angle(p.theta - 0.5 - turned).abs() < 1e-9);
}

/// Unequal steady wheel speeds: the centre runs on a circle of radius v/ω about a fixed point.
#[test]
fn unequal_wheels_drive_a_circle() {
    let b = body();
    let mut w = world(Pose::new(0.6, 0.45, 0.0), exact(), 1);
    // Let the motors settle.
    for _ in 0..400 {
        w.step([0.2, 0.3], DT);
    }
    let [wl, wr] = w.wheel_speeds();
    let (vl, vr) = (wl * b.wheel_radius, wr * b.wheel_radius);
    let v = (vl + vr) / 2.0;
    let omega = (vr - vl) / b.wheel_base;
    let radius = v / omega;
    let p0 = w.pose();
    // Centre of the circle: to the left of the heading.
    let (cx, cy) = (
        p0.x - radius * p0.theta.sin(),
        p0.y + radius * p0.theta.cos(),
    );
    for _ in 0..1000 {
        w.step([0.2, 0.3], DT);
        let p = w.pose();
        let d = ((p.x - cx).powi(2) + (p.y - cy).powi(2)).sqrt();
        assert!((d - radius).abs() < 1e-6, "off the circle: {d} vs {radius}");
    }
}

/// Driving into the right-hand wall head on: stopped at the wall, centre switch closed, wheels
/// stalled at moderate duty, slipping at full duty (stall torque above traction).
#[test]
fn wall_stops_the_robot_and_closes_the_bumper() {
    let r = body().bumper_radius;
    for (duty, slips) in [(0.5f32, false), (1.0, true)] {
        let mut w = world(Pose::new(1.0, 0.45, 0.0), exact(), 1);
        assert_eq!(w.pressed(), 0);
        let mut closed_at = None;
        for k in 0..3000 {
            w.step([duty, duty], DT);
            assert_on_table(&w);
            if closed_at.is_none() && w.pressed() != 0 {
                closed_at = Some(k);
                // It closed exactly when the bumper reached the wall.
                assert!((w.pose().x - (TABLE.0 - r)).abs() < 1e-12);
            }
        }
        assert!(closed_at.is_some(), "bumper never closed at duty {duty}");
        assert_eq!(w.pressed(), switch::CENTRE);
        assert!((w.pose().x - (TABLE.0 - r)).abs() < 1e-12);
        let speeds = w.wheel_speeds();
        if slips {
            assert_eq!(w.slipping(), [true, true]);
            assert!(speeds[0] > 5.0, "a slipping wheel spins: {speeds:?}");
        } else {
            assert_eq!(w.slipping(), [false, false]);
            assert!(speeds[0].abs() < 1e-6, "a stalled wheel stands: {speeds:?}");
        }
        // Motors off: once the wheels stop (a slipping one spins down first, still pushing),
        // the bumper opens again.
        for _ in 0..300 {
            w.step([0.0, 0.0], DT);
        }
        assert_eq!(w.wheel_speeds(), [0.0, 0.0]);
        assert_eq!(w.pressed(), 0);
    }
}

/// The switch that closes follows the angle at which the wall meets the bumper; backing into a
/// wall closes none.
#[test]
fn bumper_switch_follows_contact_angle() {
    // (start, heading, duty, expected bits)
    let cases = [
        // Heading 60° into the top wall (normal at 90°): pressed 30° to the left.
        (
            Pose::new(0.6, 0.7, 60f64.to_radians()),
            1.0f32,
            switch::LEFT | switch::CENTRE,
        ),
        // Heading 30° into the right wall (normal at 0°): pressed 30° to the right.
        (
            Pose::new(1.05, 0.45, 30f64.to_radians()),
            1.0,
            switch::CENTRE | switch::RIGHT,
        ),
        // Heading 150° into the top wall: pressed 60° to the right.
        (Pose::new(0.6, 0.8, 150f64.to_radians()), 0.5, switch::RIGHT),
        // Heading 80° into the top wall: pressed 10° to the right: centre only.
        (Pose::new(0.6, 0.8, 80f64.to_radians()), 0.5, switch::CENTRE),
        // Backing into the left wall: the rear has no switch.
        (Pose::new(0.1, 0.45, 0.0), -0.5, 0),
    ];
    for (start, duty, expected) in cases {
        let mut w = world(start, exact(), 7);
        let mut touched = false;
        for _ in 0..2000 {
            w.step([duty, duty], DT);
            assert_on_table(&w);
            touched |= w.wall_clearance() < 1e-12;
        }
        assert!(touched, "never reached a wall from {start:?}");
        assert_eq!(w.pressed(), expected, "from {start:?} at duty {duty}");
    }
}

/// The same seed gives the same run; another seed a different one.
#[test]
fn deterministic_for_a_seed() {
    let run = |seed| {
        let mut w = world(Pose::new(0.3, 0.3, 0.4), Hardware::default(), seed);
        let mut trace = Vec::new();
        for k in 0..3000 {
            let d = if k < 1500 { [0.6, 0.5] } else { [0.8, -0.2] };
            w.step(d, DT);
            trace.push(w.pose());
        }
        trace
    };
    let a = run(11);
    assert_eq!(a, run(11));
    let b = run(12);
    assert_ne!(a, b);
    let last = (a[a.len() - 1], b[b.len() - 1]);
    assert!(
        (last.0.x - last.1.x).abs() + (last.0.y - last.1.y).abs() > 1e-4,
        "seeds should differ measurably: {last:?}"
    );
}

/// Invalid set-ups are refused, not simulated.
#[test]
fn refuses_invalid_worlds() {
    assert!(World::new(TABLE, Pose::new(0.01, 0.45, 0.0), body(), exact(), 0).is_err());
    assert!(World::new(TABLE, Pose::new(0.6, 0.45, f64::NAN), body(), exact(), 0).is_err());
    assert!(World::new((0.05, 0.9), Pose::new(0.6, 0.45, 0.0), body(), exact(), 0).is_err());
    assert!(
        World::new(
            (f64::INFINITY, 0.9),
            Pose::new(0.6, 0.45, 0.0),
            body(),
            exact(),
            0
        )
        .is_err()
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Whatever the start and the duties, with noise, the bumper never enters a wall.
    #[test]
    fn never_penetrates_a_wall(
        x in 0.05f64..1.15, y in 0.05f64..0.85, theta in -PI..PI,
        dl in -1.0f32..1.0, dr in -1.0f32..1.0, dl2 in -1.0f32..1.0, dr2 in -1.0f32..1.0,
        seed in 0u64..1000,
    ) {
        let mut w = world(Pose::new(x, y, theta), Hardware::default(), seed);
        for k in 0..2500 {
            let d = if k < 1200 { [dl, dr] } else { [dl2, dr2] };
            w.step(d, DT);
            assert_on_table(&w);
        }
    }
}
