//! What the overhead camera sees of a [`Scene`] at one instant: the obstacles, the goals' printed
//! markers, the objects with their markers, the robot with its marker, and the calibration
//! markers fixed on the table — as polygons and marker placements for [`Camera::capture`].

use crate::robot::Pose;
use crate::scene::{Marker, Scene, placed};

use super::{Camera, CameraConfig, CameraError, CameraFrame, CameraModel, Imaging};
use super::{MarkerFamily, MarkerPlacement, Polygon};

/// Reflectance of obstacles (dark), objects (light grey) and the robot's body (dark grey).
const OBSTACLE_SHADE: f64 = 0.12;
const OBJECT_SHADE: f64 = 0.8;
const ROBOT_SHADE: f64 = 0.3;

/// A marker printed in a frame at `frame`: its placement on the table.
pub fn placement(m: &Marker, frame: &Pose) -> MarkerPlacement {
    let (s, c) = frame.theta.sin_cos();
    MarkerPlacement {
        id: m.id,
        family: MarkerFamily::Tag36h11,
        centre: [frame.x + c * m.x - s * m.y, frame.y + s * m.x + c * m.y],
        heading: frame.theta,
        side: m.size,
        height: m.z,
    }
}

/// The scene's polygons and markers with the robot at `robot` and the objects at `objects`
/// (scene order; an object missing from `objects` is drawn at its scene pose).
pub fn scene_view(
    scene: &Scene,
    robot: &Pose,
    objects: &[(String, Pose)],
) -> (Vec<Polygon>, Vec<MarkerPlacement>) {
    let mut polygons = Vec::new();
    let mut markers: Vec<MarkerPlacement> = scene
        .fiducials()
        .iter()
        .map(|m| placement(m, &Pose::new(0.0, 0.0, 0.0)))
        .collect();
    for o in &scene.obstacles {
        polygons.push(Polygon {
            points: o.outline.clone(),
            shade: OBSTACLE_SHADE,
        });
    }
    for g in &scene.goals {
        if let Some(m) = &g.marker {
            markers.push(placement(m, &g.pose));
        }
    }
    for o in &scene.objects {
        let pose = objects
            .iter()
            .find(|(id, _)| *id == o.id)
            .map_or(o.pose, |(_, p)| *p);
        polygons.push(Polygon {
            points: placed(&o.outline, &pose),
            shade: OBJECT_SHADE,
        });
        if let Some(m) = &o.marker {
            markers.push(placement(m, &pose));
        }
    }
    let r = scene.robot.bumper_radius;
    polygons.push(Polygon {
        points: (0..48)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::TAU / 48.0;
                [robot.x + r * a.cos(), robot.y + r * a.sin()]
            })
            .collect(),
        shade: ROBOT_SHADE,
    });
    markers.push(placement(&scene.camera.robot_marker, robot));
    (polygons, markers)
}

/// The camera a scene asks for: its image size and frame rate, straight above the table.
pub fn scene_camera_config(scene: &Scene, imaging: Imaging) -> CameraConfig {
    let table = [scene.table.width, scene.table.height];
    CameraConfig {
        model: CameraModel::overhead(table, scene.camera.width, scene.camera.height, 16.0),
        imaging,
        fps: scene.camera.fps,
        table,
        // The lens of the scene's `camera.intrinsics` file, if it has one (read with the scene).
        lens: scene.camera.lens,
    }
}

/// A camera looking at a scene.
#[derive(Debug, Clone)]
pub struct SceneCamera {
    scene: Scene,
    camera: Camera,
}

impl SceneCamera {
    /// The scene's camera with default optics and its own noise stream from `seed`.
    pub fn new(scene: Scene, seed: u64) -> Result<SceneCamera, CameraError> {
        let config = scene_camera_config(&scene, Imaging::default());
        Ok(SceneCamera {
            camera: Camera::new(config, seed)?,
            scene,
        })
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Render the scene at simulated `time` with the robot and objects where they are.
    pub fn capture(
        &mut self,
        time: f64,
        robot: &Pose,
        objects: &[(String, Pose)],
    ) -> Result<CameraFrame, CameraError> {
        let (polygons, markers) = scene_view(&self.scene, robot, objects);
        self.camera.capture(time, &polygons, &markers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_marker_of_the_lau_layout_is_drawn_inside_the_image() {
        let scene = Scene::preset("lau-irregular").expect("preset");
        let mut cam = SceneCamera::new(scene.clone(), 1).expect("camera");
        let frame = cam.capture(0.0, &scene.robot.start, &[]).expect("frame");
        // Six calibration markers, the goal's, the object's and the robot's.
        assert_eq!(frame.truth.len(), 9);
        assert!(frame.truth.iter().all(|t| t.fully_visible));
        let ids: Vec<u32> = frame.truth.iter().map(|t| t.marker.id).collect();
        assert!(ids.contains(&0) && ids.contains(&1) && ids.contains(&20));
        // The robot's marker is where the robot is.
        let robot = frame.truth.last().expect("robot marker");
        assert!((robot.marker.centre[0] - scene.robot.start.x).abs() < 1e-12);
    }
}
