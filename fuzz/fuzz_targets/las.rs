#![no_main]
//! Fuzz target `las`: see `cloudprox_fuzz::las`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::las(data));
