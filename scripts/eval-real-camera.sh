#!/bin/bash
# Learned delivery (Lau et al.) through the serial port and the
# camera from the Fig. 10/11 starts A–F, an ideal camera against a webcam lens (k1 = −0.08,
# f = 700 px, given as the scene's intrinsics file) with the robot's marker 6 cm and the
# object's 3 cm above the table. One strategy, collected in process, serves every trial.
#
#   scripts/eval-real-camera.sh OUT_DIR TRIALS [STARTS...]     (default starts: A B C D E F)
#
# Prints one line per trial and a summary; each trial's JSON is kept in OUT_DIR.
set -euo pipefail
out=${1:?usage: eval-real-camera.sh OUT_DIR TRIALS [STARTS...]}; trials=${2:?trials}; shift 2
starts=${*:-A B C D E F}
root=$(cd "$(dirname "$0")/.." && pwd)
cargo build --release -q -p pushbot -p pushbot-sim --manifest-path "$root/Cargo.toml"
bin="${CARGO_TARGET_DIR:-$root/target}/release"
mkdir -p "$out"; cd "$out"
cat > webcam.yaml <<'YAML'
image_width: 960
image_height: 720
camera_name: webcam
camera_matrix: {rows: 3, cols: 3, data: [700.0, 0.0, 479.5, 0.0, 700.0, 359.5, 0.0, 0.0, 1.0]}
distortion_model: plumb_bob
distortion_coefficients: {rows: 1, cols: 5, data: [-0.08, 0.0, 0.0, 0.0, 0.0]}
YAML
declare -A pose=([A]="0.45 0.95 0.0" [B]="0.45 0.6 1.5708" [C]="0.45 0.25 3.1416"
                 [D]="0.85 0.95 -1.5708" [E]="0.85 0.25 0.7854" [F]="1.3 0.95 2.3562")
[ -f strategy.json ] || "$bin/pushbot" --json collect --scene lau-irregular --object object \
  --out strategy.json > collect.json
for s in $starts; do
  read -r x y th <<< "${pose[$s]}"
  for cond in ideal real; do
    z_obj=""; cam=""
    if [ $cond = real ]; then
      z_obj=", z = 0.03"
      cam=$'[camera]\nintrinsics = "webcam.yaml"\nrobot_marker = { id = 0, x = 0.0, y = 0.0, size = 0.05, z = 0.06 }'
    fi
    cat > "$cond-$s.toml" <<TOML
name = "lau-irregular-$cond-$s"
[table]
width = 1.6
height = 1.2
[robot]
start = { x = 0.15, y = 0.6, theta = 0.0 }
[[objects]]
id = "object"
outline = [[-0.06, -0.04], [0.02, -0.055], [0.07, -0.01], [0.055, 0.045], [-0.01, 0.06], [-0.045, 0.035], [-0.075, 0.0]]
pose = { x = $x, y = $y, theta = $th }
mass = 0.15
support = { kind = "uniform" }
support_friction = 0.3
pusher_friction = 0.4
marker = { id = 1, x = 0.0, y = 0.0, size = 0.05$z_obj }
[[goals]]
object = "object"
pose = { x = 1.25, y = 0.6, theta = 0.0 }
tolerance = 0.022
marker = { id = 20, x = 0.0, y = 0.0, size = 0.05 }
$cam
TOML
    for trial in $(seq 1 "$trials"); do
      tag="$cond-$s-$trial"
      "$bin/pushbot-sim" --no-stdin --scene "$cond-$s.toml" --speed 5 --seed $((trial * 10)) \
        > "sim-$tag.out" 2> "sim-$tag.err" &
      sim=$!
      for _ in $(seq 100); do [ -s "sim-$tag.out" ] && break; sleep 0.1; done
      port=$(python3 -c "import json,sys;print(json.loads(open(sys.argv[1]).readline())['serial'])" "sim-$tag.out")
      camera=$(python3 -c "import json,sys;print(json.loads(open(sys.argv[1]).readline())['camera'])" "sim-$tag.out")
      code=0
      "$bin/pushbot" --json eval delivery --hil --port "$port" --camera "sim:$camera" \
        --scene "$cond-$s.toml" --method learned --strategy strategy.json --trials 1 \
        --time-limit 480 --watchdog-ms 5000 > "eval-$tag.json" 2> "eval-$tag.err" || code=$?
      kill $sim 2>/dev/null; wait $sim 2>/dev/null || true
      echo "$cond $s trial $trial: exit $code $(python3 -c "
import json,sys
r=json.load(open(sys.argv[1]))['scenes'][0]['results'][0]
print('delivered' if r['successes'] else 'FAILED', 'in %.0f s of mission time' % r['mean_time_s'])" "eval-$tag.json" 2>/dev/null || echo '(no result)')"
    done
  done
done
python3 - <<'PY'
import glob, json
for cond in ("ideal", "real"):
    ok = n = 0
    for f in glob.glob(f"eval-{cond}-*.json"):
        try:
            r = json.load(open(f))["scenes"][0]["results"][0]
        except Exception:
            n += 1
            continue
        n += r["trials"]; ok += r["successes"]
    print(f"{cond}: {ok} of {n} delivered")
PY
