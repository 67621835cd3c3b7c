#![no_main]
//! Fuzz target `pointcloud2`: see `cloudprox_fuzz::pointcloud2`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::pointcloud2(data));
