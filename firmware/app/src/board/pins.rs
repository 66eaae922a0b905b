//! Pins, from the board file: every routed pin (the six gates, the break input, the
//! resolver excitation, CAN RX/TX) gets its alternate function and very-high speed from
//! [`crate::config::PORTS_CONFIG`] — register fields computed and host-tested in
//! `motor_config::registers` from `motor::board::{GATE_PINS, GATE_AFS, IO_PINS, IO_AFS}`,
//! which the board file's `[pins]` set and codegen checked against the chip's pin data.
//! Analog pins keep their reset state (analog mode, RM0440 GPIO chapter).

use stm32g4::stm32g474 as pac;

use crate::config::{BREAK_PULL, EXCITATION, GATES_OFF, GATES_OUTPUT, PORTS_CONFIG};
use crate::registers::{Field, PortConfig};

/// Read-modify-write of one GPIO register with a computed field.
macro_rules! rmw {
    ($reg:expr, $field:expr) => {{
        let f: Field = $field;
        if f.mask != 0 {
            // SAFETY: the value changes only the bits of `f.mask`, the fields of the
            // board's pins (host-tested in motor_config::registers).
            $reg.modify(|r, w| unsafe { w.bits(f.apply(r.bits())) });
        }
    }};
}

/// Speed and alternate function first, then the mode: a pin switches to its peripheral
/// only once the peripheral's signal is selected.
macro_rules! route {
    ($gpio:expr, $c:expr) => {{
        let c: PortConfig = $c;
        rmw!($gpio.ospeedr(), c.ospeedr);
        rmw!($gpio.afrl(), c.afrl);
        rmw!($gpio.afrh(), c.afrh);
        rmw!($gpio.moder(), c.moder);
    }};
}

/// Routes the board's timer, break and CAN pins to their peripherals; the break pin gets
/// the pull to its inactive level first ([`crate::config::BREAK_PULL`]), so that an
/// open-drain comparator's line never floats into TIM1_BKIN.
pub fn init(gpioa: &pac::GPIOA, gpiob: &pac::GPIOB, gpioc: &pac::GPIOC) {
    let [pa, pb, pc] = BREAK_PULL;
    rmw!(gpioa.pupdr(), pa);
    rmw!(gpiob.pupdr(), pb);
    rmw!(gpioc.pupdr(), pc);
    let [a, b, c] = PORTS_CONFIG;
    route!(gpioa, a);
    route!(gpiob, b);
    route!(gpioc, c);
}

/// Forces the six gate signals to their off levels as plain GPIO outputs, independent of
/// the timer: the last line of defence of the fault handlers. The level is each driver
/// input's (`motor::board::GATE_OFF_LEVELS`): low for an in-phase input, high for an
/// active-low one such as the L6398's LIN — driving that one low would turn its switch on.
/// The output data is written before the mode, so a pin never drives the wrong level.
pub fn gates_off(gpioa: &pac::GPIOA, gpiob: &pac::GPIOB, gpioc: &pac::GPIOC) {
    let [ra, rb, rc] = GATES_OFF;
    // SAFETY: BSRR bits 0–15 set and 16–31 reset the pins named; writing 0 elsewhere has
    // no effect (RM0440 GPIOx_BSRR).
    unsafe {
        gpioa.bsrr().write(|w| w.bits(ra));
        gpiob.bsrr().write(|w| w.bits(rb));
        gpioc.bsrr().write(|w| w.bits(rc));
    }
    let [ma, mb, mc] = GATES_OUTPUT;
    rmw!(gpioa.moder(), ma);
    rmw!(gpiob.moder(), mb);
    rmw!(gpioc.moder(), mc);
}

/// Level of the resolver excitation output — the sign of the excitation at the sampling
/// instant (the input register reads the pin in alternate mode too).
pub fn excitation_high() -> bool {
    let (port, pin) = EXCITATION;
    // SAFETY: reading a GPIO input data register has no side effect and needs no
    // ownership of the port; the pointers are the PAC's fixed peripheral addresses.
    let idr = unsafe {
        match port {
            0 => (*pac::GPIOA::ptr()).idr().read().bits(),
            1 => (*pac::GPIOB::ptr()).idr().read().bits(),
            _ => (*pac::GPIOC::ptr()).idr().read().bits(),
        }
    };
    idr & (1 << pin) != 0
}
