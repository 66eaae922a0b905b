//! Pin assignment (STM32G474RE, LQFP64) — the board's only pin facts, also listed in
//! firmware/README.md ("Board assumptions"). Alternate functions from DS12288
//! Table 13.
//!
//! | signal | pin | function |
//! |---|---|---|
//! | gate u/v/w high side | PA8, PA9, PA10 | TIM1_CH1..3 (AF6) |
//! | gate u/v/w low side | PB13, PB14, PB15 | TIM1_CH1N, CH2N (AF6), CH3N (AF4) |
//! | over-current comparator (active low) | PB12 | TIM1_BKIN (AF6) |
//! | resolver excitation (square wave → filter) | PC6 | TIM3_CH1 (AF2) |
//! | i_u, SIN, U_dc | PA0, PA1, PA2 | ADC1_IN1, IN2, IN3 |
//! | i_v, COS, i_w | PA6, PA7, PA4 | ADC2_IN3, IN4, IN17 |
//! | CAN RX/TX | PB8, PB9 | FDCAN1 (AF9) |
//!
//! Analog pins keep their reset state (analog mode).

use stm32g4::stm32g474 as pac;

/// Routes the timer, break and CAN pins to their peripherals (very high speed
/// for the gate signals).
pub fn init(gpioa: &pac::GPIOA, gpiob: &pac::GPIOB, gpioc: &pac::GPIOC) {
    gpioa
        .ospeedr()
        .modify(|_, w| w.ospeedr8().set(0b11).ospeedr9().set(0b11).ospeedr10().set(0b11));
    gpioa
        .afrh()
        .modify(|_, w| w.afrh8().set(6).afrh9().set(6).afrh10().set(6));
    gpioa
        .moder()
        .modify(|_, w| w.moder8().set(0b10).moder9().set(0b10).moder10().set(0b10));

    gpiob
        .ospeedr()
        .modify(|_, w| w.ospeedr13().set(0b11).ospeedr14().set(0b11).ospeedr15().set(0b11));
    gpiob.afrh().modify(|_, w| {
        w.afrh8()
            .set(9)
            .afrh9()
            .set(9)
            .afrh12()
            .set(6)
            .afrh13()
            .set(6)
            .afrh14()
            .set(6)
            .afrh15()
            .set(4)
    });
    gpiob.moder().modify(|_, w| {
        w.moder8()
            .set(0b10)
            .moder9()
            .set(0b10)
            .moder12()
            .set(0b10)
            .moder13()
            .set(0b10)
            .moder14()
            .set(0b10)
            .moder15()
            .set(0b10)
    });

    gpioc.afrl().modify(|_, w| w.afrl6().set(2));
    gpioc.moder().modify(|_, w| w.moder6().set(0b10));
}

/// Forces the six gate signals low as plain GPIO outputs, independent of the
/// timer: the last line of defence of the fault handlers.
pub fn gates_low(gpioa: &pac::GPIOA, gpiob: &pac::GPIOB) {
    gpioa
        .bsrr()
        .write(|w| w.br8().set_bit().br9().set_bit().br10().set_bit());
    gpiob
        .bsrr()
        .write(|w| w.br13().set_bit().br14().set_bit().br15().set_bit());
    gpioa
        .moder()
        .modify(|_, w| w.moder8().set(0b01).moder9().set(0b01).moder10().set(0b01));
    gpiob
        .moder()
        .modify(|_, w| w.moder13().set(0b01).moder14().set(0b01).moder15().set(0b01));
}

/// Level of the resolver excitation output (PC6) — the sign of the excitation at
/// the sampling instant (the input register reads the pin in alternate mode too).
pub fn excitation_high(gpioc: &pac::GPIOC) -> bool {
    gpioc.idr().read().idr6().bit_is_set()
}
