@ HardFault entry (the vector), shared by the image (app/src/board/fault.rs) and the
@ emulated stack-overflow test (qemu/src/bin/overflow.rs): uses no stack, so it runs
@ even when the fault was a stack overflow. `{handler}` is an `extern "C" fn(sp: u32) -> !`.
    .section .text.HardFault,"ax",%progbits
    .global HardFault
    .type HardFault,%function
    .thumb_func
HardFault:
    mrs r0, MSP             @ r0: the stack pointer the exception was stacked on
    ldr r2, =0xE000EF34     @ FPCCR (PM0214 4.6.2)
    ldr r3, [r2]
    bic r3, r3, #1          @ LSPACT = 0: no lazy FP save into the (lost) frame
    str r3, [r2]
    ldr r1, =_stack_start   @ the top of the main stack (memory.x)
    msr MSP, r1             @ a fresh stack: the interrupted code never resumes
    isb
    b {handler}
    .ltorg
