//! The ARM PL011 UARTs of the LM3S6965 (as QEMU models them), driven through their registers.
//!
//! UART0 (0x4000_C000) is the robot's link to the host: received bytes go from its interrupt
//! into the shell's receive pipe, and a task copies the shell's transmit pipe out. UART1
//! (0x4000_D000) carries the defmt log stream (see `logger`).

use crate::shell::{LINK_RX, LINK_TX, try_write_all};

/// Base address of UART0, the host link.
pub const UART0: usize = 0x4000_C000;
/// Base address of UART1, the log stream.
pub const UART1: usize = 0x4000_D000;

const DR: usize = 0x000;
const FR: usize = 0x018;
const IBRD: usize = 0x024;
const FBRD: usize = 0x028;
const LCRH: usize = 0x02C;
const CR: usize = 0x030;
const IMSC: usize = 0x038;
const ICR: usize = 0x044;

const FR_RXFE: u32 = 1 << 4;
const FR_TXFF: u32 = 1 << 5;
const LCRH_WLEN_8: u32 = 0b11 << 5;
const LCRH_FEN: u32 = 1 << 4;
const CR_UARTEN: u32 = 1 << 0;
const CR_TXE: u32 = 1 << 8;
const CR_RXE: u32 = 1 << 9;
const INT_RX: u32 = 1 << 4;
const INT_RT: u32 = 1 << 6;

/// The register at `offset` of the UART at `base`.
fn reg(base: usize, offset: usize) -> *mut u32 {
    (base + offset) as *mut u32
}

fn read(base: usize, offset: usize) -> u32 {
    // SAFETY: `base` is UART0 or UART1 and `offset` one of the PL011 register offsets above:
    // a 4-byte aligned MMIO register that is always mapped on the LM3S6965. A volatile load of
    // device memory creates no reference, so it cannot alias Rust data.
    unsafe { reg(base, offset).read_volatile() }
}

fn write(base: usize, offset: usize, value: u32) {
    // SAFETY: as in `read`: an always-mapped, aligned PL011 register; the single volatile
    // store touches no Rust-visible memory.
    unsafe { reg(base, offset).write_volatile(value) }
}

/// Set a UART to 115200 8N1 (for a 12 MHz UART clock) with its 16-byte FIFOs, and enable it.
pub fn init(base: usize, rx_interrupt: bool) {
    write(base, CR, 0);
    write(base, IBRD, 6); // 12 MHz / (16 × 115200) = 6.51
    write(base, FBRD, 33); // 0.51 × 64 + 0.5
    write(base, LCRH, LCRH_WLEN_8 | LCRH_FEN);
    write(base, ICR, 0x7FF);
    write(base, IMSC, if rx_interrupt { INT_RX | INT_RT } else { 0 });
    write(base, CR, CR_UARTEN | CR_TXE | CR_RXE);
}

/// Send one byte, waiting while the transmitter is full.
pub fn write_byte(base: usize, byte: u8) {
    while read(base, FR) & FR_TXFF != 0 {}
    write(base, DR, u32::from(byte));
}

/// UART0 interrupt body: move every received byte into the shell's receive pipe.
///
/// The interrupt is cleared *before* the receiver is drained: a byte that arrives after the
/// drain raises it again. (QEMU's PL011 raises the receive interrupt once per byte put in the
/// receiver and accepts no more bytes while one waits there, so a byte left behind with its
/// interrupt cleared would stall the link for good.)
pub fn on_uart0_interrupt() {
    write(UART0, ICR, INT_RX | INT_RT);
    let mut buf = [0u8; 16];
    let mut n = 0;
    while read(UART0, FR) & FR_RXFE == 0 {
        // The low 8 bits are the data; the error bits above them are ignored: a damaged byte
        // fails the frame CRC in the core.
        buf[n] = read(UART0, DR) as u8;
        n += 1;
        if n == buf.len() {
            try_write_all(&LINK_RX, &buf);
            n = 0;
        }
    }
    if n > 0 {
        // If the core has fallen behind, bytes are dropped here and the frame CRC rejects
        // what is left of the frame.
        try_write_all(&LINK_RX, &buf[..n]);
    }
}

/// The link's transmit task body: send what the shell queued, forever.
pub async fn transmit_forever() -> ! {
    let mut buf = [0u8; 64];
    loop {
        let n = LINK_TX.read(&mut buf).await;
        for &b in &buf[..n] {
            write_byte(UART0, b);
        }
    }
}
