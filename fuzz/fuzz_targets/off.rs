#![no_main]
//! Fuzz target `off`: see `cloudprox_fuzz::off`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::off(data));
