//! The firmware image: `cargo run --release --target thumbv7em-none-eabihf -p
//! motor-firmware` builds it for the motor named by `MOTOR` and flashes a connected
//! STM32G474 board through `probe-rs` (see firmware/README.md).
#![cfg_attr(target_os = "none", no_std, no_main)]

// The board layer: peripherals, the control interrupt, exception and panic handlers.
// `crate::config` etc. inside it name motor-config's modules.
#[cfg(target_os = "none")]
mod board;
#[cfg(target_os = "none")]
use motor_config::{
    adc_frame, bringup, can_commissioning, can_frame, config, fault_frame, fault_record, hw, motor, offset, registers,
    resolver_check,
};

// The RTT transport of the `defmt` log lines (README, "defmt logging").
#[cfg(all(target_os = "none", feature = "defmt"))]
use defmt_rtt as _;

#[cfg(target_os = "none")]
mod target {
    use cortex_m_rt::entry;

    /// Reset entry: brings up the board and runs the main loop (never returns).
    #[entry]
    fn main() -> ! {
        #[cfg(feature = "defmt")]
        defmt::info!(
            "motor-firmware {=str}: boot, f_s = {=f32} Hz",
            env!("CARGO_PKG_VERSION"),
            crate::motor::limits::SWITCHING_FREQUENCY_HZ
        );
        crate::board::run()
    }
}

/// Host build: prints the register values this image would program.
#[cfg(not(target_os = "none"))]
fn main() {
    use motor_config::{config, motor};
    println!("motor: {}", motor::limits::SWITCHING_FREQUENCY_HZ);
    println!("TIM1 ARR {} DTG {:#04x}", config::PWM_PERIOD, config::DEAD_TIME_DTG);
    println!("ADC JSQR {:#010x} {:#010x}", config::JSQR[0], config::JSQR[1]);
    println!("TIM1 BDTR {:#010x}", config::BDTR);
    println!("IWDG PR {} RLR {}", config::WATCHDOG.0, config::WATCHDOG.1);
}
