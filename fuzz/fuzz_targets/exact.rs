#![no_main]
//! Fuzz target `exact`: see `cloudprox_fuzz::exact`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::exact(data));
