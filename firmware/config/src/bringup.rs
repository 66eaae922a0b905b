//! Bring-up sequences whose order matters, written against small traits so the same
//! code runs on the PAC (the board layer implements the traits) and on host models of
//! the hardware behaviour RM0440 and ST's drivers describe (the tests below).
#![forbid(unsafe_code)]

/// The ADC control bits the enable sequence touches (RM0440 §21.4.9).
pub trait AdcEnable {
    /// ADC_CR.ADEN reads 1.
    fn aden(&mut self) -> bool;
    /// Writes ADC_CR.ADEN = 1.
    fn set_aden(&mut self);
    /// ADC_ISR.ADRDY reads 1.
    fn adrdy(&mut self) -> bool;
}

/// Enables an ADC after calibration: ADEN written a few instructions after ADCAL reads
/// 0 is cleared again by the calibration logic when less than 4 ADC clock cycles have
/// passed, and ADRDY never comes. ST's `ADC_Enable` (stm32g4xx_hal_adc.c) therefore
/// re-writes ADEN while ADRDY is 0 and ADEN reads 0; so does this, for at most `polls`
/// reads of ADRDY. `true` once ADRDY is set.
pub fn enable_adc<A: AdcEnable>(adc: &mut A, polls: u32) -> bool {
    adc.set_aden();
    for _ in 0..polls {
        if adc.adrdy() {
            return true;
        }
        if !adc.aden() {
            adc.set_aden();
        }
    }
    false
}

/// TIM1's break and main-output bits (RM0440 §28.3.18, TIMx_SR.BIF, TIMx_BDTR.MOE).
pub trait BreakControl {
    /// TIMx_SR.BIF reads 1 (a break was latched).
    fn break_flag(&mut self) -> bool;
    /// Clears TIMx_SR.BIF (rc_w0).
    fn clear_break_flag(&mut self);
    /// Writes TIMx_BDTR.MOE.
    fn set_main_output(&mut self, on: bool);
}

/// Why the outputs stay off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BreakActive {
    /// BIF came back after clearing: the break input is active (the comparator reports
    /// over-current or the pin is not routed and floats to the active level).
    Input,
}

/// Arms the break after the BKIN pin has been routed (GPIO alternate function) and BKE
/// set: clears BIF — latched while BKE was set before the pin carried the comparator —
/// and reads it back. BIF cannot be cleared while the break input is active, and MOE
/// cannot be set then (RM0440 §28.3.18), so a flag that stays means the drive must stay
/// off.
pub fn arm_break<T: BreakControl>(tim: &mut T) -> Result<(), BreakActive> {
    tim.clear_break_flag();
    if tim.break_flag() {
        Err(BreakActive::Input)
    } else {
        Ok(())
    }
}

/// The end of a control period: MOE is set only if nothing tripped, the drive should
/// run, and BIF — read again here, after the step, not at the start of the interrupt —
/// is clear. A short over-current pulse that ended inside the interrupt has cleared MOE
/// in hardware and left BIF latched; re-setting MOE from a flag read at the start would
/// switch the bridge on again for a period. Returns whether the outputs are on (and
/// latches `tripped` on a break).
pub fn finish_period<T: BreakControl>(tim: &mut T, tripped: &mut bool, run: bool) -> bool {
    if tim.break_flag() {
        *tripped = true;
    }
    let on = run && !*tripped;
    tim.set_main_output(on);
    on
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ADC as RM0440 describes it after calibration: the first `ignored` ADEN writes
    /// fall within 4 ADC cycles of ADCAL clearing and are reset by the calibration logic;
    /// a write that takes sets ADRDY `ready_after` polls later.
    struct CalibratedAdc {
        ignored: u32,
        ready_after: u32,
        aden: bool,
        polls: u32,
        writes: u32,
    }

    impl AdcEnable for CalibratedAdc {
        fn aden(&mut self) -> bool {
            self.aden
        }
        fn set_aden(&mut self) {
            self.writes += 1;
            self.aden = self.writes > self.ignored;
        }
        fn adrdy(&mut self) -> bool {
            if self.aden {
                self.polls += 1;
            }
            self.aden && self.polls > self.ready_after
        }
    }

    fn adc(ignored: u32) -> CalibratedAdc {
        CalibratedAdc {
            ignored,
            ready_after: 3,
            aden: false,
            polls: 0,
            writes: 0,
        }
    }

    /// Defect 1: with the write lost to the calibration logic a single ADEN write (the old
    /// sequence) never sees ADRDY; re-writing ADEN as ST's `ADC_Enable` does does.
    #[test]
    fn aden_is_rewritten_until_ready() {
        let mut a = adc(1);
        a.set_aden(); // the old firmware: one write, then wait
        assert!(!(0..100).any(|_| a.adrdy()));
        let mut a = adc(2);
        assert!(enable_adc(&mut a, 100));
        assert_eq!(a.writes, 3);
        // A converter that never takes ADEN fails after the poll limit, not forever.
        assert!(!enable_adc(&mut adc(u32::MAX), 100));
    }

    /// TIM1 as RM0440 describes the break: BIF latches while BKE = 1 and the input is at
    /// its active level; it cannot be cleared while the input stays active; MOE is
    /// cleared by a break and cannot be set while the input is active.
    struct Tim1 {
        input_active: bool,
        bif: bool,
        moe: bool,
    }

    impl BreakControl for Tim1 {
        fn break_flag(&mut self) -> bool {
            if self.input_active {
                self.bif = true;
                self.moe = false;
            }
            self.bif
        }
        fn clear_break_flag(&mut self) {
            self.bif = self.input_active;
        }
        fn set_main_output(&mut self, on: bool) {
            self.moe = on && !self.input_active;
        }
    }

    /// Defect 3: BKE set before PB12 was routed latched BIF (an unrouted pin reads as the
    /// active level); after routing, arming clears it and the drive may start. A break
    /// input still active keeps it off.
    #[test]
    fn break_is_armed_after_routing() {
        let mut t = Tim1 {
            input_active: false,
            bif: true,
            moe: false,
        };
        assert_eq!(arm_break(&mut t), Ok(()));
        let mut t = Tim1 {
            input_active: true,
            bif: true,
            moe: false,
        };
        assert_eq!(arm_break(&mut t), Err(BreakActive::Input));
    }

    /// Defect 6: a pulse that latched BIF and ended inside the interrupt leaves BIF set
    /// and MOE clear; the period's end reads BIF again and keeps the outputs off (and
    /// tripped) instead of setting MOE from a flag read before the pulse.
    #[test]
    fn a_break_during_the_step_keeps_the_outputs_off() {
        let mut t = Tim1 {
            input_active: false,
            bif: false,
            moe: true,
        };
        let mut tripped = false;
        // The interrupt starts: no break yet.
        assert!(!t.break_flag());
        // A short over-current pulse during the step: hardware clears MOE, BIF latches.
        t.input_active = true;
        let _ = t.break_flag();
        t.input_active = false;
        assert!(!finish_period(&mut t, &mut tripped, true));
        assert!(tripped && !t.moe);
        // And it stays off in the following periods.
        assert!(!finish_period(&mut t, &mut tripped, true));
        // Without a break the outputs follow `run`.
        let mut t = Tim1 {
            input_active: false,
            bif: false,
            moe: false,
        };
        let mut tripped = false;
        assert!(finish_period(&mut t, &mut tripped, true) && t.moe);
        assert!(!finish_period(&mut t, &mut tripped, false) && !t.moe);
    }
}
