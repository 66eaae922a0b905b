//! Test-only: `tests/it` re-verifies the STM32G474RE table that `codegen` checks board
//! files against (`codegen::board::chip`, typed from RM0440 and DS12288) with embassy's
//! `stm32-metapac` metadata, which is generated from ST's own device files. A crate of
//! its own so that the metapac is compiled only for this check. No library code.
