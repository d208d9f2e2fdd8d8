//! The Stellaris watchdog timer (0x4000_0000), as QEMU models it: a down-counter on the system
//! clock that raises its interrupt on the first time-out and resets the chip on the second,
//! unless fed. The control loop feeds it every period, so a hung loop resets the board.

use crate::time_driver::SYSCLK_HZ;

const BASE: usize = 0x4000_0000;
const LOAD: usize = 0x000;
const CTL: usize = 0x008;
const ICR: usize = 0x00C;
const LOCK: usize = 0xC00;
const UNLOCK_KEY: u32 = 0x1ACC_E551;
const CTL_RESEN: u32 = 1 << 1;
const CTL_INTEN: u32 = 1 << 0;
const RCGC0: usize = 0x400F_E100;
const RCGC0_WDT: u32 = 1 << 3;

/// First time-out, ms: twice this without a feed resets the board. Generous, because an
/// emulator on a busy host can pause the guest for a good fraction of a second.
pub const TIMEOUT_MS: u32 = 1000;

fn write(addr: usize, value: u32) {
    // SAFETY: `addr` is one of the watchdog or system-control registers above: aligned,
    // always-mapped MMIO on the LM3S6965; a volatile store touches no Rust-visible memory.
    unsafe { (addr as *mut u32).write_volatile(value) }
}

fn read(addr: usize) -> u32 {
    // SAFETY: as in `write`.
    unsafe { (addr as *const u32).read_volatile() }
}

/// Clock the watchdog and start it with reset enabled.
pub fn start() {
    write(RCGC0, read(RCGC0) | RCGC0_WDT);
    write(BASE + LOCK, UNLOCK_KEY);
    write(BASE + LOAD, SYSCLK_HZ / 1_000 * TIMEOUT_MS);
    write(BASE + CTL, CTL_INTEN | CTL_RESEN);
    write(BASE + LOCK, 0);
    defmt::info!("watchdog: reset after 2 x {} ms unfed", TIMEOUT_MS);
}

/// Reload the counter (any write to the interrupt-clear register does).
pub fn feed() {
    write(BASE + LOCK, UNLOCK_KEY);
    write(BASE + ICR, 0);
    write(BASE + LOCK, 0);
}
