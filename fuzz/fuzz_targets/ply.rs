#![no_main]
//! Fuzz target `ply`: see `cloudprox_fuzz::ply`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::ply(data));
