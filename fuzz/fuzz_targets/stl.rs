#![no_main]
//! Fuzz target `stl`: see `cloudprox_fuzz::stl`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::stl(data));
