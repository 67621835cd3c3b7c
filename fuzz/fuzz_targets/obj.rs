#![no_main]
//! Fuzz target `obj`: see `cloudprox_fuzz::obj`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::obj(data));
