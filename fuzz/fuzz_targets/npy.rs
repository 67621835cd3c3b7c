#![no_main]
//! Fuzz target `npy`: see `cloudprox_fuzz::npy`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::npy(data));
