#!/usr/bin/env python3
"""Reads a pushbot recording with the Python `mcap` reader (pip package `mcap`), as a
roboticist's script would: lists its channels with their schema names, decodes every message
(JSON), and checks that the Foxglove well-known schemas are there.

    python3 scripts/check_mcap.py run.mcap           # a finished recording
    python3 scripts/check_mcap.py --cut cut.mcap     # a recording whose writer was killed

With --cut the file may end anywhere: it is read from the start with the streaming reader up
to the first record that is incomplete, and at least one camera image must have been read.
Prints one JSON object; exit status 1 when a check fails.
"""

import json
import sys

from mcap.reader import NonSeekingReader, make_reader

FOXGLOVE = {
    "/camera/image": "foxglove.CompressedImage",
    "/camera/calibration": "foxglove.CameraCalibration",
    "/camera/annotations": "foxglove.ImageAnnotations",
    "/tf": "foxglove.FrameTransforms",
    "/scene": "foxglove.SceneUpdate",
    "/paths/planned": "foxglove.SceneUpdate",
    "/paths/executed": "foxglove.SceneUpdate",
    "/log": "foxglove.Log",
}


def main(argv):
    cut = "--cut" in argv
    path = [a for a in argv if not a.startswith("--")][0]
    counts, schemas, failures = {}, {}, []
    error = None
    with open(path, "rb") as f:
        reader = NonSeekingReader(f) if cut else make_reader(f)
        try:
            # File order: sorting by time would read the whole file before the first message.
            for schema, channel, message in reader.iter_messages(log_time_order=False):
                schemas[channel.topic] = schema.name if schema else ""
                if schema is not None and schema.encoding != "jsonschema":
                    failures.append(f"{channel.topic}: schema encoding {schema.encoding}")
                if channel.message_encoding != "json":
                    failures.append(f"{channel.topic}: message encoding {channel.message_encoding}")
                json.loads(message.data)
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
        except Exception as e:  # the end of a cut file
            if not cut:
                raise
            error = f"{type(e).__name__}: {e}"
    if not cut:
        with open(path, "rb") as f:
            summary = make_reader(f).get_summary()
        for ch in summary.channels.values():
            schemas.setdefault(ch.topic, summary.schemas[ch.schema_id].name)
        for topic, name in FOXGLOVE.items():
            if schemas.get(topic) != name:
                failures.append(f"{topic}: schema {schemas.get(topic)!r}, expected {name}")
        for topic in ["/camera/image", "/camera/annotations", "/tf", "/scene", "/log",
                      "/robot/telemetry", "/pushbot/tracked"]:
            if counts.get(topic, 0) == 0:
                failures.append(f"{topic}: no message")
    elif counts.get("/camera/image", 0) == 0:
        failures.append("no camera image could be read from the cut file")
    out = {"file": path, "messages": sum(counts.values()), "counts": counts,
           "schemas": schemas, "stopped_at": error, "failures": failures}
    print(json.dumps(out, sort_keys=True))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
