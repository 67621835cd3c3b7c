#![no_main]
//! Fuzz target `xyz`: see `cloudprox_fuzz::xyz`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::xyz(data));
