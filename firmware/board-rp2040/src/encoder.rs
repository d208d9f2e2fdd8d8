//! Quadrature wheel encoders counted in hardware by the RP2040's PIO.
//!
//! One PIO state machine per wheel runs a full-rate (×4) quadrature **counter**, not a knob
//! decoder: it samples both channels every pass, looks the transition from the previous state
//! up in a 16-entry jump table at instruction 0, and counts every valid edge up or down in its
//! X register. A pass takes at most 13 PIO cycles, about 0.1 µs at 125 MHz, so no edge is
//! missed below several MHz of edge rate: far above what a geared motor's encoder produces.
//! Each pass pushes the count into the RX FIFO (without blocking); the CPU drains the FIFO and
//! takes the newest value. The count wraps in 32 bits, as the core expects.
//!
//! A transition where both channels change at once (possible only above the sampling rate, or
//! with noise) is not counted.

use embassy_rp::Peri;
use embassy_rp::gpio::Pull;
use embassy_rp::pio::program::pio_asm;
use embassy_rp::pio::{
    Common, Config, Direction, FifoJoin, Instance, LoadedProgram, PioPin, ShiftDirection,
    StateMachine,
};

/// The counter program, loaded once per PIO block and shared by its state machines.
pub struct QuadratureProgram<'d, PIO: Instance> {
    program: LoadedProgram<'d, PIO>,
}

impl<'d, PIO: Instance> QuadratureProgram<'d, PIO> {
    /// Load the program at instruction 0 (the jump table must sit there: `mov pc, isr`
    /// jumps to the 4-bit transition index).
    pub fn load(common: &mut Common<'d, PIO>) -> Self {
        let prg = pio_asm!(
            ".origin 0",
            // Jump table, index = previous (B, A) << 2 | current (B, A). Forward (+) is A leading
            // B: 00 -> 01 -> 11 -> 10 -> 00.
            "jmp update", // 00 -> 00: no change
            "jmp inc",    // 00 -> 01
            "jmp dec",    // 00 -> 10
            "jmp update", // 00 -> 11: both changed, not counted
            "jmp dec",    // 01 -> 00
            "jmp update", // 01 -> 01: no change
            "jmp update", // 01 -> 10: both changed
            "jmp inc",    // 01 -> 11
            "jmp inc",    // 10 -> 00
            "jmp update", // 10 -> 01: both changed
            "jmp update", // 10 -> 10: no change
            "jmp dec",    // 10 -> 11
            "jmp update", // 11 -> 00: both changed
            "jmp dec",    // 11 -> 01
            "jmp inc",    // 11 -> 10
            "jmp update", // 11 -> 11: no change
            // x += 1, as x = !(!x - 1): PIO can only decrement.
            "inc:",
            "mov x, ~x",
            "jmp x-- inc_done", // taken or not, execution continues at inc_done
            "inc_done:",
            "mov x, ~x",
            "jmp update",
            // x -= 1 (falls through to update when x was 0).
            "dec:",
            "jmp x-- update",
            // Publish the count, then sample: ISR = previous state (low 2 bits of Y) << 2 | pins.
            "update:",
            "mov isr, x",
            "push noblock",
            "mov isr, null",
            "in y, 2",
            "in pins, 2",
            "mov y, isr",
            "mov pc, isr",
        );
        QuadratureProgram {
            program: common.load_program(&prg.program),
        }
    }
}

/// One wheel's encoder: channel A on `pin_a`, channel B on the next GPIO.
pub struct QuadratureCounter<'d, PIO: Instance, const SM: usize> {
    sm: StateMachine<'d, PIO, SM>,
    /// The newest count read.
    last: u32,
}

impl<'d, PIO: Instance, const SM: usize> QuadratureCounter<'d, PIO, SM> {
    /// Start counting. `pin_b` must be the GPIO right after `pin_a` (PIO reads consecutive
    /// pins); both get pull-ups, for open-collector encoder outputs.
    pub fn new(
        common: &mut Common<'d, PIO>,
        mut sm: StateMachine<'d, PIO, SM>,
        pin_a: Peri<'d, impl PioPin>,
        pin_b: Peri<'d, impl PioPin>,
        program: &QuadratureProgram<'d, PIO>,
    ) -> Self {
        let mut a = common.make_pio_pin(pin_a);
        let mut b = common.make_pio_pin(pin_b);
        a.set_pull(Pull::Up);
        b.set_pull(Pull::Up);
        sm.set_pin_dirs(Direction::In, &[&a, &b]);
        let mut cfg = Config::default();
        cfg.set_in_pins(&[&a, &b]);
        cfg.fifo_join = FifoJoin::RxOnly;
        cfg.shift_in.direction = ShiftDirection::Left;
        cfg.shift_in.auto_fill = false;
        cfg.use_program(&program.program, &[]);
        // Full system clock: the fastest sampling there is.
        sm.set_config(&cfg);
        // Start from the pins' present state and a zero count, so power-up is not an edge.
        let init = pio_asm!("mov x, null", "mov isr, null", "in pins, 2", "mov y, isr");
        for &instr in init.program.code.iter() {
            // SAFETY: the state machine is stopped and these instructions only write its X,
            // Y and ISR registers; none touches the program counter, the FIFOs or any pin.
            unsafe { sm.exec_instr(instr) };
        }
        sm.set_enable(true);
        QuadratureCounter { sm, last: 0 }
    }

    /// The cumulative count (wrapping), newest available.
    pub fn count(&mut self) -> i32 {
        let rx = self.sm.rx();
        // Drain what queued up since the last read (8 entries at most, bounded in case the
        // state machine refills as fast as we read) ...
        for _ in 0..16 {
            match rx.try_pull() {
                Some(v) => self.last = v,
                None => break,
            }
        }
        // ... then take the next push, a pass (≤ 13 PIO cycles) away, for a fresh value.
        for _ in 0..64 {
            if let Some(v) = rx.try_pull() {
                self.last = v;
                break;
            }
        }
        self.last as i32
    }
}
