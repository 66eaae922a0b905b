//! Counts the instructions of one full current-control step on the emulated
//! Cortex-M4F: `ControllerConfig::process` (ADC codes in → three compare values out,
//! angle tracking observer included) with `SoftTrig`, with `FastTrig` and with the trig
//! results replayed, for the motor chosen at build time with `MOTOR=<stem>` (its
//! generated constants, through `motor-config`).
//!
//! SysTick runs from the core clock with reload 0xFF_FFFF and is read before and after
//! every measured call; the ticks of an empty measurement are subtracted. Under
//! `-icount shift=5` one instruction is 5.376 ticks ([`motor_qemu::icount`]); the
//! `nop-1024` line checks that factor. One line per measurement over semihosting, then
//! exit 0. Run by `cargo bench -p motor-qemu --bench icount`, or by hand:
//!
//! ```text
//! cd firmware
//! MOTOR=fischer-ti085 cargo build --release --target thumbv7em-none-eabihf -p motor-qemu --bin icount
//! qemu-system-arm -machine netduinoplus2 -icount shift=5 -nographic \
//!     -semihosting-config enable=on,target=native \
//!     -kernel target/thumbv7em-none-eabihf/release/icount
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Bare-metal entry point and the measurements (netduinoplus2, STM32F405).
#[cfg(target_os = "none")]
mod target {
    use core::hint::black_box;
    use core::panic::PanicInfo;

    use cortex_m::peripheral::SYST;
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m_rt::{ExceptionFrame, entry, exception};
    use cortex_m_semihosting::{debug, hprintln};
    use motor_control::FastTrig;
    use motor_control::ato::ObserverError;
    use motor_control::step::{ControllerState, Demand};
    use motor_control::trig::{SoftTrig, Trig};
    use motor_qemu::icount::{Measurement, Replay, Stats, Workload, elapsed};

    /// Measured steps (after [`WARM_UP`] unmeasured ones).
    const STEPS: u32 = 1000;
    /// Steps run before measuring, so the observer and the integrators settle.
    const WARM_UP: u32 = 200;

    /// Exits QEMU with `status` and never returns.
    fn exit(status: debug::ExitStatus) -> ! {
        debug::exit(status);
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// Ticks spent in `f` and its result: SysTick is read right before and right after
    /// it. `f` must take its inputs through `black_box` so that no work is hoisted above
    /// the first read; its result passes through `black_box` before the second.
    #[inline(always)]
    fn ticks<R>(f: impl FnOnce() -> R) -> (u32, R) {
        let start = SYST::get_current();
        let r = black_box(f());
        let end = SYST::get_current();
        (elapsed(start, end), r)
    }

    /// 2^k `nop`s in a row (each `cortex_m::asm::nop` is one inline `nop`).
    macro_rules! twice {
        ($($t:tt)*) => { $($t)* $($t)* };
    }

    fn print(name: &str, stats: Stats) {
        hprintln!("{}", Measurement { name, stats });
    }

    #[entry]
    fn main() -> ! {
        let Some(mut cp) = cortex_m::Peripherals::take() else {
            hprintln!("core peripherals already taken");
            exit(debug::EXIT_FAILURE)
        };
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(motor_qemu::icount::SYSTICK_RELOAD);
        cp.SYST.clear_current();
        cp.SYST.enable_counter();

        // The measurement itself: two SysTick reads and nothing between them.
        let mut empty = Stats::new();
        for _ in 0..100 {
            empty.add(ticks(|| black_box(())).0);
        }
        let overhead = empty.min;
        print("empty", empty);
        let net = |t: u32| t.saturating_sub(overhead);

        // Calibration: 1024 single-instruction `nop`s.
        let mut nops = Stats::new();
        for _ in 0..10 {
            nops.add(net(ticks(|| {
                twice! {twice! {twice! {twice! {twice! {twice! {twice! {twice! {twice! {twice! {
                    cortex_m::asm::nop();
                }}}}}}}}}}
            })
            .0));
        }
        print("nop-1024", nops);

        let config = &motor_qemu::motor_config::CONFIG;
        let point = motor_qemu::motor_config::operating_point();
        let demand = Demand::Current {
            id: point.current.d,
            iq: point.current.q,
            feed_forward: true,
        };
        let mut workload = Workload::new(config, point);
        let mut state = ControllerState::new();
        state.observer = motor_control::ato::AtoState::locked(0, workload.omega_r);
        for _ in 0..WARM_UP {
            let sample = workload.sample(config);
            config.process(&mut state, &mut SoftTrig, &sample, demand);
        }

        // The full step with the software trigonometry, and the same step replaying the
        // trig results (same output, trig reduced to loads).
        let mut step = Stats::new();
        let mut replayed = Stats::new();
        let mut sin_cos_calls = 0;
        for _ in 0..STEPS {
            let sample = workload.sample(config);
            let mut replay_state = state;
            let mut replay = Replay::record();
            let expected = config.process(&mut replay_state, &mut replay, &sample, demand);
            replay.rewind();
            sin_cos_calls = replay.sin_cos_calls();

            let mut again = state;
            let (t, _) = ticks(|| {
                let (s, st, d) = black_box((&sample, &mut again, demand));
                config.process(st, &mut replay, s, d)
            });
            replayed.add(net(t));

            let (t, out) = ticks(|| {
                let (s, st, d) = black_box((&sample, &mut state, demand));
                config.process(st, &mut SoftTrig, s, d)
            });
            step.add(net(t));
            if out != expected || again != state {
                hprintln!("replayed step differs from the SoftTrig step");
                exit(debug::EXIT_FAILURE)
            }
        }
        print("step", step);
        print("step-trig-replayed", replayed);

        // The same step with the single-precision software trigonometry (FastTrig,
        // 2^-23), from the same state and samples.
        let mut fast_state = state;
        let mut fast = Stats::new();
        for _ in 0..STEPS {
            let sample = workload.sample(config);
            let (t, _) = ticks(|| {
                let (s, st, d) = black_box((&sample, &mut fast_state, demand));
                config.process(st, &mut FastTrig, s, d)
            });
            fast.add(net(t));
        }
        print("step-fast-trig", fast);
        hprintln!("sin-cos-calls-per-step {}", sin_cos_calls);
        hprintln!(
            "atan2-calls-per-step {}",
            u32::from(config.observer.error == ObserverError::Atan2)
        );

        // The trig calls alone, over the angles of one electrical turn.
        let mut sin_cos = Stats::new();
        let mut atan2 = Stats::new();
        let mut trig = SoftTrig;
        let mut theta: i32 = 0;
        for _ in 0..STEPS {
            sin_cos.add(net(ticks(|| trig.sin_cos(black_box(theta))).0));
            let sc = motor_control::trig::sin_cos_q31(theta);
            atan2.add(net(ticks(|| {
                let (y, x) = black_box((sc.sin, sc.cos));
                trig.atan2(y, x)
            })
            .0));
            // 1000 angles spread over one turn (2^32 / 1000 per call).
            theta = theta.wrapping_add(4_294_967);
        }
        print("sin-cos", sin_cos);
        print("atan2", atan2);

        let mut fast_sin_cos = Stats::new();
        let mut fast_atan2 = Stats::new();
        let mut trig = FastTrig;
        for _ in 0..STEPS {
            fast_sin_cos.add(net(ticks(|| trig.sin_cos(black_box(theta))).0));
            let sc = motor_control::trig::sin_cos_q31(theta);
            fast_atan2.add(net(ticks(|| {
                let (y, x) = black_box((sc.sin, sc.cos));
                trig.atan2(y, x)
            })
            .0));
            theta = theta.wrapping_add(4_294_967);
        }
        print("fast-sin-cos", fast_sin_cos);
        print("fast-atan2", fast_atan2);
        exit(debug::EXIT_SUCCESS)
    }

    /// A fault fails the run with the faulting program counter.
    // cortex-m-rt requires this signature; the body does nothing unsafe.
    #[allow(unsafe_code)]
    #[exception]
    unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
        hprintln!("HardFault at pc {:#010x}: {:?}", frame.pc(), frame);
        exit(debug::EXIT_FAILURE)
    }

    /// A panic fails the run with its message.
    #[panic_handler]
    fn panic(info: &PanicInfo) -> ! {
        hprintln!("panic: {}", info);
        exit(debug::EXIT_FAILURE)
    }
}

/// Host build: the measurement needs the emulated Cortex-M4F's SysTick.
#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    eprintln!(
        "icount counts instructions on the emulated Cortex-M4F; run \
         `cargo bench -p motor-qemu --bench icount` in firmware/"
    );
    std::process::ExitCode::FAILURE
}
