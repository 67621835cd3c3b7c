#![no_main]
//! Fuzz target `srdf`: see `cloudprox_fuzz::srdf`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::srdf(data));
