//! The JSON schemas of the recorded channels: Foxglove's well-known message schemas
//! (`foxglove.CompressedImage`, `foxglove.CameraCalibration`, `foxglove.ImageAnnotations`,
//! `foxglove.FrameTransforms`, `foxglove.SceneUpdate`, `foxglove.Log`) — the fields this
//! program writes, under the names Foxglove recognises, so its panels open a recording with no
//! setup — and pushbot's own (`pushbot.*`) for telemetry, link events, tracked poses, sessions
//! and trace points.
//!
//! Written here from Foxglove's schema reference (field names, units and enum numbers), not
//! copied: a JSON schema only has to describe the JSON messages that follow it.

use serde_json::{Value, json};

/// The schema encoding of every schema here (MCAP's well-known `jsonschema`).
pub const ENCODING: &str = "jsonschema";

fn obj(title: &str, props: Value) -> Value {
    json!({"title": title, "type": "object", "properties": props})
}

fn arr(items: Value) -> Value {
    json!({"type": "array", "items": items})
}

fn num() -> Value {
    json!({"type": "number"})
}

fn int() -> Value {
    json!({"type": "integer"})
}

fn string() -> Value {
    json!({"type": "string"})
}

fn boolean() -> Value {
    json!({"type": "boolean"})
}

fn time() -> Value {
    json!({"type": "object", "title": "time", "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}
    }})
}

fn duration() -> Value {
    json!({"type": "object", "title": "duration", "properties": {
        "sec": {"type": "integer"},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}
    }})
}

fn color() -> Value {
    obj(
        "foxglove.Color",
        json!({"r": num(), "g": num(), "b": num(), "a": num()}),
    )
}

fn point2() -> Value {
    obj("foxglove.Point2", json!({"x": num(), "y": num()}))
}

fn vector3() -> Value {
    obj(
        "foxglove.Vector3",
        json!({"x": num(), "y": num(), "z": num()}),
    )
}

fn point3() -> Value {
    obj(
        "foxglove.Point3",
        json!({"x": num(), "y": num(), "z": num()}),
    )
}

fn quaternion() -> Value {
    obj(
        "foxglove.Quaternion",
        json!({"x": num(), "y": num(), "z": num(), "w": num()}),
    )
}

fn pose() -> Value {
    obj(
        "foxglove.Pose",
        json!({"position": vector3(), "orientation": quaternion()}),
    )
}

fn one_of(title: &str, names: &[&str]) -> Value {
    let cases: Vec<Value> = names
        .iter()
        .enumerate()
        .map(|(i, n)| json!({"title": n, "const": i}))
        .collect();
    json!({"title": title, "oneOf": cases})
}

/// `foxglove.CompressedImage`: `data` is the PNG or JPEG file, base64 in JSON.
pub fn compressed_image() -> Value {
    obj(
        "foxglove.CompressedImage",
        json!({
            "timestamp": time(),
            "frame_id": string(),
            "data": {"type": "string", "contentEncoding": "base64"},
            "format": string(),
        }),
    )
}

/// `foxglove.CameraCalibration`: a pinhole camera (`K`, `P` row-major, `D` for `plumb_bob`).
pub fn camera_calibration() -> Value {
    obj(
        "foxglove.CameraCalibration",
        json!({
            "timestamp": time(),
            "frame_id": string(),
            "width": int(),
            "height": int(),
            "distortion_model": string(),
            "D": arr(num()),
            "K": arr(num()),
            "R": arr(num()),
            "P": arr(num()),
        }),
    )
}

/// `foxglove.ImageAnnotations`: circles, point sets (outlines) and text labels in pixels.
pub fn image_annotations() -> Value {
    let circle = obj(
        "foxglove.CircleAnnotation",
        json!({"timestamp": time(), "position": point2(), "diameter": num(),
               "thickness": num(), "fill_color": color(), "outline_color": color(),
               "metadata": arr(json!({"type": "object"}))}),
    );
    let points = obj(
        "foxglove.PointsAnnotation",
        json!({"timestamp": time(),
               "type": one_of("foxglove.PointsAnnotationType",
                   &["UNKNOWN", "POINTS", "LINE_LOOP", "LINE_STRIP", "LINE_LIST"]),
               "points": arr(point2()), "outline_color": color(),
               "outline_colors": arr(color()), "fill_color": color(), "thickness": num()}),
    );
    let text = obj(
        "foxglove.TextAnnotation",
        json!({"timestamp": time(), "position": point2(), "text": string(),
               "font_size": num(), "text_color": color(), "background_color": color()}),
    );
    obj(
        "foxglove.ImageAnnotations",
        json!({"circles": arr(circle), "points": arr(points), "texts": arr(text)}),
    )
}

/// `foxglove.FrameTransforms`: parent → child transforms.
pub fn frame_transforms() -> Value {
    let tf = obj(
        "foxglove.FrameTransform",
        json!({"timestamp": time(), "parent_frame_id": string(), "child_frame_id": string(),
               "translation": vector3(), "rotation": quaternion()}),
    );
    obj("foxglove.FrameTransforms", json!({"transforms": arr(tf)}))
}

/// `foxglove.SceneUpdate`: entities made of line primitives and texts.
pub fn scene_update() -> Value {
    let line = obj(
        "foxglove.LinePrimitive",
        json!({"type": one_of("foxglove.LineType", &["LINE_STRIP", "LINE_LOOP", "LINE_LIST"]),
               "pose": pose(), "thickness": num(), "scale_invariant": boolean(),
               "points": arr(point3()), "color": color(), "colors": arr(color()),
               "indices": arr(int())}),
    );
    let text = obj(
        "foxglove.TextPrimitive",
        json!({"pose": pose(), "billboard": boolean(), "font_size": num(),
               "scale_invariant": boolean(), "color": color(), "text": string()}),
    );
    let kv = obj(
        "foxglove.KeyValuePair",
        json!({"key": string(), "value": string()}),
    );
    let entity = obj(
        "foxglove.SceneEntity",
        json!({"timestamp": time(), "frame_id": string(), "id": string(),
               "lifetime": duration(), "frame_locked": boolean(), "metadata": arr(kv.clone()),
               "arrows": arr(json!({"type": "object"})), "cubes": arr(json!({"type": "object"})),
               "spheres": arr(json!({"type": "object"})),
               "cylinders": arr(json!({"type": "object"})), "lines": arr(line),
               "triangles": arr(json!({"type": "object"})), "texts": arr(text),
               "models": arr(json!({"type": "object"}))}),
    );
    let deletion = obj(
        "foxglove.SceneEntityDeletion",
        json!({"timestamp": time(),
               "type": one_of("foxglove.SceneEntityDeletionType", &["MATCHING_ID", "ALL"]),
               "id": string()}),
    );
    obj(
        "foxglove.SceneUpdate",
        json!({"deletions": arr(deletion), "entities": arr(entity)}),
    )
}

/// `foxglove.Log`: one log line (levels 1 debug … 5 fatal).
pub fn log() -> Value {
    obj(
        "foxglove.Log",
        json!({"timestamp": time(),
               "level": one_of("foxglove.LogLevel",
                   &["UNKNOWN", "DEBUG", "INFO", "WARNING", "ERROR", "FATAL"]),
               "message": string(), "name": string(), "file": string(), "line": int()}),
    )
}

/// `pushbot.Telemetry`: the robot's telemetry as the link delivers it (robot time, odometry,
/// wheel speeds, bumper, mode, faults, running and last finished command).
pub fn telemetry() -> Value {
    json!({"title": "pushbot.Telemetry", "type": "object",
           "description": "pushbot-protocol Telemetry, serde's JSON form",
           "properties": {"time_us": int(), "pose": obj("pose", json!({"x": num(), "y": num(), "theta": num()})),
                          "wheel_speed": arr(num()), "bumper": int()}})
}

/// `pushbot.LinkEvent`: a contact, a motion's end, or the link's counters.
pub fn link_event() -> Value {
    json!({"title": "pushbot.LinkEvent", "type": "object",
           "properties": {"kind": string(), "time_us": int()}})
}

/// `pushbot.TrackedPoses`: what the tracking pipeline made of one camera frame (the numbers
/// `pushbot replay` reproduces).
pub fn tracked() -> Value {
    let body = obj(
        "pushbot.TrackedBody",
        json!({"body": string(), "x": num(), "y": num(), "theta": num(),
               "seen": boolean(), "rejected": boolean(), "age": num()}),
    );
    obj(
        "pushbot.TrackedPoses",
        json!({"session": int(), "seq": int(), "frame_time": num(), "full_frame": boolean(),
               "detections": int(), "bodies": arr(body),
               "odometry": obj("pushbot.Odometry", json!({"x": num(), "y": num(), "theta": num()}))}),
    )
}

/// `pushbot.Session`: one connection to a robot and a camera — the scene, the calibration and
/// the tracker's settings a replay needs.
pub fn session() -> Value {
    json!({"title": "pushbot.Session", "type": "object",
           "properties": {"session": int(), "label": string(), "scene": {"type": "object"},
                          "layout": {"type": "object"}, "calibration": {"type": "object"},
                          "tracker": {"type": "object"}, "detector": string(),
                          "whole_frames": boolean()}})
}

/// `pushbot.TracePoint`: the robot's and objects' poses after a primitive.
pub fn trace_point() -> Value {
    json!({"title": "pushbot.TracePoint", "type": "object",
           "properties": {"t": num(), "after": string(), "robot": {"type": "object"},
                          "objects": {"type": "array"}}})
}

/// `pushbot.StageReport`: a stage's report as the live run wrote it (numbers, notes, captions)
/// with its figures' SVG text, so that `pushbot replay` writes the same report.
pub fn stage_report() -> Value {
    json!({"title": "pushbot.StageReport", "type": "object",
           "properties": {"report": {"type": "object"},
                          "figures": {"type": "object",
                                      "description": "figure file stem -> SVG text"}}})
}
