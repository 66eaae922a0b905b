//! Independent watchdog (RM0440 §42), timeout [`crate::config::WATCHDOG`] =
//! [`crate::hw::WATCHDOG_CONTROL_PERIODS`] control periods.

use stm32g4::stm32g474 as pac;

use super::clocks::{POLL_LIMIT, wait_for};
use crate::config::WATCHDOG;

/// Key values of IWDG_KR (RM0440 §42.4.1).
const KEY_START: u16 = 0xCCCC;
const KEY_UNLOCK: u16 = 0x5555;
const KEY_REFRESH: u16 = 0xAAAA;

/// Writes a key.
fn key(iwdg: &pac::IWDG, k: u16) {
    // SAFETY: the IWDG key register accepts any 16-bit value; only the keys act.
    iwdg.kr().write(|w| unsafe { w.key().bits(k) });
}

/// Starts the watchdog with the configured timeout (cannot be stopped again).
pub fn start(iwdg: &pac::IWDG) {
    key(iwdg, KEY_START);
    key(iwdg, KEY_UNLOCK);
    let (pr, rl) = WATCHDOG;
    iwdg.pr().write(|w| w.pr().set(pr));
    iwdg.rlr().write(|w| w.rl().set(rl));
    // The new values take effect once the status flags clear.
    wait_for(POLL_LIMIT, || iwdg.sr().read().bits() == 0);
    refresh(iwdg);
}

/// Reloads the counter.
pub fn refresh(iwdg: &pac::IWDG) {
    key(iwdg, KEY_REFRESH);
}

/// Starts the watchdog with its reset configuration (fault handlers: the ≈0.5 s
/// default timeout, whatever was configured).
pub fn start_default(iwdg: &pac::IWDG) {
    key(iwdg, KEY_START);
}
