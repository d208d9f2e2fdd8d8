//! The pushbot firmware on a Raspberry Pi Pico (RP2040).
//!
//! The embassy shell (`shell.rs`, shared with the QEMU board) around the sans-IO core of
//! `pushbot-firmware`, on this board layer (pins: see the README's wiring table and the
//! constants below):
//!
//! * control loop on an `embassy-time` `Ticker` at the core's rate (1 kHz);
//! * two DC motors on a DRV8833 dual H-bridge, 20 kHz PWM with direction ([`motor`]);
//! * two quadrature encoders counted by PIO0 at full rate ([`encoder`]);
//! * three bumper switches, watched on GPIO edges;
//! * the host link on UART0 (feature `link-uart`, default) or USB-CDC (feature `link-usb`);
//! * defmt logs over RTT, `panic-probe`, and the hardware watchdog, fed by the control loop.
#![no_std]
#![no_main]

#[cfg(all(feature = "link-uart", feature = "link-usb"))]
compile_error!(
    "choose one link: feature `link-uart` (default) or `link-usb` (with --no-default-features)"
);
#[cfg(not(any(feature = "link-uart", feature = "link-usb")))]
compile_error!("choose a link: feature `link-uart` or `link-usb`");

mod encoder;
mod motor;
mod shell;

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_futures::select::select3;
use embassy_rp::bind_interrupts;
use embassy_rp::gpio::{Input, Level, Output, Pull};
use embassy_rp::peripherals::PIO0;
use embassy_rp::pio::{self, Pio};
use embassy_rp::pwm::{Config as PwmConfig, Pwm};
use embassy_rp::watchdog::Watchdog;
use embassy_time::Duration;
use panic_probe as _;

use crate::encoder::{QuadratureCounter, QuadratureProgram};
use crate::motor::{Drive, Motor};
use crate::shell::{BUMPER, Hardware};

/// Direction of each wheel, [left, right]: the right motor and encoder are mounted mirror-wise,
/// so the same sense of rotation drives the robot backwards. Flip a sign here (or swap that
/// motor's or encoder's two wires) if a wheel runs or counts the wrong way.
const WHEEL_SIGN: [f32; 2] = [1.0, -1.0];
/// Hardware watchdog time-out: the control loop feeds it every millisecond.
const WATCHDOG_TIMEOUT: Duration = Duration::from_millis(50);

#[cfg(feature = "link-uart")]
bind_interrupts!(struct Irqs {
    PIO0_IRQ_0 => pio::InterruptHandler<PIO0>;
    UART0_IRQ => embassy_rp::uart::BufferedInterruptHandler<embassy_rp::peripherals::UART0>;
});
#[cfg(feature = "link-usb")]
bind_interrupts!(struct Irqs {
    PIO0_IRQ_0 => pio::InterruptHandler<PIO0>;
    USBCTRL_IRQ => embassy_rp::usb::InterruptHandler<embassy_rp::peripherals::USB>;
});

/// The Pico's hardware as the shell sees it.
struct Pico {
    drive: Drive<'static>,
    left: QuadratureCounter<'static, PIO0, 0>,
    right: QuadratureCounter<'static, PIO0, 1>,
    watchdog: Watchdog,
}

impl Hardware for Pico {
    fn encoders(&mut self) -> [i32; 2] {
        let l = self.left.count();
        let r = self.right.count();
        // Wrapping negation: the counts wrap, and so does a mirrored count.
        let orient = |c: i32, s: f32| if s < 0.0 { c.wrapping_neg() } else { c };
        [orient(l, WHEEL_SIGN[0]), orient(r, WHEEL_SIGN[1])]
    }

    fn drive(&mut self, duty: [f32; 2]) {
        self.drive.set(duty);
    }

    fn feed_watchdog(&mut self) {
        self.watchdog.feed(WATCHDOG_TIMEOUT);
    }
}

/// Bumper switches (to ground, pulled up): keep [`BUMPER`] equal to the closed switches,
/// updated on every edge.
#[embassy_executor::task]
async fn bumper_task(mut switches: [Input<'static>; 3]) {
    loop {
        let bits = switches
            .iter()
            .enumerate()
            .fold(0u8, |acc, (i, s)| acc | (u8::from(s.is_low()) << i));
        BUMPER.store(bits, core::sync::atomic::Ordering::Relaxed);
        let [a, b, c] = &mut switches;
        select3(
            a.wait_for_any_edge(),
            b.wait_for_any_edge(),
            c.wait_for_any_edge(),
        )
        .await;
    }
}

#[embassy_executor::main(
    executor = "embassy_rp::executor::Executor",
    entry = "cortex_m_rt::entry"
)]
async fn main(spawner: Spawner) {
    let p = embassy_rp::init(Default::default());
    defmt::info!("pushbot on rp2040");

    // Motors first, stopped, bridge asleep.
    let enable = Output::new(p.PIN_6, Level::Low);
    let sys_clk = embassy_rp::clocks::clk_sys_freq();
    let left_pwm = Pwm::new_output_ab(p.PWM_SLICE1, p.PIN_2, p.PIN_3, PwmConfig::default());
    let right_pwm = Pwm::new_output_ab(p.PWM_SLICE2, p.PIN_4, p.PIN_5, PwmConfig::default());
    let drive = Drive {
        motors: [
            Motor::new(left_pwm, sys_clk, WHEEL_SIGN[0]),
            Motor::new(right_pwm, sys_clk, WHEEL_SIGN[1]),
        ],
        enable,
    };

    // Encoders: left A/B on GP10/GP11, right A/B on GP12/GP13.
    let Pio {
        mut common,
        sm0,
        sm1,
        ..
    } = Pio::new(p.PIO0, Irqs);
    let program = QuadratureProgram::load(&mut common);
    let left = QuadratureCounter::new(&mut common, sm0, p.PIN_10, p.PIN_11, &program);
    let right = QuadratureCounter::new(&mut common, sm1, p.PIN_12, p.PIN_13, &program);

    // Bumper: left, centre, right on GP18, GP19, GP20, switches to ground.
    let switches = [
        Input::new(p.PIN_18, Pull::Up),
        Input::new(p.PIN_19, Pull::Up),
        Input::new(p.PIN_20, Pull::Up),
    ];
    spawner.spawn(defmt::unwrap!(bumper_task(switches)));

    #[cfg(feature = "link-uart")]
    link::uart::start(&spawner, p.UART0, p.PIN_0, p.PIN_1);
    #[cfg(feature = "link-usb")]
    link::usb::start(&spawner, p.USB);

    let mut watchdog = Watchdog::new(p.WATCHDOG);
    watchdog.pause_on_debug(true);
    watchdog.start(WATCHDOG_TIMEOUT);
    defmt::info!("watchdog: {} ms", WATCHDOG_TIMEOUT.as_millis());

    shell::control_loop(
        Pico {
            drive,
            left,
            right,
            watchdog,
        },
        pushbot_firmware::RobotParams::default(),
    )
    .await
}

/// The link to the host: tasks that move bytes between the serial device and the shell's
/// pipes.
mod link {
    /// UART0 at [`uart::BAUD`] 8N1, for a radio bridge (HC-05, XBee) or a USB-serial adapter.
    #[cfg(feature = "link-uart")]
    pub mod uart {
        use embassy_executor::Spawner;
        use embassy_rp::Peri;
        use embassy_rp::peripherals::{PIN_0, PIN_1, UART0};
        use embassy_rp::uart::{BufferedUart, BufferedUartRx, BufferedUartTx, Config};
        use embedded_io_async::{Read, Write};
        use static_cell::StaticCell;

        use crate::Irqs;
        use crate::shell::{LINK_RX, LINK_TX};

        /// Baud rate (set an HC-05 to it with `AT+UART=115200,0,0`).
        pub const BAUD: u32 = 115_200;

        /// Open UART0 on GP0 (TX) / GP1 (RX) and spawn its receive and transmit tasks.
        pub fn start(
            spawner: &Spawner,
            uart: Peri<'static, UART0>,
            tx_pin: Peri<'static, PIN_0>,
            rx_pin: Peri<'static, PIN_1>,
        ) {
            static TX_BUF: StaticCell<[u8; 256]> = StaticCell::new();
            static RX_BUF: StaticCell<[u8; 256]> = StaticCell::new();
            let mut config = Config::default();
            config.baudrate = BAUD;
            let uart = BufferedUart::new(
                uart,
                tx_pin,
                rx_pin,
                Irqs,
                TX_BUF.init([0; 256]),
                RX_BUF.init([0; 256]),
                config,
            );
            let (tx, rx) = uart.split();
            spawner.spawn(defmt::unwrap!(rx_task(rx)));
            spawner.spawn(defmt::unwrap!(tx_task(tx)));
            defmt::info!("link: UART0 {} baud", BAUD);
        }

        #[embassy_executor::task]
        async fn rx_task(mut rx: BufferedUartRx) {
            let mut buf = [0u8; 64];
            loop {
                match rx.read(&mut buf).await {
                    Ok(n) => LINK_RX.write_all(&buf[..n]).await,
                    // Framing/parity/overrun: the damaged bytes fail the frame CRC.
                    Err(e) => defmt::warn!("uart rx: {}", e),
                }
            }
        }

        #[embassy_executor::task]
        async fn tx_task(mut tx: BufferedUartTx) {
            let mut buf = [0u8; 64];
            loop {
                let n = LINK_TX.read(&mut buf).await;
                if let Err(e) = tx.write_all(&buf[..n]).await {
                    defmt::warn!("uart tx: {}", e);
                }
            }
        }
    }

    /// The Pico's USB port as a CDC-ACM serial device (`/dev/ttyACM*` on Linux).
    #[cfg(feature = "link-usb")]
    pub mod usb {
        use embassy_executor::Spawner;
        use embassy_futures::join::join;
        use embassy_rp::Peri;
        use embassy_rp::peripherals::USB;
        use embassy_rp::usb::Driver;
        use embassy_usb::class::cdc_acm::{CdcAcmClass, Receiver, Sender, State};
        use embassy_usb::{Builder, Config, UsbDevice};
        use static_cell::StaticCell;

        use crate::Irqs;
        use crate::shell::{LINK_RX, LINK_TX};

        type UsbDriver = Driver<'static, USB>;
        const PACKET: u16 = 64;

        /// Enumerate as a CDC-ACM device and spawn the device, receive and transmit tasks.
        pub fn start(spawner: &Spawner, usb: Peri<'static, USB>) {
            let driver = Driver::new(usb, Irqs);
            let mut config = Config::new(0x1209, 0x0001); // pid.codes test VID/PID
            config.manufacturer = Some("pushbot");
            config.product = Some("pushbot robot link");
            config.serial_number = Some("pushbot-rp2040");
            config.max_power = 100;
            config.max_packet_size_0 = 64;

            static CONFIG_DESC: StaticCell<[u8; 256]> = StaticCell::new();
            static BOS_DESC: StaticCell<[u8; 64]> = StaticCell::new();
            static CONTROL_BUF: StaticCell<[u8; 64]> = StaticCell::new();
            static STATE: StaticCell<State> = StaticCell::new();
            let mut builder = Builder::new(
                driver,
                config,
                CONFIG_DESC.init([0; 256]),
                BOS_DESC.init([0; 64]),
                &mut [],
                CONTROL_BUF.init([0; 64]),
            );
            let class = CdcAcmClass::new(&mut builder, STATE.init(State::new()), PACKET);
            let (tx, rx) = class.split();
            let device = builder.build();
            spawner.spawn(defmt::unwrap!(device_task(device)));
            spawner.spawn(defmt::unwrap!(io_task(tx, rx)));
            defmt::info!("link: USB-CDC");
        }

        #[embassy_executor::task]
        async fn device_task(mut device: UsbDevice<'static, UsbDriver>) {
            device.run().await
        }

        #[embassy_executor::task]
        async fn io_task(mut tx: Sender<'static, UsbDriver>, mut rx: Receiver<'static, UsbDriver>) {
            join(
                async {
                    let mut buf = [0u8; PACKET as usize];
                    loop {
                        rx.wait_connection().await;
                        // Disconnected: wait for the host to open the port again.
                        while let Ok(n) = rx.read_packet(&mut buf).await {
                            LINK_RX.write_all(&buf[..n]).await;
                        }
                    }
                },
                async {
                    let mut buf = [0u8; PACKET as usize];
                    loop {
                        tx.wait_connection().await;
                        loop {
                            let n = LINK_TX.read(&mut buf[..PACKET as usize - 1]).await;
                            // Packets shorter than the maximum end a USB transfer at once.
                            if tx.write_packet(&buf[..n]).await.is_err() {
                                break;
                            }
                        }
                    }
                },
            )
            .await;
        }
    }
}
