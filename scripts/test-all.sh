#!/usr/bin/env bash
# Runs every test of pushbot on a fresh Debian machine with rustup: installs what it needs
# (Debian packages, Rust targets), checks formatting and lints, builds the board firmware,
# and runs the whole test suite, including the hardware-in-the-loop and QEMU tests.
set -euo pipefail
cd "$(dirname "$0")/.."

# Each stage's heading carries the minutes since the start, so a slow stage shows in CI's log.
say() { printf '\n== %s (at %dm%02ds)\n' "$*" $((SECONDS / 60)) $((SECONDS % 60)); }

say "installing what the tests need"
need_pkgs=()
command -v qemu-system-arm >/dev/null 2>&1 || need_pkgs+=(qemu-system-arm)
command -v arm-none-eabi-size >/dev/null 2>&1 || need_pkgs+=(binutils-arm-none-eabi)
if [ ${#need_pkgs[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_pkgs[@]}" >/dev/null
fi
# rust-toolchain.toml names the toolchain, components and targets; make sure they are there.
rustup show active-toolchain >/dev/null
rustup target add thumbv6m-none-eabi thumbv7m-none-eabi >/dev/null

say "formatting"
cargo fmt --all -- --check

say "lints"
cargo clippy --workspace --all-targets -- -D warnings

if [ -x firmware/build-boards.sh ] || [ -f firmware/build-boards.sh ]; then
  say "board firmware"
  bash firmware/build-boards.sh
fi

say "tests"
cargo test --workspace

# The firmware ELF itself in QEMU against the real host link (issue 3): the board binary's
# handshake, heartbeats, stall fault, link watchdog and garbage rejection.
say "firmware in QEMU"
PUSHBOT_QEMU_ELF="$PWD/target/boards/thumbv7m-none-eabi/release/pushbot-board-qemu" \
  cargo test -p pushbot-tests --test qemu -- --ignored --nocapture
echo "qemu: passed"
say "all passed"
