#!/bin/bash
# Learned delivery among obstacles (Lau et al. §III-E) on the
# project's own wall layouts. Twelve rows per strategy seed: three layouts (`lau-zigzag`, two
# staggered walls; `lau-door`, a 30 cm door; `lau-obstacles`, a block) × two objects (the
# irregular object, and the L-shape marked in its corner: the scenes ending in `-l`) × trial
# seeds 1 and 2; each row is starts A–F × TRIALS trials, the truth camera. The strategies are
# the ones kept in results/obstacle-rows/strategies/seed-K, collected on the clear table.
#
#   scripts/obstacle-rows.sh OUT_DIR [TRIALS] [STRATEGY_SEEDS...]   (default: 20, seeds 1–5)
#
# A row in which a trial is not delivered exits 1 and is kept (the table counts it); any
# other error stops the run. Each row's JSON is kept in OUT_DIR; the table (delivered, trials
# over 1.3× the shortest path, the worst ratio, recoveries, time-outs without a recovery) is
# printed and written to OUT_DIR/table.md. With 20 trials and five seeds (7200 deliveries) it
# takes about 8 minutes on 2 cores. Rows already in OUT_DIR are not run again.
set -euo pipefail
out=${1:?usage: obstacle-rows.sh OUT_DIR [TRIALS] [STRATEGY_SEEDS...]}
trials=${2:-20}
shift $(( $# > 1 ? 2 : 1 ))
seeds=${*:-1 2 3 4 5}
root=$(cd "$(dirname "$0")/.." && pwd)
strategies="$root/results/obstacle-rows/strategies"
cargo build --release -q -p pushbot --manifest-path "$root/Cargo.toml"
bin="${CARGO_TARGET_DIR:-$root/target}/release/pushbot"
mkdir -p "$out"
jobs=()
for s in $seeds; do
  [ -d "$strategies/seed-$s" ] || { echo "no strategies for seed $s in $strategies" >&2; exit 2; }
  for k in 1 2; do
    for scene in lau-zigzag lau-door lau-obstacles lau-zigzag-l lau-door-l lau-obstacles-l; do
      case $scene in *-l) object=lau-l-shape ;; *) object=lau-irregular ;; esac
      json="$out/s$s-$scene-k$k.json"
      [ -s "$json" ] && continue
      jobs+=("$bin eval delivery --scene $scene --method learned --trials $trials --seed $k \
--strategy $strategies/seed-$s/$object.strategy --sim-camera truth --json > $json.part; \
[ \$? -le 1 ] && mv $json.part $json")
    done
  done
done
echo "${#jobs[@]} rows to run" >&2
printf '%s\0' "${jobs[@]+"${jobs[@]}"}" | xargs -0 -r -P "$(nproc)" -I{} bash -c '{}'
python3 "$root/scripts/obstacle_rows.py" "$out" $seeds | tee "$out/table.md"
