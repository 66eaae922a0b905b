//! The microcontroller's own pin data: which peripheral signals each package pin
//! carries, with the alternate-function number (GPIOx_AFRL/AFRH) for digital functions
//! and none for analog ones (ADC inputs, comparator and op-amp pins).
//!
//! The table is not written by hand: `chip/stm32g474re.rs` is generated from
//! `stm32-metapac` 21 (`metadata` feature), which embassy generates from ST's own
//! STM32CubeMX pin database, and `codegen/tests/chip_data.rs` re-derives it from that
//! crate on every test run (`UPDATE_CHIP_DATA=1` rewrites it). The crate itself is a
//! dev-dependency only: it is a 13 MB download and 249 MB of source for 2 424 chips,
//! and the build script and proc-macros that call this module would otherwise compile
//! it in every profile.
//!
//! The few facts the pin database does not carry are written here with their source:
//! the BOOT0 function of PB8 (DS12288 §3.7, Table 13 "PB8-BOOT0") and the fast/slow
//! ADC channel classes (DS12288 Table 67, notes 3–4).

#[rustfmt::skip]
mod stm32g474re;

/// One signal a pin can carry: `(peripheral, signal, alternate function)`, e.g.
/// `("TIM1", "CH1N", Some(6))` or `("ADC2", "IN17", None)`.
pub type Function = (&'static str, &'static str, Option<u8>);

/// A microcontroller in one package.
#[derive(Debug)]
pub struct Chip {
    /// Part number with package letter, e.g. `STM32G474RE`.
    pub name: &'static str,
    /// Package, e.g. `LQFP64`.
    pub package: &'static str,
    /// Every GPIO of the package with its functions (sorted by peripheral, signal).
    pub pins: &'static [(&'static str, &'static [Function])],
}

/// The chips board files may name.
pub const CHIPS: &[&Chip] = &[&stm32g474re::STM32G474RE];

/// The chip called `name` (exact part number).
pub fn chip(name: &str) -> Option<&'static Chip> {
    CHIPS.iter().copied().find(|c| c.name == name)
}

/// The pin that doubles as BOOT0 on the STM32G4: PB8-BOOT0 (DS12288 §3.7 "Boot
/// modes", Table 13). With the factory option bytes (FLASH_OPTR.nSWBOOT0 = 1, RM0440
/// §3.4.1) its level at reset selects boot from the system bootloader instead of flash.
pub const BOOT0_PIN: &str = "PB8";

/// The highest channel number of the fast ADC inputs: "Fast channels are ADCx_IN1 to
/// ADCx_IN5", every other input is slow (DS12288 Table 67, notes 3 and 4).
pub const LAST_FAST_CHANNEL: u8 = 5;

impl Chip {
    /// The functions of `pin`, `None` if the package has no such pin.
    pub fn functions(&self, pin: &str) -> Option<&'static [Function]> {
        self.pins.iter().find(|(p, _)| *p == pin).map(|(_, f)| *f)
    }

    /// The alternate-function number that routes `peripheral`'s `signal` to `pin`.
    pub fn alternate_function(&self, pin: &str, peripheral: &str, signal: &str) -> Option<u8> {
        self.functions(pin)?
            .iter()
            .find(|(p, s, _)| *p == peripheral && *s == signal)
            .and_then(|(_, _, af)| *af)
    }

    /// Every pin that carries `peripheral`'s `signal`, with its alternate function.
    pub fn pins_with(&self, peripheral: &str, signal: &str) -> Vec<(&'static str, Option<u8>)> {
        self.pins
            .iter()
            .filter_map(|(pin, fs)| {
                fs.iter()
                    .find(|(p, s, _)| *p == peripheral && *s == signal)
                    .map(|(_, _, af)| (*pin, *af))
            })
            .collect()
    }

    /// The single-ended input channel of `adc` (e.g. `"ADC2"`) on `pin`: `IN17` → 17.
    /// Differential negative inputs (`INNx`) are not single-ended channels.
    pub fn adc_channel(&self, pin: &str, adc: &str) -> Option<u8> {
        self.functions(pin)?
            .iter()
            .filter(|(p, _, af)| *p == adc && af.is_none())
            .find_map(|(_, s, _)| s.strip_prefix("IN").and_then(|n| n.parse().ok()))
    }

    /// The pin's functions as a user reads them: `AF6 TIM1_CH1N, …; analog: ADC2_IN17, …`.
    pub fn describe(&self, pin: &str) -> String {
        let Some(fs) = self.functions(pin) else {
            return String::new();
        };
        let mut digital: Vec<(u8, String)> = fs
            .iter()
            .filter_map(|(p, s, af)| af.map(|af| (af, format!("AF{af} {p}_{s}"))))
            .collect();
        digital.sort();
        let analog: Vec<String> = fs
            .iter()
            .filter(|(_, s, af)| af.is_none() && !s.starts_with("INN"))
            .map(|(p, s, _)| format!("{p}_{s}"))
            .collect();
        let mut out = digital.into_iter().map(|(_, d)| d).collect::<Vec<_>>().join(", ");
        if !analog.is_empty() {
            if !out.is_empty() {
                out.push_str("; ");
            }
            out.push_str("analog: ");
            out.push_str(&analog.join(", "));
        }
        out
    }

    /// Pin names in package order.
    pub fn pin_names(&self) -> Vec<&'static str> {
        self.pins.iter().map(|(p, _)| *p).collect()
    }
}

/// Whether ADC channel `channel` is a fast channel (DS12288 Table 67, note 3).
pub fn is_fast_channel(channel: u8) -> bool {
    (1..=LAST_FAST_CHANNEL).contains(&channel)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Facts of the DS12288 pin table (Table 13) and RM0440 the firmware relies on:
    /// PA8 is TIM1_CH1 on AF6, PB15 is TIM1_CH3N on AF4 (not AF6), PA4 is ADC2_IN17 (a
    /// slow channel), PA0 is IN1 of both ADC1 and ADC2, PB8 carries FDCAN1_RX on AF9.
    #[test]
    fn datasheet_facts_are_in_the_table() {
        let c = chip("STM32G474RE").expect("shipped");
        assert_eq!(c.package, "LQFP64");
        // DS12288 Table 2: 52 GPIOs on the STM32G474Rx.
        assert_eq!(c.pins.len(), 52);
        assert_eq!(c.alternate_function("PA8", "TIM1", "CH1"), Some(6));
        assert_eq!(c.alternate_function("PB15", "TIM1", "CH3N"), Some(4));
        assert_eq!(c.alternate_function("PB8", "FDCAN1", "RX"), Some(9));
        assert_eq!(c.adc_channel("PA4", "ADC2"), Some(17));
        assert!(!is_fast_channel(17));
        assert_eq!(
            (c.adc_channel("PA0", "ADC1"), c.adc_channel("PA0", "ADC2")),
            (Some(1), Some(1))
        );
        assert!(is_fast_channel(1));
        assert_eq!(c.adc_channel("PA8", "ADC1"), None);
        assert!(c.describe("PA5").contains("AF1 TIM2_CH1"), "{}", c.describe("PA5"));
        assert!(c.functions("PX9").is_none());
        let ch1n: Vec<&str> = c.pins_with("TIM1", "CH1N").iter().map(|(p, _)| *p).collect();
        assert_eq!(ch1n, ["PA7", "PA11", "PB13", "PC13"]);
    }
}
