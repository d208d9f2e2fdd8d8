//! The defmt global logger of the QEMU board: encoded log frames go out on UART1, in place of
//! the RTT channel a debug probe reads on real hardware. Decode with
//! `defmt-print -e <elf> < defmt.bin` (`cargo run` writes UART1 to `defmt.bin`).

use core::sync::atomic::{AtomicBool, Ordering};

use crate::pl011::{UART1, write_byte};

#[defmt::global_logger]
struct Logger;

/// Whether a log frame is being written (defmt forbids nesting).
static TAKEN: AtomicBool = AtomicBool::new(false);
/// The critical section held while a frame is written.
static mut RESTORE: critical_section::RestoreState = critical_section::RestoreState::invalid();
/// The frame encoder.
static mut ENCODER: defmt::Encoder = defmt::Encoder::new();

fn emit(bytes: &[u8]) {
    for &b in bytes {
        write_byte(UART1, b);
    }
}

// SAFETY: `acquire` enters a critical section before touching `RESTORE`/`ENCODER` and `release`
// leaves it after, so on this single-core MCU no other code runs between them and the two
// statics are never accessed concurrently; `TAKEN` turns a nested `acquire` (a log call from
// inside a log call) into a panic instead of a second mutable access.
unsafe impl defmt::Logger for Logger {
    fn acquire() {
        // SAFETY: paired with the `release` in `Logger::release`, which defmt guarantees to call.
        let restore = unsafe { critical_section::acquire() };
        if TAKEN.load(Ordering::Relaxed) {
            panic!("defmt logger taken reentrantly");
        }
        TAKEN.store(true, Ordering::Relaxed);
        // SAFETY: inside the critical section, with `TAKEN` set: the only access (see above).
        unsafe {
            RESTORE = restore;
            (*core::ptr::addr_of_mut!(ENCODER)).start_frame(emit);
        }
    }

    unsafe fn flush() {}

    unsafe fn release() {
        // SAFETY: defmt calls `release` only after `acquire`, so we are in its critical section.
        unsafe {
            (*core::ptr::addr_of_mut!(ENCODER)).end_frame(emit);
            TAKEN.store(false, Ordering::Relaxed);
            critical_section::release(RESTORE);
        }
    }

    unsafe fn write(bytes: &[u8]) {
        // SAFETY: defmt calls `write` only between `acquire` and `release`.
        unsafe { (*core::ptr::addr_of_mut!(ENCODER)).write(bytes, emit) }
    }
}
