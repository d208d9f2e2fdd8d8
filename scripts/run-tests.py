#!/usr/bin/env python3
"""Runs every test binary of the workspace, several at once, as `cargo test --workspace` would
run them one after another (each in its package's folder, the same arguments).

The hardware-in-the-loop tests (the `pushbot-tests` package) spend most of their time waiting on
a robot paced at five times real time, so one binary at a time leaves the cores idle: here
`--jobs` binaries run at once, the longest known first, and the others than the
hardware-in-the-loop tests run at a lower priority (nice 10), so that the paced robot and the
console's latency budgets get the CPU they ask for.

Each binary's output is kept and printed whole, in name order, once it has finished; a line per
binary says how long it took. Exit status 1 if any binary failed.

    cargo test --workspace --no-run --message-format=json | python3 scripts/run-tests.py --jobs 3
"""

import argparse
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

# The package whose tests drive the simulated robot over a pty (they wait, not compute).
HIL_PACKAGE = "pushbot-tests"
# Binaries known to take a minute or more, started first so that none of them is left for last
# (their order: longest first, as measured on two cores).
LONG_FIRST = ["strategy_hil", "recording", "console_browser", "rearrange_live"]


def binaries(messages):
    """The test executables in cargo's JSON messages: package, target name, kind, path, folder."""
    found = []
    for line in messages:
        line = line.strip()
        if not line.startswith("{"):
            continue
        m = json.loads(line)
        if m.get("reason") != "compiler-artifact" or not m.get("executable"):
            continue
        if not m.get("profile", {}).get("test"):
            continue
        found.append(
            {
                "package": package_name(m),
                "name": m["target"]["name"],
                "kind": m["target"]["kind"][0],
                "exe": m["executable"],
                "dir": str(Path(m["manifest_path"]).parent),
            }
        )
    return found


def package_name(message):
    """A package's name from its compiler-artifact message."""
    # package_id: "path+file:///…/host#pushbot@0.1.0" (or "…/pushbot#0.1.0" when alike).
    pid = message["package_id"]
    tail = pid.split("#", 1)[1] if "#" in pid else pid
    if "@" in tail:
        return tail.split("@", 1)[0]
    return pid.split("#", 1)[0].rstrip("/").rsplit("/", 1)[-1]


def order(bins):
    """Longest known first, then the hardware-in-the-loop binaries, then the rest, by name."""

    def key(b):
        long = LONG_FIRST.index(b["name"]) if b["name"] in LONG_FIRST else len(LONG_FIRST)
        return (long, b["package"] != HIL_PACKAGE, b["package"], b["name"], b["kind"])

    return sorted(bins, key=key)


def run(b, extra):
    """Runs one binary; returns its exit status, output and wall time."""
    nice = b["package"] != HIL_PACKAGE
    start = time.monotonic()
    proc = subprocess.run(
        [b["exe"], *extra],
        cwd=b["dir"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        preexec_fn=(lambda: os.nice(10)) if nice else None,
    )
    return proc.returncode, proc.stdout.decode("utf-8", "replace"), time.monotonic() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=3, help="binaries run at once")
    ap.add_argument("--only", choices=["all", "hil", "rest"], default="all")
    ap.add_argument("args", nargs="*", help="passed to every test binary (after --)")
    a = ap.parse_args()
    bins = binaries(sys.stdin)
    if a.only != "all":
        bins = [b for b in bins if (b["package"] == HIL_PACKAGE) == (a.only == "hil")]
    if not bins:
        sys.exit("no test binaries in cargo's messages (pipe `cargo test --no-run "
                 "--message-format=json` into this script)")
    queue = order(bins)
    results = {}
    lock = threading.Lock()

    def worker():
        while True:
            with lock:
                if not queue:
                    return
                b = queue.pop(0)
            status, out, secs = run(b, a.args)
            with lock:
                results[(b["package"], b["kind"], b["name"])] = (b, status, out, secs)
                mark = "ok" if status == 0 else f"FAILED (exit {status})"
                print(f"-- {b['package']} {b['kind']} {b['name']}: {mark}, {secs:.1f} s",
                      flush=True)

    started = time.monotonic()
    threads = [threading.Thread(target=worker) for _ in range(max(1, a.jobs))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    failed = []
    for key in sorted(results):
        b, status, out, secs = results[key]
        print(f"\n== {b['package']} {b['kind']} {b['name']} ({secs:.1f} s)")
        print(out, end="")
        if status != 0:
            failed.append(f"{b['package']} {b['kind']} {b['name']}")
    print(f"\n{len(results)} test binaries in {time.monotonic() - started:.0f} s, "
          f"{a.jobs} at a time")
    if failed:
        print("failed: " + ", ".join(failed), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
