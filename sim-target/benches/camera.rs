//! Timing of the simulated overhead camera (`cargo bench -p pushbot-sim --bench camera`): one
//! 960×720 frame of Lau et al.'s table (six calibration markers, the object's and the robot's)
//! when nothing moved since the last frame (only the sensor's noise is new), when the robot
//! moved (the scene drawn again), and when it moves during the exposure (motion blur: the
//! robot drawn along its arc several times and the views averaged).

use criterion::{Criterion, criterion_group, criterion_main};
use pushbot_sim::camera::scene_view::SceneCamera;
use pushbot_sim::{Pose, Scene};

fn bench(c: &mut Criterion) {
    let mut scene = Scene::preset("lau-irregular").expect("preset");
    // The shutter open a third of the frame period, as a webcam's indoors.
    scene.camera.exposure = 0.011;
    let objects: Vec<(String, Pose)> = scene
        .objects
        .iter()
        .map(|o| (o.id.clone(), o.pose))
        .collect();
    let mut cam = SceneCamera::new(scene, 1).expect("camera");
    let robot = Pose::new(0.3, 0.4, 0.3);
    c.bench_function("frame, nothing moved", |b| {
        b.iter(|| cam.capture(0.0, &robot, &objects).expect("frame"))
    });
    let mut k = 0u32;
    c.bench_function("frame, the robot moved", |b| {
        b.iter(|| {
            k += 1;
            let r = Pose::new(0.3 + 1e-4 * f64::from(k % 100), 0.4, 0.3);
            cam.capture(0.0, &r, &objects).expect("frame")
        })
    });
    c.bench_function("frame, the robot moving (motion blur)", |b| {
        b.iter(|| {
            k += 1;
            let r = Pose::new(0.3 + 1e-4 * f64::from(k % 100), 0.4, 0.3);
            cam.capture_moving(0.0, &r, [0.12, 0.5], &objects)
                .expect("frame")
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
