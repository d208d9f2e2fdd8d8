//! What the overhead camera sees of a [`Scene`] at one instant: the obstacles, the goals' printed
//! markers, the objects with their markers, the robot with its marker, and the calibration
//! markers fixed on the table — as polygons and marker placements for [`Camera::capture`].

use crate::robot::Pose;
use crate::scene::{Marker, Scene, placed};

use super::render::Window;
use super::{Camera, CameraConfig, CameraError, CameraFrame, CameraModel, Imaging};
use super::{MarkerFamily, MarkerPlacement, Overlay, Polygon, View};

/// Reflectance of obstacles (dark), objects (light grey) and the robot's body (dark grey).
const OBSTACLE_SHADE: f64 = 0.12;
const OBJECT_SHADE: f64 = 0.8;
const ROBOT_SHADE: f64 = 0.3;
/// Reflectance of an occluder (a hand).
const OCCLUDER_SHADE: f64 = 0.35;

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

/// The camera a scene asks for: its image size and frame rate, straight above the table with
/// the table filling the image, or where its `pose` puts it; through its lens, if it has one.
pub fn scene_camera_config(scene: &Scene, imaging: Imaging) -> CameraConfig {
    let table = [scene.table.width, scene.table.height];
    let (w, h) = (scene.camera.width, scene.camera.height);
    let optics = scene.camera.optics();
    let placed = scene
        .camera
        .pose
        .and_then(|p| p.pose())
        .zip(optics)
        .and_then(|(pose, lens)| pose.plane_homography(&lens, 0.0));
    CameraConfig {
        model: match placed {
            Some(table_to_pixel) => CameraModel {
                width: w,
                height: h,
                table_to_pixel,
            },
            None => CameraModel::overhead(table, w, h, 16.0),
        },
        imaging,
        fps: scene.camera.fps,
        table,
        // The lens of the scene's `camera.intrinsics` file, or a placed camera's ideal one.
        lens: optics,
    }
}

/// Most views drawn over one exposure.
const MAX_VIEWS: usize = 15;

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
        self.capture_moving(time, robot, [0.0, 0.0], objects)
    }

    /// Render the scene at simulated `time` (the middle of the exposure) with the robot at
    /// `robot` moving at `twist` (forward m/s, turning rad/s) and the objects where they are:
    /// with the scene's `camera.exposure`, the robot is drawn along its arc over the exposure,
    /// enough views that no point of it moves more than half a pixel between two (at most
    /// 15), and the views averaged; the scene's occluders shown at `time` are drawn on top.
    pub fn capture_moving(
        &mut self,
        time: f64,
        robot: &Pose,
        twist: [f64; 2],
        objects: &[(String, Pose)],
    ) -> Result<CameraFrame, CameraError> {
        self.capture_moving_within(time, robot, twist, objects, None)
    }

    /// As [`Self::capture`], with the sensor read out only within `windows` (frame pixels;
    /// every other pixel 0): [`Camera::capture_exposure_within`].
    pub fn capture_within(
        &mut self,
        time: f64,
        robot: &Pose,
        objects: &[(String, Pose)],
        windows: &[Window],
    ) -> Result<CameraFrame, CameraError> {
        self.capture_moving_within(time, robot, [0.0, 0.0], objects, Some(windows))
    }

    fn capture_moving_within(
        &mut self,
        time: f64,
        robot: &Pose,
        twist: [f64; 2],
        objects: &[(String, Pose)],
        windows: Option<&[Window]>,
    ) -> Result<CameraFrame, CameraError> {
        let exposure = self.scene.camera.exposure;
        let reach = self.scene.robot.bumper_radius.max(
            self.scene
                .camera
                .robot_marker
                .x
                .hypot(self.scene.camera.robot_marker.y)
                + self.scene.camera.robot_marker.size,
        );
        let travel_m = (twist[0].abs() + twist[1].abs() * reach) * exposure;
        let px = travel_m * self.pixels_per_metre();
        let n = if px.is_finite() && px > 0.5 {
            ((2.0 * px).ceil() as usize).clamp(2, MAX_VIEWS) | 1
        } else {
            1
        };
        let drawn: Vec<_> = (0..n)
            .map(|k| {
                let s = if n == 1 {
                    0.0
                } else {
                    exposure * (k as f64 / (n - 1) as f64 - 0.5)
                };
                scene_view(&self.scene, &along_arc(robot, twist, s), objects)
            })
            .collect();
        let views: Vec<View<'_>> = drawn
            .iter()
            .map(|(polygons, markers)| View { polygons, markers })
            .collect();
        let overlays: Vec<Overlay> = self
            .scene
            .camera
            .occluders
            .iter()
            .filter(|o| o.shown_at(time))
            .map(|o| Overlay {
                polygon: Polygon {
                    points: o.outline.clone(),
                    shade: OCCLUDER_SHADE,
                },
                height: o.z,
            })
            .collect();
        self.camera
            .capture_exposure_within(time, &views, &overlays, windows)
    }

    /// The image's scale at the table's centre, pixels per metre.
    fn pixels_per_metre(&self) -> f64 {
        let h = self.camera.config().model.table_to_pixel;
        let c = [self.scene.table.width / 2.0, self.scene.table.height / 2.0];
        match (h.apply(c), h.apply([c[0] + 0.01, c[1]])) {
            (Some(a), Some(b)) => (b[0] - a[0]).hypot(b[1] - a[1]) / 0.01,
            _ => 0.0,
        }
    }
}

/// Where a robot at `pose` moving at `twist` (forward m/s, turning rad/s) is `s` seconds later
/// (earlier for negative `s`), along its arc.
pub fn along_arc(pose: &Pose, twist: [f64; 2], s: f64) -> Pose {
    let [v, w] = twist;
    let th = pose.theta + w * s;
    if w.abs() < 1e-9 {
        let (sn, c) = pose.theta.sin_cos();
        return Pose::new(pose.x + v * s * c, pose.y + v * s * sn, th);
    }
    Pose::new(
        pose.x + v / w * (th.sin() - pose.theta.sin()),
        pose.y - v / w * (th.cos() - pose.theta.cos()),
        th,
    )
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
        // The robot's marker is where it sits on the robot (3 cm behind its middle; the robot
        // faces +x).
        let robot = frame.truth.last().expect("robot marker");
        let rm = &scene.camera.robot_marker;
        assert!(rm.x < 0.0);
        assert!((robot.marker.centre[0] - (scene.robot.start.x + rm.x)).abs() < 1e-12);
        assert!((robot.marker.centre[1] - scene.robot.start.y).abs() < 1e-12);
    }
}
