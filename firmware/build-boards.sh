#!/usr/bin/env bash
# Build the board binaries (release ELFs) and report their sizes, one line per ELF:
#
#   firmware <board>: flash N bytes, ram M bytes
#
# flash = everything the ELF puts in flash (vector table, boot2, code, read-only data and the
# initial values of .data); ram = static RAM (.data + .bss + .uninit; the stack is not static).
# Fails if the RP2040 builds exceed the budget: flash <= 64 KiB, static RAM <= 16 KiB.
#
# Each board is its own Cargo workspace with its own .cargo/config.toml (target, runner), so
# it is built from its folder. Target directory: $PUSHBOT_BOARD_TARGET_DIR, default
# target/boards at the repository root (tests/tests/qemu.rs looks for the QEMU ELF there).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export CARGO_TARGET_DIR="${PUSHBOT_BOARD_TARGET_DIR:-$ROOT/target/boards}"
FLASH_BUDGET=$((64 * 1024))
RAM_BUDGET=$((16 * 1024))

# Section sizes from the ELF's section headers. readelf is format-generic, so the host's
# binutils read ARM ELFs; arm-none-eabi-readelf is used when present.
READELF="$(command -v arm-none-eabi-readelf || command -v readelf || true)"
if [[ -z "$READELF" ]]; then
    echo "build-boards: need readelf (apt-get install binutils)" >&2
    exit 1
fi

# sizes ELF -> "FLASH RAM" (plain bash arithmetic: no gawk needed)
sizes() {
    local flash=0 ram=0 name type addr size flags
    # Lines look like "  [ 2] .text PROGBITS 10000100 000200 00a7d0 00 AX 0 0 4".
    while read -r name type addr size flags; do
        [[ "$name" == .* && "$flags" == *A* ]] || continue
        addr=$((16#$addr)) size=$((16#$size))
        if ((addr >= 0x20000000)); then
            ram=$((ram + size))
            [[ "$name" == .data ]] && flash=$((flash + size))
        elif [[ "$type" != NOBITS ]]; then
            flash=$((flash + size))
        fi
    done < <("$READELF" -SW "$1" | sed -n 's/^ *\[ *[0-9]*\] *//p' | awk '{ print $1, $2, $3, $5, $7 }')
    echo "$flash $ram"
}

report() { # board elf budget(yes|no)
    local board="$1" elf="$2" check="$3" flash ram
    read -r flash ram < <(sizes "$elf")
    echo "firmware $board: flash $flash bytes, ram $ram bytes"
    if [[ "$check" == yes ]] && ((flash > FLASH_BUDGET || ram > RAM_BUDGET)); then
        echo "build-boards: $board over budget (flash <= $FLASH_BUDGET, ram <= $RAM_BUDGET)" >&2
        return 1
    fi
}

build() { # folder [cargo args...]
    local dir="$1"
    shift
    (cd "$ROOT/firmware/$dir" && cargo build --release --quiet "$@")
}

status=0
# The USB-CDC link variant must build and fit too; built first, as both variants write the
# same ELF name and the UART one (the default) is the one to leave behind.
build board-rp2040 --no-default-features --features link-usb
report rp2040-usb "$CARGO_TARGET_DIR/thumbv6m-none-eabi/release/pushbot-board-rp2040" yes || status=1
build board-rp2040
report rp2040 "$CARGO_TARGET_DIR/thumbv6m-none-eabi/release/pushbot-board-rp2040" yes || status=1
build board-qemu
report qemu-lm3s6965evb "$CARGO_TARGET_DIR/thumbv7m-none-eabi/release/pushbot-board-qemu" no
exit $status
