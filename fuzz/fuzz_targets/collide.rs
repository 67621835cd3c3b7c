#![no_main]
//! Fuzz target `collide`: see `cloudprox_fuzz::collide`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::collide(data));
