//! Messages in Foxglove's well-known schemas, built from pushbot's types as JSON values: pure
//! functions, no I/O (the writer and the replay both use them).
//!
//! Frames: `table` is the table (metres, z up, origin at its lower-left corner); every tracked
//! body (`robot`, object ids, `goal:<id>`) is a child frame of it; the camera image is in frame
//! `camera`.

use base64::Engine as _;
use pushbot_world::Scene;
use serde_json::{Value, json};

use crate::vision::FrameResult;
use crate::vision::calibration::Calibration;

/// The table's frame id.
pub const TABLE_FRAME: &str = "table";
/// The camera image's frame id.
pub const CAMERA_FRAME: &str = "camera";

/// A time as Foxglove's `{sec, nsec}`, from nanoseconds.
pub fn time(ns: u64) -> Value {
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

/// A colour from 0–1 components.
pub fn color(r: f64, g: f64, b: f64, a: f64) -> Value {
    json!({"r": r, "g": g, "b": b, "a": a})
}

/// The rotation about z by `theta` as a quaternion.
pub fn yaw(theta: f64) -> Value {
    let h = 0.5 * theta;
    json!({"x": 0.0, "y": 0.0, "z": h.sin(), "w": h.cos()})
}

/// `foxglove.CompressedImage` of a PNG file.
pub fn compressed_image(ns: u64, png: &[u8]) -> Value {
    json!({
        "timestamp": time(ns),
        "frame_id": CAMERA_FRAME,
        "data": base64::engine::general_purpose::STANDARD.encode(png),
        "format": "png",
    })
}

/// The PNG bytes of a `foxglove.CompressedImage` message; `None` when it has none.
pub fn image_data(msg: &Value) -> Option<Vec<u8>> {
    let data = msg.get("data")?.as_str()?;
    base64::engine::general_purpose::STANDARD.decode(data).ok()
}

/// `foxglove.CameraCalibration` of the camera: the table→pixel homography read as a pinhole
/// camera looking at the table (principal point at the image centre, square pixels; the
/// focal length from the homography's perspective part, or the image width for a camera
/// looking straight down, where the homography cannot tell it), no distortion (the tracker
/// works on the image as it is).
pub fn camera_calibration(ns: u64, cal: &Calibration) -> Value {
    let [w, h] = cal.image_size;
    // A known lens is published as it is (its principal point moved to ROS's pixel centres at
    // integers); otherwise a pinhole read from the table homography.
    let (k, d) = match &cal.lens {
        Some(l) => (
            [l.fx, 0.0, l.cx - 0.5, 0.0, l.fy, l.cy - 0.5, 0.0, 0.0, 1.0],
            l.distortion.to_array(),
        ),
        None => {
            let (cx, cy) = (f64::from(w) / 2.0, f64::from(h) / 2.0);
            let f = focal_length(cal, cx, cy).unwrap_or(f64::from(w));
            ([f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0], [0.0; 5])
        }
    };
    json!({
        "timestamp": time(ns),
        "frame_id": CAMERA_FRAME,
        "width": w,
        "height": h,
        "distortion_model": "plumb_bob",
        "D": d,
        "K": k,
        "R": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        "P": [k[0], 0.0, k[2], 0.0, 0.0, k[4], k[5], 0.0, 0.0, 0.0, 1.0, 0.0],
    })
}

/// Focal length from `H = K [r1 r2 t]`: `r1 ⟂ r2` and `|r1| = |r2|` (Zhang's two constraints,
/// one view), whichever is better conditioned; `None` when neither says anything (a camera
/// looking straight down).
fn focal_length(cal: &Calibration, cx: f64, cy: f64) -> Option<f64> {
    let m = &cal.table_to_pixel.0;
    let col = |j: usize| [m[0][j] - cx * m[2][j], m[1][j] - cy * m[2][j], m[2][j]];
    let (a, b) = (col(0), col(1));
    let orthogonal = (-(a[0] * b[0] + a[1] * b[1]), a[2] * b[2]);
    let equal = (
        b[0] * b[0] + b[1] * b[1] - a[0] * a[0] - a[1] * a[1],
        a[2] * a[2] - b[2] * b[2],
    );
    let (n, d) = if orthogonal.1.abs() >= equal.1.abs() {
        orthogonal
    } else {
        equal
    };
    if d.abs() < 1e-12 {
        return None;
    }
    let f2 = n / d;
    (f2.is_finite() && f2 > 1.0).then(|| f2.sqrt())
}

/// `foxglove.ImageAnnotations` of a frame: every detected marker outlined (green, with its
/// id), every tracked body as a dot with its name (red when seen in this frame, grey when
/// predicted), labels stacked so that none overlaps another.
pub fn image_annotations(ns: u64, result: &FrameResult, cal: &Calibration) -> Value {
    let t = time(ns);
    let green = color(0.2, 0.9, 0.2, 1.0);
    let mut points = Vec::new();
    let mut texts = Vec::new();
    let mut circles = Vec::new();
    for d in &result.detections {
        let pts: Vec<Value> = d
            .corners
            .iter()
            .map(|c| json!({"x": c[0], "y": c[1]}))
            .collect();
        points.push(json!({"timestamp": t, "type": 2, "points": pts,
                           "outline_color": green, "outline_colors": [],
                           "fill_color": color(0.0, 0.0, 0.0, 0.0), "thickness": 2.0,
                           "metadata": []}));
    }
    let mut anchors = Vec::new();
    for tr in &result.tracked {
        let Some(p) = cal.table_to_pixel.apply([tr.pose.x, tr.pose.y]) else {
            continue;
        };
        let c = if tr.seen {
            color(1.0, 0.23, 0.19, 1.0)
        } else {
            color(0.6, 0.6, 0.6, 1.0)
        };
        circles.push(json!({"timestamp": t, "position": {"x": p[0], "y": p[1]},
                            "diameter": 10.0, "thickness": 2.0,
                            "fill_color": c, "outline_color": c, "metadata": []}));
        anchors.push((p, tr.body.clone(), c));
    }
    let placed = crate::exec::view::place_labels(
        &anchors
            .iter()
            .map(|(p, s, _)| (*p, s.len()))
            .collect::<Vec<_>>(),
        16.0,
    );
    for ((_, text, c), pos) in anchors.into_iter().zip(placed) {
        texts.push(
            json!({"timestamp": t, "position": {"x": pos[0], "y": pos[1]},
                          "text": text, "font_size": 16.0, "text_color": c,
                          "background_color": color(0.0, 0.0, 0.0, 0.6),
                          "metadata": []}),
        );
    }
    json!({"circles": circles, "points": points, "texts": texts})
}

/// `foxglove.FrameTransforms`: `table` → each tracked body.
pub fn frame_transforms(ns: u64, result: &FrameResult) -> Value {
    let tfs: Vec<Value> = result
        .tracked
        .iter()
        .map(|tr| {
            json!({"timestamp": time(ns), "parent_frame_id": TABLE_FRAME,
                   "child_frame_id": tr.body,
                   "translation": {"x": tr.pose.x, "y": tr.pose.y, "z": 0.0},
                   "rotation": yaw(tr.pose.theta)})
        })
        .collect();
    json!({"transforms": tfs})
}

fn identity() -> Value {
    json!({"position": {"x": 0.0, "y": 0.0, "z": 0.0}, "orientation": yaw(0.0)})
}

fn line(kind: u8, pts: &[[f64; 2]], z: f64, width: f64, c: Value) -> Value {
    let points: Vec<Value> = pts
        .iter()
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .map(|p| json!({"x": p[0], "y": p[1], "z": z}))
        .collect();
    json!({"type": kind, "pose": identity(), "thickness": width, "scale_invariant": false,
           "points": points, "color": c, "colors": [], "indices": []})
}

fn entity(ns: u64, frame: &str, id: &str, locked: bool, lines: Vec<Value>) -> Value {
    // Every primitive list present (empty when unused), as the schema lists them.
    json!({"timestamp": time(ns), "frame_id": frame, "id": id,
           "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": locked, "metadata": [],
           "arrows": [], "cubes": [], "spheres": [], "cylinders": [], "lines": lines,
           "triangles": [], "texts": [], "models": []})
}

/// `foxglove.SceneUpdate` of a scene: the table's edge and the obstacles in `table`, each
/// object's outline in its own frame (so it moves with the tracked pose), each goal's outline
/// where it must end, and the robot's bumper in `robot`.
pub fn scene_update(ns: u64, scene: &Scene) -> Value {
    let (w, h) = (scene.table.width, scene.table.height);
    let mut ents = vec![entity(
        ns,
        TABLE_FRAME,
        "table",
        false,
        vec![line(
            1,
            &[[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]],
            0.0,
            0.004,
            color(0.8, 0.8, 0.8, 1.0),
        )],
    )];
    for (i, o) in scene.obstacles.iter().enumerate() {
        ents.push(entity(
            ns,
            TABLE_FRAME,
            &format!("obstacle-{i}"),
            false,
            vec![line(1, &o.outline, 0.0, 0.004, color(0.4, 0.4, 0.4, 1.0))],
        ));
    }
    for o in &scene.objects {
        ents.push(entity(
            ns,
            &o.id,
            &format!("object-{}", o.id),
            true,
            vec![line(1, &o.outline, 0.0, 0.003, color(1.0, 0.23, 0.19, 1.0))],
        ));
    }
    for g in &scene.goals {
        let Some(o) = scene.objects.iter().find(|o| o.id == g.object) else {
            continue;
        };
        let pts: Vec<[f64; 2]> = o
            .outline
            .iter()
            .map(|v| {
                let p = g.pose.point_to_world(nalgebra::Vector2::new(v[0], v[1]));
                [p.x, p.y]
            })
            .collect();
        ents.push(entity(
            ns,
            TABLE_FRAME,
            &format!("goal-{}", g.object),
            false,
            vec![line(1, &pts, 0.0, 0.003, color(0.2, 0.8, 0.2, 1.0))],
        ));
    }
    let r = scene.robot.bumper_radius;
    let disc: Vec<[f64; 2]> = (0..24)
        .map(|i| {
            let a = f64::from(i) * std::f64::consts::TAU / 24.0;
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    ents.push(entity(
        ns,
        "robot",
        "robot",
        true,
        vec![
            line(1, &disc, 0.0, 0.003, color(0.1, 0.4, 1.0, 1.0)),
            line(
                0,
                &[[0.0, 0.0], [r, 0.0]],
                0.0,
                0.003,
                color(0.1, 0.4, 1.0, 1.0),
            ),
        ],
    ));
    json!({"deletions": [], "entities": ents})
}

/// `foxglove.SceneUpdate` of one path in `table` (a line strip): `id` names it (a later path
/// with the same id replaces it).
pub fn path_update(ns: u64, id: &str, pts: &[[f64; 2]], c: Value) -> Value {
    json!({"deletions": [], "entities": [entity(ns, TABLE_FRAME, id, false,
        vec![line(0, pts, 0.001, 0.004, c)])]})
}

/// `foxglove.Log` (level 2 info, 3 warning, 4 error).
pub fn log(ns: u64, level: u8, name: &str, message: &str) -> Value {
    json!({"timestamp": time(ns), "level": level, "message": message, "name": name,
           "file": "", "line": 0})
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushbot_world::camera::Homography;

    fn calibration(h: [[f64; 3]; 3]) -> Calibration {
        Calibration {
            version: 1,
            image_size: [960, 720],
            pixel_to_table: Homography(h),
            table_to_pixel: Homography(h),
            rms_px: 0.0,
            max_px: 0.0,
            mm_per_px: 1.0,
            markers: Vec::new(),
            points: 0,
            lens: None,
            camera_centre: None,
        }
    }

    #[test]
    fn times_quaternions_and_images() {
        assert_eq!(time(3_000_000_007), json!({"sec": 3, "nsec": 7}));
        let q = yaw(std::f64::consts::FRAC_PI_2);
        assert!((q["z"].as_f64().unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((q["w"].as_f64().unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
        let png = b"\x89PNG fake bytes \x00\xff";
        let msg = compressed_image(5, png);
        assert_eq!(msg["format"], "png");
        assert_eq!(image_data(&msg).as_deref(), Some(&png[..]));
        assert_eq!(image_data(&json!({"data": "not base64!"})), None);
    }

    #[test]
    fn a_pinhole_is_read_from_the_homography() {
        // Straight down: no perspective, the focal length falls back to the image width.
        let down = calibration([[500.0, 0.0, 100.0], [0.0, -500.0, 600.0], [0.0, 0.0, 1.0]]);
        assert_eq!(camera_calibration(0, &down)["K"][0], 960.0);
        // H = K [r1 r2 t] of a camera with f = 800 tilted 20° about x, 1.5 m away.
        let (f, cx, cy) = (800.0, 480.0, 360.0);
        let (s, c) = 20f64.to_radians().sin_cos();
        let k = |v: [f64; 3]| [f * v[0] + cx * v[2], f * v[1] + cy * v[2], v[2]];
        // Then also tilted about y and turned 30° about the optical axis (there the
        // orthogonality constraint decides).
        let (sz, cz) = 30f64.to_radians().sin_cos();
        let turned = |v: [f64; 3]| [cz * v[0] - sz * v[1], sz * v[0] + cz * v[1], v[2]];
        let tilt_y = |v: [f64; 3]| [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]];
        let (r1, r2) = ([1.0, 0.0, 0.0], [0.0, c, s]);
        for (r1, r2) in [(r1, r2), (turned(tilt_y(r1)), turned(tilt_y(r2)))] {
            let (a, b, tt) = (k(r1), k(r2), k([-0.6, -0.4, 1.5]));
            let h = [
                [a[0], b[0], tt[0]],
                [a[1], b[1], tt[1]],
                [a[2], b[2], tt[2]],
            ];
            let got = camera_calibration(0, &calibration(h))["K"][0]
                .as_f64()
                .unwrap();
            assert!((got - f).abs() < 1e-6, "{got}");
        }
    }

    #[test]
    fn the_scene_has_an_entity_for_everything_on_the_table() {
        let scene = Scene::preset("lau-obstacles").expect("preset");
        let u = scene_update(0, &scene);
        let ids: Vec<&str> = u["entities"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["id"].as_str().unwrap())
            .collect();
        let expected = 2 + scene.obstacles.len() + scene.objects.len() + scene.goals.len();
        assert_eq!(ids.len(), expected, "{ids:?}");
        assert!(ids.contains(&"table") && ids.contains(&"robot"));
        // An object's outline is drawn in its own frame, so it follows the tracked pose.
        let o = &scene.objects[0];
        let e = u["entities"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["id"] == format!("object-{}", o.id))
            .unwrap();
        assert_eq!(e["frame_id"], o.id.as_str());
        assert_eq!(e["frame_locked"], true);
        assert_eq!(
            e["lines"][0]["points"].as_array().unwrap().len(),
            o.outline.len()
        );
    }
}
