#![no_main]
//! Fuzz target `pcd`: see `cloudprox_fuzz::pcd`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::pcd(data));
