//! An `embassy-time` driver for the LM3S6965 as QEMU models it.
//!
//! Time comes from the Cortex-M SysTick down-counter, free-running over its full 24 bits
//! (a wrap every 1.4 s at 12 MHz) with the wraps counted in its interrupt: a late interrupt
//! (QEMU on a busy host can be milliseconds late) loses no time, because the count itself
//! follows the emulator's clock. Wake-ups are kept in the `embassy-time-queue-utils` queue and
//! checked by general-purpose Timer 0, periodic at 250 µs (a quarter of the control period); a
//! late or merged timer interrupt only delays a wake-up, never the clock.

use core::cell::{Cell, RefCell};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;
use lm3s6965::interrupt;

/// SysTick's clock in QEMU's `lm3s6965evb` after reset (RCC at its reset value: the 12 MHz
/// main oscillator, no PLL).
pub const SYSCLK_HZ: u32 = 12_000_000;
/// SysTick counts this many cycles per wrap (24 bits).
const WRAP: u64 = 1 << 24;
/// Period of the wake-up tick, µs: a quarter of the control period, so a tick that QEMU
/// delivers late or merges with the next still wakes the loop in time.
const WAKE_TICK_US: u32 = 250;
/// Timer 0 (GPTM), the wake-up tick.
const TIMER0: usize = 0x4003_0000;
const GPTM_CFG: usize = 0x000;
const GPTM_TAMR: usize = 0x004;
const GPTM_CTL: usize = 0x00C;
const GPTM_IMR: usize = 0x018;
const GPTM_ICR: usize = 0x024;
const GPTM_TAILR: usize = 0x028;
const GPTM_TIMEOUT: u32 = 1 << 0;
/// System control: run-mode clock gating 1, Timer 0 bit.
const RCGC1: usize = 0x400F_E104;
const RCGC1_TIMER0: u32 = 1 << 16;

fn write(addr: usize, value: u32) {
    // SAFETY: `addr` is one of the Timer 0 or system-control registers above: aligned,
    // always-mapped MMIO on the LM3S6965; a volatile store touches no Rust-visible memory.
    unsafe { (addr as *mut u32).write_volatile(value) }
}

fn read(addr: usize) -> u32 {
    // SAFETY: as in `write`.
    unsafe { (addr as *const u32).read_volatile() }
}

struct SysTickDriver {
    /// SysTick wraps since [`init`].
    wraps: Mutex<CriticalSectionRawMutex, Cell<u64>>,
    /// Time of the earliest pending wake-up, µs (`u64::MAX`: none).
    alarm: Mutex<CriticalSectionRawMutex, Cell<u64>>,
    /// Tasks waiting on timers.
    queue: Mutex<CriticalSectionRawMutex, RefCell<Queue>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    wraps: Mutex::const_new(CriticalSectionRawMutex::new(), Cell::new(0)),
    alarm: Mutex::const_new(CriticalSectionRawMutex::new(), Cell::new(u64::MAX)),
    queue: Mutex::new(RefCell::new(Queue::new())),
});

impl SysTickDriver {
    /// Microseconds since [`init`]; the caller holds a critical section, so the wrap interrupt
    /// cannot run in between and a wrap shows as SysTick's pending bit instead.
    fn now_in(&self, cs: critical_section::CriticalSection) -> u64 {
        let first = SYST::get_current();
        let wrapped = SCB::is_pendst_pending();
        let second = SYST::get_current();
        let mut wraps = self.wraps.borrow(cs).get();
        // SysTick counts down: a later reading above an earlier one means it reloaded between.
        let value = if wrapped || second > first {
            wraps += 1;
            second
        } else {
            first
        };
        let cycles = wraps * WRAP + (WRAP - 1 - u64::from(value));
        cycles / u64::from(SYSCLK_HZ / 1_000_000)
    }

    /// Wake every task whose time has come and remember the next wake-up time.
    fn service_queue(&self, cs: critical_section::CriticalSection) {
        let now = self.now_in(cs);
        let next = self.queue.borrow(cs).borrow_mut().next_expiration(now);
        self.alarm.borrow(cs).set(next);
    }

    /// SysTick wrapped.
    fn on_wrap(&self) {
        critical_section::with(|cs| {
            let wraps = self.wraps.borrow(cs);
            wraps.set(wraps.get() + 1);
        });
    }

    /// The wake-up tick.
    fn on_tick(&self) {
        write(TIMER0 + GPTM_ICR, GPTM_TIMEOUT);
        critical_section::with(|cs| {
            if self.alarm.borrow(cs).get() <= self.now_in(cs) {
                self.service_queue(cs);
            }
        });
    }
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now_in(cs))
    }

    fn schedule_wake(&self, at: u64, waker: &core::task::Waker) {
        critical_section::with(|cs| {
            if self.queue.borrow(cs).borrow_mut().schedule_wake(at, waker) {
                self.service_queue(cs);
            }
        });
    }
}

/// Start the clock (SysTick, free-running from the core clock) and the wake-up tick
/// (Timer 0, periodic).
pub fn init(mut syst: SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload((WRAP - 1) as u32);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();

    write(RCGC1, read(RCGC1) | RCGC1_TIMER0);
    write(TIMER0 + GPTM_CTL, 0);
    write(TIMER0 + GPTM_CFG, 0); // one 32-bit timer
    write(TIMER0 + GPTM_TAMR, 0x2); // periodic
    write(
        TIMER0 + GPTM_TAILR,
        SYSCLK_HZ / 1_000_000 * WAKE_TICK_US - 1,
    );
    write(TIMER0 + GPTM_IMR, GPTM_TIMEOUT);
    write(TIMER0 + GPTM_ICR, GPTM_TIMEOUT);
    write(TIMER0 + GPTM_CTL, 1); // enable timer A
    // SAFETY: the Timer 0 handler only clears its own interrupt and takes the driver's
    // critical-section mutexes: unmasking it breaks no critical section.
    unsafe { cortex_m::peripheral::NVIC::unmask(lm3s6965::Interrupt::TIMER_0A) };
}

#[exception]
fn SysTick() {
    DRIVER.on_wrap();
}

#[interrupt]
fn TIMER_0A() {
    DRIVER.on_tick();
}
