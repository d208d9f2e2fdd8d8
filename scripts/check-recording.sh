#!/usr/bin/env bash
# Recordings, replay and the report, as a user meets them, run by scripts/test-all.sh:
#
# 1. `pushbot demo` writes run.mcap; Python's `mcap` reader lists its channels with Foxglove's
#    schema names and decodes every message (scripts/check_mcap.py);
# 2. `pushbot replay run.mcap --json` tracks the frames again to the same poses (0.1 mm) and
#    writes its report;
# 3. report.html (and the replay's) open in headless chromium: every figure drawn at a non-zero
#    size with a caption, no raw JSON in a cell, no page error (scripts/check_report.py; its
#    --self-test also shows that a broken report fails);
# 4. a demo killed with SIGKILL mid-run leaves a recording that reads up to its last chunk and
#    replays.
#
# Needs chromium and Python's mcap (scripts/test-all.sh installs them); uses target/debug/pushbot.
set -euo pipefail
cd "$(dirname "$0")/.."

bin="${CARGO_TARGET_DIR:-target}/debug/pushbot"
# The binary `cargo test --workspace` builds for the host's integration tests (test profile,
# opt-level 1): after the tests nothing is compiled again. A `cargo build` would resolve the
# dependencies' features without the dev-dependencies and compile the workspace crates anew.
cargo test -q --workspace --no-run
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The rearrangement and the stable push (about a minute); PUSHBOT_CHECK_FULL_DEMO=1 adds the
# learned strategy's collection and delivery (several minutes).
stages="rearrange,stable"
[ "${PUSHBOT_CHECK_FULL_DEMO:-0}" = 1 ] && stages="strategy,rearrange,stable"
echo "-- demo ($stages) with its recording"
"$bin" demo --stages "$stages" --out "$work/demo" --json >"$work/demo.json"
python3 - "$work/demo.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print("demo:", "success" if d["success"] else "FAILED", "recording", d["recording"])
PY
test -s "$work/demo/run.mcap"
python3 scripts/check_mcap.py "$work/demo/run.mcap" >"$work/mcap.json"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("mcap:", d["messages"], "messages on", len(d["schemas"]), "channels:", ", ".join(sorted(set(d["schemas"].values()))))' "$work/mcap.json"

echo "-- replay"
"$bin" replay "$work/demo/run.mcap" --json >"$work/replay.json"
python3 - "$work/replay.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print(f"replay: {d['frames']} frames, largest difference {d['max_diff_m'] * 1e3:.6f} mm")
assert d["agree"] and d["max_diff_m"] <= 1e-4, d
PY

echo "-- the reports in a browser"
python3 scripts/check_report.py --self-test "$work/demo/report.html" >/dev/null
python3 scripts/check_report.py "$work/demo/replay/report.html" >/dev/null
echo "reports: every figure drawn, captioned, no raw JSON, no page error"

echo "-- a demo killed mid-run"
"$bin" demo --stages rearrange --out "$work/killed" --json >/dev/null 2>&1 &
pid=$!
# Wait for a few camera looks (about 0.5 MB each) to be written.
for _ in $(seq 1 240); do
  size=$(stat -c %s "$work/killed/run.mcap" 2>/dev/null || echo 0)
  [ "$size" -gt 3000000 ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.5
done
kill -9 "$pid" 2>/dev/null || { echo "the demo ended before it could be killed" >&2; exit 1; }
wait "$pid" 2>/dev/null || true
python3 scripts/check_mcap.py --cut "$work/killed/run.mcap" >"$work/cut.json"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("killed:", d["messages"], "messages read,", d["counts"].get("/camera/image", 0), "images; stopped at:", d["stopped_at"])' "$work/cut.json"
"$bin" replay "$work/killed/run.mcap" --json >"$work/cut-replay.json"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["agree"], d; print("killed recording replays:", d["frames"], "frames")' "$work/cut-replay.json"
echo "recordings: passed"
