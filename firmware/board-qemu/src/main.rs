//! The pushbot firmware on an emulated Cortex-M3: QEMU's `lm3s6965evb`.
//!
//! The same embassy shell as the RP2040 board (`../board-rp2040/src/shell.rs`, included below)
//! around the same core, on a small board layer: a SysTick time driver, the PL011 UART0 as the
//! host link, defmt logs on UART1 and the Stellaris hardware watchdog. The board has no motors
//! and no encoders: duties go nowhere and the counts stay frozen, so any commanded move ends in
//! the core's stall fault. `tests/tests/qemu.rs` runs it against the real host link.
#![no_std]
#![no_main]

#[path = "../../board-rp2040/src/shell.rs"]
mod shell;

mod logger;
mod pl011;
mod time_driver;
mod watchdog;

use embassy_executor::Spawner;
use lm3s6965::interrupt;
use panic_probe as _;

/// The emulated board: duties are recorded, encoders never move.
struct QemuBoard {
    /// Last duties applied (only for the log).
    duty: [f32; 2],
}

impl shell::Hardware for QemuBoard {
    fn encoders(&mut self) -> [i32; 2] {
        // No wheels in the emulator: the counts stay where they are.
        [0, 0]
    }

    fn drive(&mut self, duty: [f32; 2]) {
        if (duty[0] == 0.0) != (self.duty[0] == 0.0) || (duty[1] == 0.0) != (self.duty[1] == 0.0) {
            defmt::debug!("motors {} {}", duty[0], duty[1]);
        }
        self.duty = duty;
    }

    fn feed_watchdog(&mut self) {
        watchdog::feed();
    }
}

#[interrupt]
fn UART0() {
    pl011::on_uart0_interrupt();
}

#[embassy_executor::task]
async fn link_tx() {
    pl011::transmit_forever().await
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let Some(cp) = cortex_m::Peripherals::take() else {
        defmt::panic!("core peripherals taken twice");
    };
    pl011::init(pl011::UART1, false);
    defmt::info!("pushbot on qemu lm3s6965evb");
    time_driver::init(cp.SYST);
    pl011::init(pl011::UART0, true);
    // SAFETY: the UART0 handler only touches UART0's receive registers and the receive pipe,
    // which is guarded by a critical-section mutex: unmasking it breaks no critical section.
    unsafe { cortex_m::peripheral::NVIC::unmask(lm3s6965::Interrupt::UART0) };
    // Bytes that came in before the interrupt was on (init clears its flag) are waiting in
    // the receiver: run the handler once to take them.
    cortex_m::peripheral::NVIC::pend(lm3s6965::Interrupt::UART0);
    watchdog::start();
    match link_tx() {
        Ok(token) => spawner.spawn(token),
        Err(_) => defmt::panic!("link tx task already running"),
    }
    // The reference robot, but for one thing: QEMU runs the 1 kHz loop on a shared host that
    // may deschedule it for tens of milliseconds, a gap a real board never has. Latching
    // CONTROL_OVERRUN for that would test the host machine, not the firmware; the emulated
    // board therefore tolerates gaps of up to a quarter second (the check itself is tested in
    // the core's tests, and stays at 3 periods on real hardware).
    let params = pushbot_firmware::RobotParams {
        overrun_periods: 250,
        ..pushbot_firmware::RobotParams::default()
    };
    shell::control_loop(QemuBoard { duty: [0.0; 2] }, params).await
}
