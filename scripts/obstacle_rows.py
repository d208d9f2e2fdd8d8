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
    total = {"n": 0, "ok": 0, "over": 0, "worst": 0.0, "rec": 0, "silent": 0}
    worst_where = ""
    for s in seeds:
        t = {"n": 0, "ok": 0, "over": 0, "worst": 0.0, "rec": 0, "silent": 0}
        for name, r in rows(out, s):
            t["n"] += r["trials"]
            t["ok"] += r["successes"]
            ratios = r.get("path_ratios", [])
            t["over"] += sum(1 for x in ratios if x > LIMIT)
            if ratios and max(ratios) > t["worst"]:
                t["worst"] = max(ratios)
                if t["worst"] > total["worst"]:
                    worst_where = f"{name} from {r['start']}"
            t["rec"] += r["stall_recoveries"]
            t["silent"] += r["silent_timeouts"]
        print(f"| {s} | {t['ok']}/{t['n']} | {t['over']} | {t['worst']:.2f} | {t['rec']} | {t['silent']} |")
        for k in ("n", "ok", "over", "rec", "silent"):
            total[k] += t[k]
        total["worst"] = max(total["worst"], t["worst"])
    pct = 100.0 * total["ok"] / max(total["n"], 1)
    print(
        f"| all | {total['ok']}/{total['n']} ({pct:.2f} %) | {total['over']} | "
        f"{total['worst']:.2f} | {total['rec']} | {total['silent']} |"
    )
    print(f"\nworst: {worst_where}")


if __name__ == "__main__":
    main()
