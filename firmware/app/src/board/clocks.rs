//! System clock: HSI16 → PLL → 170 MHz in range-1 boost mode (RM0440 §6.1.5, §7.2).

use stm32g4::stm32g474 as pac;

use crate::hw;

/// Bounded busy-wait: `ready` polled at most `limit` times.
pub fn wait_for(limit: u32, mut ready: impl FnMut() -> bool) -> bool {
    (0..limit).any(|_| ready())
}

/// Polls for clock and peripheral ready flags: generous for the µs-scale waits.
pub const POLL_LIMIT: u32 = hw::SYSCLK_HZ / 1_000;

/// Polls for HSERDY: each poll is a volatile read and a branch (≥ 3 cycles at 170 MHz),
/// so 20 × POLL_LIMIT polls last ≥ 60 ms — many times the t_SU(HSE) of DS12288's HSE
/// oscillator characteristics (2 ms typical; no maximum stated: it depends on the
/// crystal and its load).
const HSE_POLLS: u32 = 20 * POLL_LIMIT;

/// Busy-waits `us` microseconds at SYSCLK.
pub fn delay_us(us: u32) {
    cortex_m::asm::delay(hw::SYSCLK_HZ / hw::US_PER_S * us);
}

/// Switches SYSCLK to the PLL at [`hw::SYSCLK_HZ`]; APB1/APB2 undivided. Returns
/// `false` if the PLL does not lock.
pub fn init(rcc: &pac::RCC, pwr: &pac::PWR, flash: &pac::FLASH) -> bool {
    rcc.apb1enr1().modify(|_, w| w.pwren().set_bit());
    // Boost mode for > 150 MHz (R1MODE = 0), then the wait states, then the PLL.
    pwr.cr5().modify(|_, w| w.r1mode().clear_bit());
    // SAFETY: LATENCY takes 0..=15 wait states; 4 is RM0440's value for 170 MHz.
    flash.acr().modify(|_, w| unsafe {
        w.latency()
            .bits(hw::FLASH_WAIT_STATES)
            .prften()
            .set_bit()
            .icen()
            .set_bit()
            .dcen()
            .set_bit()
    });
    if !wait_for(POLL_LIMIT, || {
        flash.acr().read().latency().bits() == hw::FLASH_WAIT_STATES
    }) {
        return false;
    }
    // SAFETY: PLLSRC 0b10 selects HSI16; PLLN 85 is within 8..=127.
    rcc.pllcfgr().write(|w| unsafe {
        w.pllsrc()
            .bits(0b10)
            .pllm()
            .bits((hw::PLL_M - 1) as u8)
            .plln()
            .bits(hw::PLL_N as u8)
            .pllr()
            .bits((hw::PLL_R / 2 - 1) as u8)
            .pllren()
            .set_bit()
    });
    rcc.cr().modify(|_, w| w.pllon().set_bit());
    if !wait_for(POLL_LIMIT, || rcc.cr().read().pllrdy().bit_is_set()) {
        return false;
    }
    // RM0440 §7.2.7: switch to > 80 MHz through AHB/2 for at least 1 µs.
    rcc.cfgr().modify(|_, w| w.hpre().set(0b1000));
    rcc.cfgr().modify(|_, w| w.sw().set(0b11));
    if !wait_for(POLL_LIMIT, || rcc.cfgr().read().sws().bits() == 0b11) {
        return false;
    }
    delay_us(1);
    rcc.cfgr().modify(|_, w| w.hpre().set(0).ppre1().set(0).ppre2().set(0));
    true
}

/// Enables the clocks of TIM1 and GPIOA..C, which the fault path writes: a fault before
/// [`enable_peripherals`] (a bring-up halt on the option bytes) would otherwise write
/// to unclocked peripherals, whose writes RM0440 does not support (§7.4, the RCC's
/// peripheral clock enable registers), and leave the gate pins in their reset state
/// instead of driving them off. Setting an enable bit that is already set changes
/// nothing, so this is safe from any state.
pub fn enable_gate_peripherals(rcc: &pac::RCC) {
    rcc.ahb2enr()
        .modify(|_, w| w.gpioaen().set_bit().gpioben().set_bit().gpiocen().set_bit());
    rcc.apb2enr().modify(|_, w| w.tim1en().set_bit());
    // Two clock cycles before the first access: read back, as in enable_peripherals.
    let _ = rcc.ahb2enr().read();
    let _ = rcc.apb2enr().read();
}

/// Enables the clocks of every peripheral the board uses, FDCAN1's kernel clock from the
/// board's HSE crystal where it has one ([`hw::FDCAN_FROM_HSE`]); `false` if the HSE
/// oscillator does not become ready (RCC_CR.HSERDY, RM0440 §7.4.1; its start-up time is
/// a few ms: DS12288, HSE oscillator characteristics, t_SU(HSE) 2 ms typical).
pub fn enable_peripherals(rcc: &pac::RCC) -> bool {
    if hw::FDCAN_FROM_HSE {
        rcc.cr().modify(|_, w| w.hseon().set_bit());
        if !wait_for(HSE_POLLS, || rcc.cr().read().hserdy().bit_is_set()) {
            return false;
        }
    }
    rcc.ahb1enr().modify(|_, w| w.cordicen().set_bit().fmacen().set_bit());
    rcc.ahb2enr().modify(|_, w| {
        w.gpioaen()
            .set_bit()
            .gpioben()
            .set_bit()
            .gpiocen()
            .set_bit()
            .adc12en()
            .set_bit()
    });
    rcc.apb2enr().modify(|_, w| w.tim1en().set_bit().syscfgen().set_bit());
    rcc.apb1enr1().modify(|_, w| w.tim3en().set_bit().fdcanen().set_bit());
    // SAFETY: FDCANSEL 0b00 selects HSE, 0b10 PCLK1 (RM0440 §7.4.26).
    rcc.ccipr().modify(|_, w| unsafe { w.fdcansel().bits(hw::FDCANSEL) });
    // RM0440 RCC: after a peripheral clock is enabled, allow two clock cycles before
    // touching the peripheral — read an enable register back (ST's
    // __HAL_RCC_*_CLK_ENABLE does the same with a dummy read).
    let _ = rcc.apb2enr().read();
    let _ = rcc.apb1enr1().read();
    true
}
