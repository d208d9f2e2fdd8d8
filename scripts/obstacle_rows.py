#!/usr/bin/env python3
"""The table of scripts/obstacle-rows.sh: one line per strategy seed and one for all.

    obstacle_rows.py OUT_DIR SEED...

Reads OUT_DIR/sSEED-SCENE-kK.json (`pushbot eval delivery --json`) and counts, per strategy
seed: deliveries, trials whose object path is over 1.3x the shortest collision-free path for its
outline (from each result's `path_ratios`), the worst ratio, stall recoveries, and time-outs
without a recovery logged. Exits 1 when a row is missing or has no ratios.
"""
import glob
import json
import os
import sys

LIMIT = 1.3


def rows(out, seed):
    files = sorted(glob.glob(os.path.join(out, f"s{seed}-*.json")))
    if len(files) != 12:
        sys.exit(f"seed {seed}: {len(files)} rows in {out}, 12 expected")
    for f in files:
        with open(f) as fh:
            doc = json.load(fh)
        for scene in doc["scenes"]:
            for r in scene["results"]:
                if r["successes"] and "path_ratios" not in r:
                    sys.exit(f"{f}: no path_ratios (written by an older build)")
                yield os.path.basename(f), r


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, seeds = sys.argv[1], sys.argv[2:]
    print("| strategy seed | delivered | over 1.3× | worst | recoveries | time-outs without a recovery |")
    print("|---|---|---|---|---|---|")
    keys = ("trials", "successes", "over", "stall_recoveries", "silent_timeouts")
    total = dict.fromkeys(keys, 0)
    total_worst = (0.0, "")
    for s in seeds:
        t = dict.fromkeys(keys, 0)
        worst = (0.0, "")
        for name, r in rows(out, s):
            ratios = r.get("path_ratios", [])
            r = dict(r, over=sum(1 for x in ratios if x > LIMIT))
            for k in keys:
                t[k] += r[k]
            worst = max([worst] + [(x, f"{name} from {r['start']}") for x in ratios])
        print(
            f"| {s} | {t['successes']}/{t['trials']} | {t['over']} | {worst[0]:.2f} | "
            f"{t['stall_recoveries']} | {t['silent_timeouts']} |"
        )
        for k in keys:
            total[k] += t[k]
        total_worst = max(total_worst, worst)
    pct = 100.0 * total["successes"] / max(total["trials"], 1)
    print(
        f"| all | {total['successes']}/{total['trials']} ({pct:.2f} %) | {total['over']} | "
        f"{total_worst[0]:.2f} | {total['stall_recoveries']} | {total['silent_timeouts']} |"
    )
    print(f"\nworst: {total_worst[1]}")


if __name__ == "__main__":
    main()
