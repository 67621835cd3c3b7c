#![no_main]
//! Fuzz target `urdf`: see `cloudprox_fuzz::urdf`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::urdf(data));
